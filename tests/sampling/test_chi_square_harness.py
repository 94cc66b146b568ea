"""The chi-square harness (tests/chi_square.py) itself: its cubature is accurate,
it accepts correct samplers and rejects samplers with small known errors, on the
upper hemisphere and on the whole sphere (``sphere=True``).

Samplers and densities come from the float64 toolkit ``pb.microfacet`` (tested
on its own in tests/microfacet/test_ggx_beckmann_gtr.py) and from closed forms
written here.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

import chi_square as cs
import principled_brdf as pb
from conftest import seeded_rng

mf = pb.microfacet
N = 10**6
# The acceptance tests below are one family: Šidák over them.
ACCEPTANCE_CASES = 16
ACCEPT = cs.sidak_threshold(ACCEPTANCE_CASES)
REJECT = 1e-6  # a wrong sampler must be rejected far beyond any correction


def view(theta_deg: float, phi: float = 0.4) -> np.ndarray:
    t = np.radians(theta_deg)
    return np.array([np.sin(t) * np.cos(phi), np.sin(t) * np.sin(phi), np.cos(t)])


def mirror(wo: np.ndarray) -> np.ndarray:
    return wo * np.array([-1.0, -1.0, 1.0])


def reflect(wo: np.ndarray, h: np.ndarray) -> np.ndarray:
    return 2.0 * np.sum(wo * h, axis=-1, keepdims=True) * h - wo


def half_vector(wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
    h = wi + wo
    return h / np.linalg.norm(h, axis=-1, keepdims=True)


# --------------------------------------------------------------------------
# samplers with known densities


def cosine_power_sample(rng, n, exponent):
    """Density (exponent + 1) cos^exponent θ / (2π): cos θ = u^(1 / (exponent + 1))."""
    u1, u2 = rng.random(n), rng.random(n)
    return cs.spherical_to_direction(2.0 * np.pi * u2, u1 ** (1.0 / (exponent + 1.0)))


def cosine_power_pdf(exponent):
    return lambda w: (exponent + 1.0) / (2.0 * np.pi) * np.maximum(w[:, 2], 0.0) ** exponent


def ggx_h_sample(rng, n, alpha_x, alpha_y):
    return mf.GGX(alpha_x, alpha_y).sample(rng.random(n), rng.random(n))


def ggx_h_pdf(alpha_x, alpha_y):
    return lambda h: mf.GGX(alpha_x, alpha_y).pdf(h)


def visible_wi_sample(rng, n, wo, alpha_x, alpha_y):
    """wi reflected about Heitz's visible normals: some land below the horizon."""
    h = mf.GGX(alpha_x, alpha_y).sample_visible(wo, rng.random(n), rng.random(n))
    return reflect(wo, h)


def visible_wi_pdf(wo, alpha_x, alpha_y, lower=False):
    """G1(wo) D(h) / (4 cos θv) of wi (the D_wo(h) / (4 wo·h) of the reflection); with
    ``lower`` the density at the mirror image (x, y, -z), to integrate the lower hemisphere."""

    def pdf(w):
        w = w * np.array([1.0, 1.0, -1.0]) if lower else w
        h = half_vector(w, wo)
        return mf.GGX(alpha_x, alpha_y).pdf_visible(h, wo) / (4.0 * np.sum(wo * h, axis=-1))

    return pdf


# whole sphere: uniform, and refraction through visible normals into a medium below


ETA = 1.5  # relative index of refraction of the medium below the surface


def uniform_sphere_sample(rng, n):
    u1, u2 = rng.random(n), rng.random(n)
    return cs.spherical_to_direction(2.0 * np.pi * u2, 1.0 - 2.0 * u1)


def refract(wo: np.ndarray, h: np.ndarray, eta: float = ETA) -> np.ndarray:
    """``wo`` (with ``wo·h > 0``) refracted through the microfacet normal ``h`` into the medium below."""
    c = np.sum(wo * h, axis=-1, keepdims=True)
    return -wo / eta + (c / eta - np.sqrt(1.0 - (1.0 - c * c) / eta**2)) * h


