"""The chi-square harness (tests/chi_square.py) itself: its cubature is accurate,
it accepts correct samplers and rejects samplers with small known errors.

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
ACCEPTANCE_CASES = 9
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