def refracted_wi_sample(rng, n, wo, alpha_x, alpha_y):
    h = mf.GGX(alpha_x, alpha_y).sample_visible(wo, rng.random(n), rng.random(n))
    return refract(wo, h)


def refracted_wi_pdf(wo, alpha_x, alpha_y, eta=ETA):
    """D_wo(h) η² |wi·h| / (wo·h + η wi·h)² at the generalized half vector
    h = -(wo + η wi) / |wo + η wi| (Walter et al. 2007, eq. 17): a density on the whole sphere."""

    def pdf(w):
        h = -(wo + eta * w)
        h = h / np.linalg.norm(h, axis=-1, keepdims=True)
        wi_h, wo_h = np.sum(w * h, axis=-1), np.sum(wo * h, axis=-1)
        return mf.GGX(alpha_x, alpha_y).pdf_visible(h, wo) * eta**2 * np.abs(wi_h) / (wo_h + eta * wi_h) ** 2

    return pdf


def refracted_peak(wo: np.ndarray) -> np.ndarray:
    return refract(wo, np.array([0.0, 0.0, 1.0]))


def jumps(wo: np.ndarray) -> list[float]:
    """The cos θ where the reflected and the refracted densities jump: the images of the
    microfacet horizon h_z = 0 (module docstring of tests/chi_square.py)."""
    return [-wo[2], -wo[2] / ETA]


def dielectric_sample(rng, n, wo, alpha, reflect_weight):
    """A rough dielectric's sampler: one visible normal, reflected with probability
    ``reflect_weight``, else refracted. ``(wi, invalid)``: a reflection below the
    surface or a transmission above it is invalid (a BSDF returns it with pdf 0)."""
    h = mf.GGX(alpha, alpha).sample_visible(wo, rng.random(n), rng.random(n))
    reflected = rng.random(n) < reflect_weight
    wi = np.where(reflected[:, None], reflect(wo, h), refract(wo, h))
    invalid = np.where(reflected, wi[:, 2] <= 0.0, wi[:, 2] >= 0.0)
    return wi, invalid


def dielectric_pdf(wo, alpha, reflect_weight):
    reflected, refracted = visible_wi_pdf(wo, alpha, alpha), refracted_wi_pdf(wo, alpha, alpha)

    def pdf(w):
        return np.where(w[:, 2] > 0.0, reflect_weight * reflected(w), (1.0 - reflect_weight) * refracted(w))

    return pdf


# --------------------------------------------------------------------------
# the pieces


def test_sidak_threshold():
    assert cs.sidak_threshold(1) == pytest.approx(0.01, rel=1e-12)
    assert cs.sidak_threshold(160) == pytest.approx(1.0 - 0.99 ** (1 / 160), rel=1e-12)
    assert cs.sidak_threshold(160) == pytest.approx(6.2814e-5, rel=1e-4)


def test_cell_counts():
    n_phi, n_cos = 4, 2
    w = cs.spherical_to_direction(np.array([0.1, 0.1, 2.0, 6.2, 1.0, 1.0]), np.array([0.2, 0.9, 0.9, 0.6, 0.0, -0.5]))
    counts, below = cs.cell_counts(w, n_phi, n_cos)
    expected = np.zeros((n_cos, n_phi), int)
    expected[0, 0] = 1  # cos 0.2, φ 0.1
    expected[1, 0] = 1  # cos 0.9, φ 0.1
    expected[1, 1] = 1  # φ 2.0 in [π/2, π)
    expected[1, 3] = 1  # φ 6.2
    np.testing.assert_array_equal(counts, expected)
    assert below == 2  # z = 0 and z < 0
    counts, below = cs.cell_counts(w, n_phi, n_cos, below=[True, False, False, False, False, False])
    assert below == 3 and counts.sum() == 3
    # exact edges: φ = 0 and cos θ = 1 fall into the first / last cells
    counts, _ = cs.cell_counts(np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 1e-300]]), n_phi, n_cos)
    assert counts[1, 0] == 1 and counts[0, 0] == 1


def test_cell_counts_on_the_sphere():
    n_phi, n_cos = 4, 4  # rows from cos θ = -1, -0.5, 0, 0.5
    w = cs.spherical_to_direction(np.array([0.1, 2.0, 6.2, 1.0, 0.0, 0.1]), np.array([0.2, -0.9, -0.3, 0.0, -1.0, 1.0]))
    counts, invalid = cs.cell_counts(w, n_phi, n_cos, sphere=True)
    expected = np.zeros((n_cos, n_phi), int)
    expected[2, 0] = 1  # cos 0.2, φ 0.1
    expected[0, 1] = 1  # cos -0.9, φ 2.0
    expected[1, 3] = 1  # cos -0.3, φ 6.2
    expected[2, 0] += 1  # cos 0 (the horizon) opens the upper rows; φ 1.0
    expected[0, 0] = 1  # cos -1 (the south pole)
    expected[3, 0] = 1  # cos 1
    np.testing.assert_array_equal(counts, expected)
    assert invalid == 0
    # flagged, zero and non-finite directions go to the invalid cell
    w = np.concatenate([w, [[0.0, 0.0, 0.0], [np.nan, 0.0, 1.0], [0.0, np.inf, 0.0]]])
    counts, invalid = cs.cell_counts(w, n_phi, n_cos, sphere=True, invalid=[True] + [False] * 8)
    assert invalid == 4 and counts.sum() == 5 and counts[2, 0] == 1
    with pytest.raises(ValueError, match="invalid="):
        cs.cell_counts(w, n_phi, n_cos, below=np.zeros(9, bool), sphere=True)
    # on the hemisphere, invalid= joins below=
    counts, below = cs.cell_counts(w[:6], n_phi, n_cos, invalid=[True, False, False, False, False, False])
    assert below == 5 and counts.sum() == 1


def test_pearson_pooling():
    observed = np.array([100, 90, 2, 1, 0, 3])
    expected = np.array([95.0, 95.0, 2.0, 1.0, 0.5, 1.5])
    statistic, dof, pooled = cs.pearson_pooled(observed, expected)
    # cells 2..5 pool to 6 observed vs 5 expected (>= 5): three cells remain
    assert pooled == 4 and dof == 2
    assert statistic == pytest.approx(25 / 95 + 25 / 95 + 1 / 5)
    # a pool that still expects fewer than 5 joins the smallest remaining cell
    statistic, dof, pooled = cs.pearson_pooled(np.array([50, 60, 1]), np.array([55.0, 55.0, 2.0]))
    assert pooled == 1 and dof == 1
    assert statistic == pytest.approx(36 / 57 + 25 / 55)  # the pool (1 vs 2) joins cell 0: 51 vs 57


def test_cubature_exact_for_the_cosine_density():
    cells = cs.integrate_cells(cosine_power_pdf(1.0))
    phi = np.linspace(0.0, 2.0 * np.pi, 51)
    cos_theta = np.linspace(0.0, 1.0, 51)
    exact = np.outer(np.diff(cos_theta**2) / 2.0, np.diff(phi)) / np.pi
    np.testing.assert_allclose(cells, exact, rtol=1e-12, atol=1e-16)
    assert cells.sum() == pytest.approx(1.0, abs=1e-13)


def test_cubature_vector_valued():
    cells = cs.integrate_cells(lambda w: np.stack([w[:, 2] / np.pi, 3.0 * w[:, 2] ** 2 / (2.0 * np.pi)], axis=1))
    assert cells.shape == (50, 50, 2)
    np.testing.assert_allclose(cells.sum(axis=(0, 1)), [1.0, 1.0], atol=1e-12)


def test_cubature_exact_on_the_whole_sphere():
    """Every cell has solid angle 4π / (n_phi n_cos); a density that vanishes below the horizon
    integrates to 1 exactly since with n_cos even the horizon is a row boundary."""
    cells = cs.integrate_cells(lambda w: np.full(len(w), 1.0 / (4.0 * np.pi)), sphere=True)
    np.testing.assert_allclose(cells, 1.0 / 2500, rtol=1e-12)
    cells = cs.integrate_cells(lambda w: (1.0 + w[:, 2]) / (4.0 * np.pi), n_phi=8, n_cos=10, sphere=True)
    cos_theta = np.linspace(-1.0, 1.0, 11)
    rows = (np.diff(cos_theta) + np.diff(cos_theta**2) / 2.0) / (2.0 * 8)
    np.testing.assert_allclose(cells, np.repeat(rows[:, None], 8, axis=1), rtol=1e-12)
    cells = cs.integrate_cells(cosine_power_pdf(1.0), sphere=True)
    assert cells[:25].sum() == 0.0 and cells.sum() == pytest.approx(1.0, abs=1e-13)


@pytest.mark.parametrize("alpha_x, alpha_y", [(1.0, 1.0), (0.5, 0.05), (0.05, 0.05), (0.001, 0.001),
                                              (0.01, 0.001), (0.001, 0.0001)])
def test_cubature_resolves_narrow_peaks_at_the_pole(alpha_x, alpha_y):
    """∫ D cos θh over the hemisphere is 1 (docs/model.md, "The model") even when the whole peak sits inside one cell row."""
    cells = cs.integrate_cells(ggx_h_pdf(alpha_x, alpha_y), peaks=[[0.0, 0.0, 1.0]], peak_width=min(alpha_x, alpha_y))
    assert cells.sum() == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize("alpha", [0.5, 0.05, 0.002])
@pytest.mark.parametrize("theta", [0, 30, 60, 85])
def test_cubature_resolves_off_pole_peaks(alpha, theta):
    """Density of reflected visible normals: upper plus lower hemisphere is 1 (the peak
    at the mirror direction of wo sits anywhere in a cell)."""
    wo = view(theta)
    alpha_y = alpha / 4
    upper = cs.integrate_cells(visible_wi_pdf(wo, alpha, alpha_y), peaks=[mirror(wo)], peak_width=alpha_y * wo[2])
    lower = cs.integrate_cells(visible_wi_pdf(wo, alpha, alpha_y, lower=True))
    assert upper.sum() + lower.sum() == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize("alpha_x, alpha_y", [(0.05, 0.05), (0.001, 0.001), (0.001, 0.0001)])
def test_cubature_resolves_narrow_peaks_at_the_south_pole(alpha_x, alpha_y):
    """D cos θh turned upside down: the peak at cos θ = -1, where the cells are wedges."""
    pdf = ggx_h_pdf(alpha_x, alpha_y)
    cells = cs.integrate_cells(lambda w: pdf(w * np.array([1.0, 1.0, -1.0])), sphere=True,
                               peaks=[[0.0, 0.0, -1.0]], peak_width=min(alpha_x, alpha_y))
    assert cells[:25].sum() == pytest.approx(1.0, abs=1e-6)


@pytest.mark.parametrize("alpha", [0.5, 0.05, 0.002])
@pytest.mark.parametrize("theta", [0, 60, 80])
def test_cubature_resolves_peaks_in_both_hemispheres(alpha, theta):
    """Half reflected (peak at the mirror direction, with mass below the horizon) and half
    refracted (peak below the horizon, at the south pole for theta 0): 1 over the sphere."""
    wo = view(theta)
    alpha_y = alpha / 4
    reflected, refracted = visible_wi_pdf(wo, alpha, alpha_y), refracted_wi_pdf(wo, alpha, alpha_y)
    cells = cs.integrate_cells(lambda w: 0.5 * (reflected(w) + refracted(w)), sphere=True,
                               peaks=[mirror(wo), refracted_peak(wo)], peak_width=alpha_y * wo[2] / 3,
                               cos_breaks=jumps(wo))
    assert cells.sum() == pytest.approx(1.0, abs=1e-6)


def test_cubature_needs_the_break_at_a_jump():
    """Refraction at grazing incidence into a medium of index 1.1: the density jumps to its
    largest values at cos θ = -cos θo / η, a hair above a row boundary of the 50 x 50 grid,
    and most of that band escapes every node unless the cells are cut at the jump."""
    wo = view(85.0)
    pdf = refracted_wi_pdf(wo, 0.5, 0.125, eta=1.1)
    blind = cs.integrate_cells(pdf, sphere=True).sum()
    told = cs.integrate_cells(pdf, sphere=True, cos_breaks=[-wo[2] / 1.1]).sum()
    assert told == pytest.approx(1.0, abs=1e-6)
    assert 1.0 - blind > 1e-3


def test_cubature_needs_the_peak_hint():
    """A peak without tails, far narrower than a cell, falls between the nodes unless the
    cubature is told where it is: this is why ``peaks`` exists (and why the tests pass it)."""
    center = view(47.0, 0.3)
    sigma = 3e-4

    def gaussian_bump(w):  # normalised to 1 up to a relative O(sigma²)
        angle = np.arctan2(np.linalg.norm(np.cross(w, center), axis=-1), w @ center)
        return np.exp(-0.5 * (angle / sigma) ** 2) / (2.0 * np.pi * sigma**2)

    blind = cs.integrate_cells(gaussian_bump).sum()
    told = cs.integrate_cells(gaussian_bump, peaks=[center], peak_width=sigma).sum()
    assert told == pytest.approx(1.0, abs=1e-6)
    assert blind < 0.5
    # the same below the horizon, on the whole sphere
    center = view(133.0, 0.3)
    blind = cs.integrate_cells(gaussian_bump, sphere=True).sum()
    told = cs.integrate_cells(gaussian_bump, sphere=True, peaks=[center], peak_width=sigma).sum()
    assert told == pytest.approx(1.0, abs=1e-6)
    assert blind < 0.5


# --------------------------------------------------------------------------
# accepts correct samplers (ACCEPTANCE_CASES of them, Šidák-corrected)


def test_accepts_cosine_sampler():
    rng = seeded_rng("harness", "cosine")
    result = cs.chi_square_test(cosine_power_sample(rng, N, 1.0), cosine_power_pdf(1.0))
    assert result.p_value > ACCEPT, result.describe()
    assert result.integral == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("alpha_x, alpha_y", [(0.3, 0.3), (0.6, 0.06), (0.001, 0.001), (0.02, 0.002)])
def test_accepts_ggx_distribution_sampler(alpha_x, alpha_y):
    rng = seeded_rng("harness", "ggx", alpha_x, alpha_y)
    h = ggx_h_sample(rng, N, alpha_x, alpha_y)
    result = cs.chi_square_test(h, ggx_h_pdf(alpha_x, alpha_y), peaks=[[0, 0, 1]], peak_width=min(alpha_x, alpha_y))
    assert result.p_value > ACCEPT, result.describe()


@pytest.mark.parametrize("alpha, theta", [(0.5, 60.0), (0.8, 85.0), (0.01, 30.0), (0.002, 85.0)])
def test_accepts_visible_normal_sampler_with_mass_below_the_horizon(alpha, theta):
    rng = seeded_rng("harness", "visible", alpha, theta)
    wo = view(theta)
    alpha_y = alpha / 3
    wi = visible_wi_sample(rng, N, wo, alpha, alpha_y)
    result = cs.chi_square_test(wi, visible_wi_pdf(wo, alpha, alpha_y), peaks=[mirror(wo)],
                                peak_width=alpha_y * wo[2])
    assert result.p_value > ACCEPT, result.describe()
    if alpha >= 0.5:
        assert result.expected_below > 1000  # the below-horizon cell really is in play


def test_accepts_uniform_sphere_sampler():
    rng = seeded_rng("harness", "uniform-sphere")
    result = cs.chi_square_test(uniform_sphere_sample(rng, N), lambda w: np.full(len(w), 1.0 / (4.0 * np.pi)),
                                sphere=True)
    assert result.p_value > ACCEPT, result.describe()
    assert result.integral == pytest.approx(1.0, abs=1e-12) and result.observed_below == 0


@pytest.mark.parametrize("alpha, theta", [(0.5, 60.0), (0.02, 30.0), (0.002, 0.0), (0.3, 85.0)])
def test_accepts_refracted_visible_normal_sampler(alpha, theta):
    """The whole lobe below the horizon; at normal incidence its peak is the south pole."""
    rng = seeded_rng("harness", "refracted", alpha, theta)
    wo = view(theta)
    alpha_y = alpha / 3
    wi = refracted_wi_sample(rng, N, wo, alpha, alpha_y)
    result = cs.chi_square_test(wi, refracted_wi_pdf(wo, alpha, alpha_y), sphere=True,
                                peaks=[refracted_peak(wo)], peak_width=alpha_y * wo[2] / 3, cos_breaks=jumps(wo))
    assert result.p_value > ACCEPT, result.describe()


@pytest.mark.parametrize("alpha, theta", [(0.5, 70.0), (0.01, 40.0)])
def test_accepts_reflection_and_transmission_mixture(alpha, theta):
    """A rough dielectric: a reflected peak above, a transmitted peak below, and the
    invalid samples (reflections below the surface) in the extra cell."""
    rng = seeded_rng("harness", "dielectric", alpha, theta)
    wo = view(theta)
    wi, invalid = dielectric_sample(rng, N, wo, alpha, 0.3)
    result = cs.chi_square_test(wi, dielectric_pdf(wo, alpha, 0.3), sphere=True, invalid=invalid,
                                peaks=[mirror(wo), refracted_peak(wo)], peak_width=alpha * wo[2] / 3,
                                cos_breaks=jumps(wo))
    assert result.p_value > ACCEPT, result.describe()
    if alpha >= 0.5:
        assert result.expected_below > 1000  # the invalid cell really is in play


def test_p_values_of_a_correct_sampler_are_uniform():
    """Over 40 independent runs of 10^5 samples the p-values look uniform (no bias in the
    expected counts that only shows as a shifted statistic)."""
    p_values = []
    for run in range(40):
        rng = seeded_rng("harness", "uniformity", run)
        alpha = 0.05 if run % 2 else 0.4
        h = ggx_h_sample(rng, 10**5, alpha, alpha / 2)
        p_values.append(cs.chi_square_pvalue(h, ggx_h_pdf(alpha, alpha / 2), n_phi=20, n_cos=20,
                                             peaks=[[0, 0, 1]], peak_width=alpha / 2))
    assert stats.kstest(p_values, "uniform").pvalue > 1e-3, np.round(p_values, 3)


# --------------------------------------------------------------------------
# rejects samplers with small errors


def test_rejects_cosine_power_1_05():
    rng = seeded_rng("harness", "cosine-1.05")
    result = cs.chi_square_test(cosine_power_sample(rng, N, 1.05), cosine_power_pdf(1.0))
    assert result.p_value < REJECT, result.describe()


def test_rejects_roughness_0_30_against_0_33():
    rng = seeded_rng("harness", "ggx-0.30")
    h = ggx_h_sample(rng, N, 0.30, 0.30)
    result = cs.chi_square_test(h, ggx_h_pdf(0.33, 0.33))
    assert result.p_value < REJECT, result.describe()


def test_rejects_a_narrow_peak_slightly_too_wide():
    """alpha 0.0011 tested against 0.001: the whole peak is inside one cell, so only the
    resolved cubature can tell (the cell's expectation must be right to ~1e-3)."""
    rng = seeded_rng("harness", "narrow")
    wo = view(30.0)
    wi = visible_wi_sample(rng, N, wo, 0.0011, 0.0011)
    result = cs.chi_square_test(wi, visible_wi_pdf(wo, 0.001, 0.001), peaks=[mirror(wo)], peak_width=0.001 * wo[2])
    assert result.p_value < REJECT, result.describe()


def test_rejects_a_sampler_that_drops_its_below_horizon_samples():
    """Redrawing the samples that land below the horizon (instead of reporting them)
    inflates the upper hemisphere by ~5 %; the below-horizon cell catches it."""
    rng = seeded_rng("harness", "dropped")
    wo = view(60.0)
    wi = visible_wi_sample(rng, N, wo, 0.3, 0.3)
    below = wi[:, 2] <= 0
    wi[below] = visible_wi_sample(rng, int(below.sum()), wo, 0.3, 0.3)  # one retry, most land above
    result = cs.chi_square_test(wi, visible_wi_pdf(wo, 0.3, 0.3), peaks=[mirror(wo)], peak_width=0.3 * wo[2])
    assert result.p_value < REJECT, result.describe()


def test_rejects_a_three_percent_contamination():
    rng = seeded_rng("harness", "contaminated")
    wi = cosine_power_sample(rng, N, 1.0)
    k = 3 * N // 100
    wi[:k] = cosine_power_sample(rng, k, 0.0)  # 3 % uniform over the hemisphere
    result = cs.chi_square_test(wi, cosine_power_pdf(1.0))
    assert result.p_value < REJECT, result.describe()


def test_rejects_a_lower_cosine_lobe_with_power_1_05():
    """A cosine lobe below the horizon drawn with exponent 1.05 and tested against 1."""
    rng = seeded_rng("harness", "lower-cosine-1.05")
    wi = cosine_power_sample(rng, N, 1.05) * np.array([1.0, 1.0, -1.0])
    cosine = cosine_power_pdf(1.0)
    result = cs.chi_square_test(wi, lambda w: cosine(-w), sphere=True)
    assert result.p_value < REJECT, result.describe()


@pytest.mark.parametrize("scale", [0.97, 1.03])
def test_rejects_a_mis_scaled_pdf_on_the_sphere(scale):
    """3 % too little density leaves the invalid cell expecting 3 % of the samples; 3 % too
    much inflates every cell."""
    rng = seeded_rng("harness", "mis-scaled", scale)
    result = cs.chi_square_test(uniform_sphere_sample(rng, N), lambda w: np.full(len(w), scale / (4.0 * np.pi)),
                                sphere=True)
    assert result.p_value < REJECT, result.describe()


def test_rejects_a_transmitted_peak_slightly_too_wide():
    rng = seeded_rng("harness", "narrow-transmitted")
    wo = view(30.0)
    wi = refracted_wi_sample(rng, N, wo, 0.011, 0.011)
    result = cs.chi_square_test(wi, refracted_wi_pdf(wo, 0.01, 0.01), sphere=True,
                                peaks=[refracted_peak(wo)], peak_width=0.01 * wo[2] / 3, cos_breaks=jumps(wo))
    assert result.p_value < REJECT, result.describe()


def test_rejects_a_wrong_mixture_weight():
    """Reflected with probability 0.30, tested against 0.33."""
    rng = seeded_rng("harness", "dielectric-weight")
    wo = view(40.0)
    wi, invalid = dielectric_sample(rng, N, wo, 0.1, 0.30)
    result = cs.chi_square_test(wi, dielectric_pdf(wo, 0.1, 0.33), sphere=True, invalid=invalid,
                                peaks=[mirror(wo), refracted_peak(wo)], peak_width=0.1 * wo[2] / 3,
                                cos_breaks=jumps(wo))
    assert result.p_value < REJECT, result.describe()


def test_rejects_a_sampler_that_drops_its_invalid_samples():
    """Redrawing the reflections that land below the surface (instead of flagging them) leaves
    the invalid cell nearly empty."""
    rng = seeded_rng("harness", "dielectric-dropped")
    wo = view(70.0)
    wi, invalid = dielectric_sample(rng, N, wo, 0.5, 0.3)
    retry = invalid.copy()
    wi[retry], invalid[retry] = dielectric_sample(rng, int(retry.sum()), wo, 0.5, 0.3)  # most land valid
    result = cs.chi_square_test(wi, dielectric_pdf(wo, 0.5, 0.3), sphere=True, invalid=invalid,
                                peaks=[mirror(wo), refracted_peak(wo)], peak_width=0.5 * wo[2] / 3,
                                cos_breaks=jumps(wo))
    assert result.p_value < REJECT, result.describe()
