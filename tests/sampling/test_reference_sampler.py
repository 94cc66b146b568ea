"""The float64 reference sampler and pdf (docs/sampling.md, docs/validation.md).

- the definition itself: a numpy transcription of the README (lobe probabilities,
  lobe choice by u0, the direction maps driven by u1, u2, the per-lobe pdfs built
  from the independent toolkit ``pb.microfacet``) against the reference;
- consistency: the returned pdf is ``pdf()`` of the returned pair, the weight is
  ``f cos θl / pdf`` (1e-12 relative);
- docs/validation.md: ``∫ pdf()`` over the upper hemisphere equals the fraction of samples
  landing above it (within 1e-3; the fraction from 2^18 scrambled Sobol points);
- docs/validation.md: chi-square of 10^6 samples against ``pdf()`` for 44 materials x
  4 view angles (visible normals) plus 12 x 4 (distribution sampling), Šidák
  over all cases;
- docs/validation.md: mean weight (importance-sampled Monte Carlo albedo) against a
  quadrature of f cos θl done lobe by lobe ((θl, φl) for diffuse and sheen,
  stretched polar half vectors for the two specular lobes), itself checked
  against the adaptive cubature of tests/chi_square.py;
- docs/validation.md: no NaN or infinity, the below-horizon conventions, lobe probabilities.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from scipy.stats import qmc

import chi_square as cs
import principled_brdf as pb
from conftest import (
    MODELS,
    SELECTED_TESTS,
    assert_relative_close,
    below_horizon_directions,
    corner_materials,
    random_directions,
    random_material_arrays,
    random_material_dict,
    seeded_rng,
)

mf = pb.microfacet
SAMPLERS = ("visible", "distribution")
VIEW_ANGLES = (0.0, 30.0, 60.0, 85.0)
VIEW_AZIMUTH = 0.4  # off the anisotropy axes, so alpha_x != alpha_y matters


def view(theta_deg: float, phi: float = VIEW_AZIMUTH) -> np.ndarray:
    t = np.radians(theta_deg)
    return np.array([np.sin(t) * np.cos(phi), np.sin(t) * np.sin(phi), np.cos(t)])


def mirror(wo: np.ndarray) -> np.ndarray:
    return wo * np.array([-1.0, -1.0, 1.0])


def dot(a, b):
    return np.sum(a * b, axis=-1)


def reflect(wo, h):
    return 2.0 * dot(wo, h)[..., None] * h - wo


def half_vector(wi, wo):
    h = wi + wo
    return h / np.linalg.norm(h, axis=-1, keepdims=True)


# --------------------------------------------------------------------------
# docs/sampling.md, transcribed in numpy (per element: p is a dict of arrays)


def mix(a, b, t):
    return a + (b - a) * t


def luminance(c):
    return c @ np.array([0.3, 0.6, 0.1])


def material_arrays(params: dict, n: int) -> dict:
    """Every parameter as an ``(n,)`` array (``base_color`` ``(n, 3)``), defaults filled in."""
    full = {name: np.asarray(info.default, dtype=np.float64) for name, info in pb.PARAMETERS.items()}
    full.update({k: np.asarray(v, dtype=np.float64) for k, v in params.items()})
    return {k: np.broadcast_to(v, (n, 3) if k == "base_color" else (n,)) for k, v in full.items()}


def readme_alphas(p):
    aspect = np.sqrt(1.0 - 0.9 * p["anisotropic"])
    alpha = p["roughness"] ** 2
    return np.maximum(0.001, alpha / aspect), np.maximum(0.001, alpha * aspect)


def readme_clearcoat_alpha(p):
    return mix(0.1, 0.001, p["clearcoat_gloss"])


def readme_lobe_probabilities(p, wo):
    base = p["base_color"]
    cd_lum = luminance(base)
    tinted = cd_lum >= 2.0 ** -126
    tint = np.where(tinted[:, None], base / np.where(tinted, cd_lum, 1.0)[:, None], 1.0)
    spec0 = mix(p["specular"][:, None] * 0.08 * mix(1.0, tint, p["specular_tint"][:, None]), base,
                p["metallic"][:, None])
    sheen_color = mix(1.0, tint, p["sheen_tint"][:, None])
    fv = np.clip(1.0 - wo[:, 2], 0.0, 1.0) ** 5
    w0 = (1.0 - p["metallic"]) * (cd_lum + 0.1 * p["sheen"] * luminance(sheen_color))
    w1 = np.maximum(luminance(mix(spec0, 1.0, fv[:, None])), 0.02)
    w2 = 0.25 * p["clearcoat"] * mix(0.04, 1.0, fv)
    w = np.stack([w0, w1, w2], axis=-1)
    return w / w.sum(axis=-1, keepdims=True)


def readme_lobe(probability, u0):
    lobe = np.where(u0 < probability[:, 0], 0, np.where(u0 < probability[:, 0] + probability[:, 1], 1, 2))
    return np.where((lobe == 2) & (probability[:, 2] <= 0), 1, lobe)


def readme_cosine(u1, u2):
    r, phi = np.sqrt(u2), 2.0 * np.pi * u1
    return np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1.0 - u2)], axis=-1)


def readme_visible_normal(wo, ax, ay, u1, u2):
    v = np.stack([ax * wo[:, 0], ay * wo[:, 1], wo[:, 2]], axis=-1)
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    phi = 2.0 * np.pi * u1
    z = (1.0 - u2) * (1.0 + v[:, 2]) - v[:, 2]
    s = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    m = np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=-1) + v
    h = np.stack([ax * m[:, 0], ay * m[:, 1], m[:, 2]], axis=-1)
    return h / np.linalg.norm(h, axis=-1, keepdims=True)


def readme_distribution_normal(ax, ay, u1, u2):
    phi = 2.0 * np.pi * u1
    h = np.stack([np.sqrt(u2) * ax * np.cos(phi), np.sqrt(u2) * ay * np.sin(phi), np.sqrt(1.0 - u2)], axis=-1)
    return h / np.linalg.norm(h, axis=-1, keepdims=True)


def readme_gtr1_normal(a, u1, u2):
    cos2 = (1.0 - a ** (2.0 * (1.0 - u2))) / (1.0 - a * a)
    sin2 = a * a * (a ** (-2.0 * u2) - 1.0) / (1.0 - a * a)
    phi = 2.0 * np.pi * u1
    s = np.sqrt(sin2)
    return np.stack([s * np.cos(phi), s * np.sin(phi), np.sqrt(cos2)], axis=-1)


def readme_sample(p, wo, u, sampler):
    """(wi, lobe) for per-element parameters p, wo (n, 3), u (n, 3)."""
    lobe = readme_lobe(readme_lobe_probabilities(p, wo), u[:, 0])
    ax, ay = readme_alphas(p)
    if sampler == "visible":
        h_spec = readme_visible_normal(wo, ax, ay, u[:, 1], u[:, 2])
    else:
        h_spec = readme_distribution_normal(ax, ay, u[:, 1], u[:, 2])
    h_coat = readme_gtr1_normal(readme_clearcoat_alpha(p), u[:, 1], u[:, 2])
    wi = np.where((lobe == 0)[:, None], readme_cosine(u[:, 1], u[:, 2]),
                  np.where((lobe == 1)[:, None], reflect(wo, h_spec), reflect(wo, h_coat)))
    return wi, lobe


def toolkit_pdf(p, wi, wo, sampler):
    """The mixture pdf from README, per lobe through pb.microfacet (independent of the model's C++)."""
    n = len(wi)
    probability = readme_lobe_probabilities(p, wo)
    upper = (wi[:, 2] > 0) & (wo[:, 2] > 0)
    density = np.zeros(n)
    wi, wo, probability = wi[upper], wo[upper], probability[upper]
    ax, ay = (a[upper] for a in readme_alphas(p))
    ac = readme_clearcoat_alpha(p)[upper]
    h = half_vector(wi, wo)
    cos_d = np.linalg.norm(wi + wo, axis=-1) / 2.0  # = wi·h = wo·h, symmetric in wi and wo (as reference.hpp)
    if sampler == "visible":
        spec = mf.GGX(ax, ay).pdf_visible(h, wo) / (4.0 * dot(wo, h))
    else:
        spec = mf.GGX(ax, ay).pdf(h) / (4.0 * cos_d)
    coat = mf.GTR(ac, 1.0).pdf(h) / (4.0 * cos_d)
    density[upper] = probability[:, 0] * wi[:, 2] / np.pi + probability[:, 1] * spec + probability[:, 2] * coat
    return density


# --------------------------------------------------------------------------
# inputs


def random_batch(rng, n, min_cos=1e-4):
    """Per-element random materials (domain edges included), view directions down to
    ``min_cos`` and uniforms."""
    params = random_material_arrays(rng, n)
    return params, pb.Material(**params), random_directions(rng, n, min_cos=min_cos), rng.random((n, 3))


def chi_square_materials() -> list:
    """44 named uniform materials: corner cases and random draws (edges included)."""
    named = corner_materials() + [
        ("mirror_aniso_metal", dict(roughness=0.0, anisotropic=1.0, metallic=1.0)),
        ("mirror_clearcoat_2_gloss_1", dict(roughness=0.0, clearcoat=2.0, clearcoat_gloss=1.0)),
        ("rough_clearcoat_2_gloss_1", dict(roughness=0.7, clearcoat=2.0, clearcoat_gloss=1.0, metallic=0.3)),
        ("metal_clearcoat_satin", dict(metallic=1.0, roughness=0.2, clearcoat=1.0, clearcoat_gloss=0.0)),
        ("black_metal", dict(base_color=(0.0, 0.0, 0.0), metallic=1.0, roughness=0.4)),
        ("no_specular", dict(specular=0.0, roughness=0.4)),
        ("roughness_1_5", dict(roughness=1.5, anisotropic=0.5)),
        ("roughness_0_03_aniso", dict(roughness=0.03, anisotropic=1.0, metallic=1.0)),
        ("aniso_rough", dict(roughness=0.8, anisotropic=1.0)),
        ("glossy_sheen_coat", dict(roughness=0.1, sheen=1.0, clearcoat=0.5, clearcoat_gloss=0.9)),
    ]
    rng = seeded_rng("chi-square-materials")
    randoms = [(f"random{i}", random_material_dict(rng, edge_fraction=0.3)) for i in range(44 - len(named))]
    return named + randoms


MATERIALS = chi_square_materials()
DISTRIBUTION_MATERIALS = [MATERIALS[i] for i in (0, 1, 2, 4, 5, 9, 11, 13, 16, 19, 25, 30)]
CHI_SQUARE_CASES = [
    (name, params, theta, "visible") for name, params in MATERIALS for theta in VIEW_ANGLES
] + [(name, params, theta, "distribution") for name, params in DISTRIBUTION_MATERIALS for theta in VIEW_ANGLES]
CHI_SQUARE_SAMPLES = 10**6
CHI_SQUARE_THRESHOLD = cs.sidak_threshold(len(CHI_SQUARE_CASES))


def case_id(case) -> str:
    name, _, theta, sampler = case
    return f"{name}-{theta:g}deg-{sampler}"


def peak_width(params: dict, wo: np.ndarray) -> float:
    """The narrowest angular feature of the pdf at the mirror direction: the smallest
    alpha (specular or clearcoat), foreshortened by cos θv."""
    p = material_arrays(params, 1)
    ax, ay = readme_alphas(p)
    return float(min(ax[0], ay[0], readme_clearcoat_alpha(p)[0]) * max(wo[2], 0.05))


# --------------------------------------------------------------------------
# the definition (README) and consistency


def test_sample_type_is_exported():
    assert pb.reference.Sample._fields == ("wi", "pdf", "weight", "lobe")


@pytest.mark.parametrize("sampler", SAMPLERS)
def test_directions_follow_the_readme_definition(sampler):
    """Same u -> same lobe and same wi as the README formulas (the SIMD kernel's contract)."""
    rng = seeded_rng("readme-definition", sampler)
    n = 200_000
    params, material, wo, u = random_batch(rng, n)
    s = pb.reference.sample(material, wo, u, specular_sampler=sampler)
    wi, lobe = readme_sample(material_arrays(params, n), wo, u, sampler)
    np.testing.assert_array_equal(s.lobe, lobe)
    assert s.lobe.dtype == np.int32
    np.testing.assert_allclose(s.wi, wi, rtol=0, atol=1e-10)
    assert np.all(np.bincount(s.lobe, minlength=3) > 1000)  # every lobe exercised


@pytest.mark.parametrize("sampler", SAMPLERS)
def test_pdf_matches_the_readme_mixture_built_from_the_toolkit(sampler):
    rng = seeded_rng("readme-pdf", sampler)
    n = 100_000
    params, material, wo, u = random_batch(rng, n, min_cos=1e-3)
    p = material_arrays(params, n)
    sampled = pb.reference.sample(material, wo, u, specular_sampler=sampler).wi
    sampled[sampled[:, 2] <= 0] *= np.array([1.0, 1.0, -1.0])  # reflected into the upper hemisphere
    for wi in (sampled, random_directions(rng, n, min_cos=1e-3)):
        expected = toolkit_pdf(p, wi, wo, sampler)
        actual = pb.reference.pdf(material, wi, wo, specular_sampler=sampler)
        assert_relative_close(actual, expected, 1e-11, what=f"pdf ({sampler})")


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("sampler", SAMPLERS)
def test_returned_pdf_and_weight_are_consistent(model, sampler):
    rng = seeded_rng("consistency", model, sampler)
    n = 200_000
    _, material, wo, u = random_batch(rng, n)
    s = pb.reference.sample(material, wo, u, model=model, specular_sampler=sampler)
    again = pb.reference.pdf(material, s.wi, wo, model=model, specular_sampler=sampler)
    assert_relative_close(s.pdf, again, 1e-12, what="returned pdf vs pdf()")
    above = s.pdf > 0
    np.testing.assert_array_equal(above, s.wi[:, 2] > 0)  # wo is above: pdf > 0 exactly where wi is
    f = pb.reference.eval(material, s.wi, wo, model=model)[above]  # per-element material: evaluate all
    expected = f * s.wi[above, 2:3] / s.pdf[above, None]
    assert_relative_close(s.weight[above], expected, 1e-12, floor=1e-300, what="weight vs f cos / pdf")
    assert np.all(s.weight[~above] == 0.0)


def test_lobe_frequencies_match_the_probabilities():
    """u0 picks lobe k with probability P_k (binomial, 5 sigma)."""
    rng = seeded_rng("lobe-frequencies")
    n = 10**6
    for params in (dict(clearcoat=1.0, sheen=0.5, metallic=0.3), dict(clearcoat=0.2, roughness=0.1)):
        material = pb.Material(**params)
        for theta in VIEW_ANGLES:
            wo = view(theta)
            probability = pb.reference.lobe_probabilities(material, wo)
            lobe = pb.reference.sample(material, wo, rng.random((n, 3))).lobe
            frequency = np.bincount(lobe, minlength=3) / n
            sigma = np.sqrt(probability * (1 - probability) / n)
            assert np.all(np.abs(frequency - probability) <= 5 * sigma + 1e-12), (params, theta, frequency, probability)


def test_model_changes_the_weight_only():
    rng = seeded_rng("model-weight-only")
    n = 50_000
    _, material, wo, u = random_batch(rng, n)
    a = pb.reference.sample(material, wo, u, model="disney2014")
    b = pb.reference.sample(material, wo, u, model="disney2012")
    np.testing.assert_array_equal(a.wi, b.wi)
    np.testing.assert_array_equal(a.pdf, b.pdf)
    np.testing.assert_array_equal(a.lobe, b.lobe)
    assert np.any(a.weight != b.weight)


# --------------------------------------------------------------------------
# lobe probabilities (f)


def test_lobe_probabilities_follow_the_readme():
    rng = seeded_rng("lobe-probabilities")
    n = 100_000
    params, material, wo, _ = random_batch(rng, n)
    wo[: n // 10] = below_horizon_directions(rng, n // 10)  # FV = 1 there; still a distribution
    p = pb.reference.lobe_probabilities(material, wo)
    assert p.shape == (n, 3)
    np.testing.assert_allclose(p, readme_lobe_probabilities(material_arrays(params, n), wo), rtol=1e-13, atol=1e-300)
    np.testing.assert_allclose(p.sum(axis=-1), 1.0, rtol=0, atol=4e-16)
    assert np.all(p >= 0)


def test_lobe_probability_is_zero_only_for_a_lobe_that_is_zero():
    """P0 = 0 only for metals or black sheen-less surfaces, P2 = 0 only without clearcoat,
    P1 never; and a lobe with P = 0 is indeed 0 everywhere (checked at random pairs)."""
    rng = seeded_rng("lobe-probability-zero")
    n = 20_000
    params, material, wo, _ = random_batch(rng, n)
    p = pb.reference.lobe_probabilities(material, wo)
    diffuse_can_be_nonzero = (params["metallic"] < 1) & ((params["base_color"].max(axis=-1) > 0) | (params["sheen"] > 0))
    np.testing.assert_array_equal(p[:, 0] > 0, diffuse_can_be_nonzero)
    np.testing.assert_array_equal(p[:, 2] > 0, params["clearcoat"] > 0)
    assert np.all(p[:, 1] > 0)
    # the lobes that got probability 0 are really zero, at many directions
    lobes = pb.reference.eval_lobes(material, random_directions(rng, n), wo)
    assert np.all(lobes.diffuse[p[:, 0] == 0] == 0) and np.all(lobes.sheen[p[:, 0] == 0] == 0)
    assert np.all(lobes.clearcoat[p[:, 2] == 0] == 0)


# --------------------------------------------------------------------------
# docs/validation.md: ∫ pdf over the upper hemisphere = fraction of samples above it

HEMISPHERE_CASES = [(name, params, theta, sampler)
                    for name, params in MATERIALS[:8] + MATERIALS[-6:]
                    for theta in VIEW_ANGLES for sampler in SAMPLERS]


def run_hemisphere_case(case):
    """(∫ pdf over the upper hemisphere by cubature, fraction of samples above the horizon)."""
    name, params, theta, sampler = case
    material, wo = pb.Material(**params), view(theta)
    integral = cs.integrate_cells(lambda w: pb.reference.pdf(material, w, wo, specular_sampler=sampler),
                                  peaks=[mirror(wo)], peak_width=peak_width(params, wo)).sum()
    # 2^18 scrambled Sobol points: the fraction's error (< 2e-4 here) is far below the 1e-3 of docs/validation.md
    u = qmc.Sobol(3, scramble=True, seed=int(seeded_rng("sobol", case_id(case)).integers(2**31))).random_base2(18)
    wi = pb.reference.sample(material, wo, u, specular_sampler=sampler).wi
    return float(integral), float(np.mean(wi[:, 2] > 0))


@pytest.mark.parametrize("case", HEMISPHERE_CASES, ids=[case_id(c) for c in HEMISPHERE_CASES])
def test_pdf_integral_equals_fraction_of_samples_above_the_horizon(case, heavy_result):
    integral, above = heavy_result
    assert integral <= 1.0 + 1e-6
    assert abs(integral - above) <= 1e-3, (integral, above)


# --------------------------------------------------------------------------
# docs/validation.md: chi-square


def run_chi_square_case(case):
    name, params, theta, sampler = case
    material, wo = pb.Material(**params), view(theta)
    u = seeded_rng("chi-square", case_id(case)).random((CHI_SQUARE_SAMPLES, 3))
    s = pb.reference.sample(material, wo, u, specular_sampler=sampler)
    del u
    result = cs.chi_square_test(
        s.wi,
        lambda w: pb.reference.pdf(material, w, wo, specular_sampler=sampler),
        below=s.pdf == 0,
        peaks=[mirror(wo)],
        peak_width=peak_width(params, wo),
    )
    return result.p_value, result.describe()


@pytest.mark.parametrize("case", CHI_SQUARE_CASES, ids=[case_id(c) for c in CHI_SQUARE_CASES])
def test_sampling_distribution_chi_square(case, heavy_result):
    assert len(MATERIALS) >= 40 and len(CHI_SQUARE_CASES) >= 160
    p_value, description = heavy_result
    assert p_value > CHI_SQUARE_THRESHOLD, f"{case_id(case)}: {description} (threshold {CHI_SQUARE_THRESHOLD:.3g})"


# --------------------------------------------------------------------------
# docs/validation.md: Monte Carlo albedo (mean weight) vs quadrature


def gauss_legendre(order: int):
    """Gauss-Legendre nodes and weights on [0, 1]."""
    nodes, weights = np.polynomial.legendre.leggauss(order)
    return 0.5 * (nodes + 1.0), 0.5 * weights


def horizon_theta_h(phi_h, wo):
    """The polar angle of h, at azimuth phi_h, beyond which wi = 2 (wo·h) h - wo is below the
    horizon: wi.z = sin θo cos(φh - φo) sin 2θh + cos θo cos 2θh = 0."""
    sin_o = np.hypot(wo[0], wo[1])
    cos_phi = np.cos(phi_h - np.arctan2(wo[1], wo[0]))
    return 0.5 * np.arctan2(wo[2], -sin_o * cos_phi)


def albedo_quadrature(params: dict, wo: np.ndarray, model: str, n_azimuth: int = 256, n_radial: int = 64):
    """∫ f cos θl dwi over the upper hemisphere, RGB, lobe by lobe, each over the exact region
    where wi is above the horizon and in variables where its integrand is smooth:

    - diffuse + sheen over (θl, φl): Gauss-Legendre in θl, trapezoid in φl;
    - specular and clearcoat over half vectors, dwi = 4 (wo·h) dωh, with h in stretched
      polar coordinates h ∝ (ax ρ cos ψ, ay ρ sin ψ, 1) (ax = ay = ac for the clearcoat),
      dωh = ax ay ρ / |h'|³ dρ dψ: the peak (width ~alpha in θh) has width ~1 in ρ. The
      trapezoid rule runs over ψ (periodic), Gauss-Legendre over y = asinh ρ (linear
      through the peak, logarithmic in the tails) from 0 to the ρ where wi reaches the
      horizon (``horizon_theta_h``): no kink anywhere, so the rule converges fast.
    """
    material = pb.Material(**params)
    p = material_arrays(params, 1)
    ax, ay = (float(a[0]) for a in readme_alphas(p))
    ac = float(readme_clearcoat_alpha(p)[0])
    azimuth = 2.0 * np.pi * (np.arange(n_azimuth) + 0.5) / n_azimuth
    t, w_t = gauss_legendre(n_radial)
    azimuth, t = (a.ravel() for a in np.meshgrid(azimuth, t, indexing="ij"))
    weight = np.tile(w_t, n_azimuth) * (2.0 * np.pi / n_azimuth)

    theta = 0.5 * np.pi * t
    wi = cs.spherical_to_direction(azimuth, np.cos(theta))
    lobes = pb.reference.eval_lobes(material, wi, wo, model=model)
    jacobian = 0.5 * np.pi * np.cos(theta) * np.sin(theta)
    total = ((weight * jacobian)[:, None] * (lobes.diffuse + lobes.sheen)).sum(axis=0)

    for lobe, (alpha_x, alpha_y) in (("specular", (ax, ay)), ("clearcoat", (ac, ac))):
        stretch_x, stretch_y = alpha_x * np.cos(azimuth), alpha_y * np.sin(azimuth)
        theta_max = horizon_theta_h(np.arctan2(stretch_y, stretch_x), wo)
        y_max = np.arcsinh(np.tan(theta_max) / np.hypot(stretch_x, stretch_y))  # tan θh = |stretch| ρ
        y = y_max * t
        rho = np.sinh(y)
        h = np.stack([stretch_x * rho, stretch_y * rho, np.ones_like(rho)], axis=-1)
        length = np.linalg.norm(h, axis=-1)
        h /= length[:, None]
        wi = reflect(wo, h)
        wi /= np.linalg.norm(wi, axis=-1, keepdims=True)
        f = getattr(pb.reference.eval_lobes(material, wi, wo, model=model, cosine=True), lobe)
        jacobian = 4.0 * dot(wo, h) * alpha_x * alpha_y * rho / length**3 * np.cosh(y) * y_max
        total += ((weight * jacobian)[:, None] * f).sum(axis=0)
    return total


ALBEDO_MATERIALS = [MATERIALS[i] for i in (0, 1, 2, 4, 5, 7, 8, 9, 11, 12, 14, 16)] + MATERIALS[-4:]
ALBEDO_CASES = [(name, params, theta, MODELS[k % 2], SAMPLERS[(k // 2) % 2])
                for k, (name, params) in enumerate(ALBEDO_MATERIALS) for theta in VIEW_ANGLES]


def test_albedo_quadrature_is_accurate():
    """The lobe-wise quadrature against the adaptive cubature of tests/chi_square.py (a different
    method), and against itself at a finer resolution."""
    for name, params in (MATERIALS[1], MATERIALS[9], MATERIALS[12], MATERIALS[-1],
                         ("aniso_sharp", dict(roughness=0.05, anisotropic=1)),
                         ("aniso_rough", dict(roughness=0.8, anisotropic=1, clearcoat=1, clearcoat_gloss=0))):
        material = pb.Material(**params)
        for theta in (0.0, 60.0, 85.0):
            wo = view(theta)
            quadrature = albedo_quadrature(params, wo, "disney2014")
            finer = albedo_quadrature(params, wo, "disney2014", n_azimuth=512, n_radial=128)
            cubature = cs.integrate_cells(lambda w: pb.reference.eval(material, w, wo, cosine=True),
                                          peaks=[mirror(wo)], peak_width=peak_width(params, wo),
                                          atol=1e-9).sum(axis=(0, 1))
            np.testing.assert_allclose(quadrature, finer, rtol=1e-5, err_msg=f"{name} {theta}")
            np.testing.assert_allclose(quadrature, cubature, rtol=1e-5, err_msg=f"{name} {theta}")


def albedo_case_id(case) -> str:
    name, _, theta, model, sampler = case
    return f"{name}-{theta:g}deg-{sampler}-{model}"


def run_albedo_case(case):
    """(quadrature, Monte Carlo mean weight, its standard error), RGB each."""
    name, params, theta, model, sampler = case
    material, wo = pb.Material(**params), view(theta)
    quadrature = albedo_quadrature(params, wo, model)
    n = 10**6
    u = seeded_rng("albedo", name, theta, model, sampler).random((n, 3))
    weight = pb.reference.sample(material, wo, u, model=model, specular_sampler=sampler).weight
    return quadrature, weight.mean(axis=0), weight.std(axis=0, ddof=1) / np.sqrt(n)


@pytest.mark.parametrize("case", ALBEDO_CASES, ids=[albedo_case_id(c) for c in ALBEDO_CASES])
def test_mean_weight_is_the_directional_albedo(case, heavy_result):
    quadrature, estimate, standard_error = heavy_result
    assert np.all(np.abs(estimate - quadrature) <= 3.0 * standard_error + 1e-12), (
        f"MC {estimate} vs quadrature {quadrature}, 3 SE = {3 * standard_error}")


# --------------------------------------------------------------------------
# the statistical cases run two (or more) at a time


HEAVY_TESTS = {  # test name -> (case id, runner)
    "test_pdf_integral_equals_fraction_of_samples_above_the_horizon": (case_id, run_hemisphere_case),
    "test_sampling_distribution_chi_square": (case_id, run_chi_square_case),
    "test_mean_weight_is_the_directional_albedo": (albedo_case_id, run_albedo_case),
}


def _run_or_keep_error(job):
    runner, case = job
    try:
        return runner(case)
    except Exception as error:  # reported by the test that asks for it
        return error


@pytest.fixture(scope="module")
def heavy_results(request):
    """Runs every selected case of the statistical tests once, on a thread pool (the C++ loops
    and most numpy work release the GIL), and hands each test its own result."""
    jobs = {}
    for item in request.config.stash[SELECTED_TESTS]:
        entry = HEAVY_TESTS.get(getattr(item, "originalname", None))
        if entry is not None and item.module is request.module:
            identify, runner = entry
            case = item.callspec.params["case"]
            jobs[(item.originalname, identify(case))] = (runner, case)
    with ThreadPoolExecutor(max_workers=max(2, min(4, os.cpu_count() or 2))) as pool:
        return dict(zip(jobs, pool.map(_run_or_keep_error, jobs.values())))


@pytest.fixture
def heavy_result(request, heavy_results):
    """This statistical test's own result from ``heavy_results``."""
    name = request.node.originalname
    value = heavy_results[(name, HEAVY_TESTS[name][0](request.node.callspec.params["case"]))]
    if isinstance(value, Exception):
        raise value
    return value


# --------------------------------------------------------------------------
# docs/validation.md and the below-horizon conventions (e)


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("sampler", SAMPLERS)
def test_no_nan_or_inf_for_inputs_in_the_domain(model, sampler):
    rng = seeded_rng("finite", model, sampler)
    n = 200_000
    params, material, wo, u = random_batch(rng, n, min_cos=1e-4)
    wo[:2000] = view(np.degrees(np.arccos(1e-4)), 0.0)  # grazing, cos θv = 1e-4
    wo[2000:3000] = [0.0, 0.0, 1.0]  # the normal
    ends = np.array([0.0, 1.0, 1.0 - 2.0**-53, 2.0**-53, 0.5])
    u[3000:23000] = rng.choice(ends, (20000, 3))  # ends of the unit interval, every combination
    s = pb.reference.sample(material, wo, u, model=model, specular_sampler=sampler)
    for name in ("wi", "pdf", "weight"):
        assert np.all(np.isfinite(getattr(s, name))), name
    assert np.all(s.pdf >= 0) and np.all(s.weight >= 0)
    assert np.all((s.lobe >= 0) & (s.lobe <= 2))
    np.testing.assert_allclose(np.linalg.norm(s.wi, axis=-1), 1.0, atol=1e-12)
    np.testing.assert_array_equal(s.pdf > 0, s.wi[:, 2] > 0)
    assert np.all(s.weight[s.pdf == 0] == 0)
    # lobes with probability 0 are never drawn, whatever u0 (u0 = 1 included)
    p = pb.reference.lobe_probabilities(material, wo)
    assert np.all(p[np.arange(n), s.lobe] > 0)
    density = pb.reference.pdf(material, random_directions(rng, n, min_cos=1e-4), wo, specular_sampler=sampler)
    assert np.all(np.isfinite(density)) and np.all(density > 0)


def test_roughness_zero_and_grazing_views_stay_finite():
    material = pb.Material(roughness=0.0, anisotropic=1.0, clearcoat=2.0, clearcoat_gloss=1.0, metallic=0.5)
    rng = seeded_rng("mirror-grazing")
    for cos_v in (1e-4, 1e-3, 0.05, 1.0):
        wo = view(np.degrees(np.arccos(cos_v)), 0.0)
        for sampler in SAMPLERS:
            s = pb.reference.sample(material, wo, rng.random((100_000, 3)), specular_sampler=sampler)
            assert np.all(np.isfinite(s.wi)) and np.all(np.isfinite(s.pdf)) and np.all(np.isfinite(s.weight))
            assert np.all(s.weight[s.pdf > 0].max(axis=0) < 1e3)  # bounded weights: the pdf follows f
    # exactly the mirror direction (h = n) and its neighbours
    wo = view(60.0)
    for wi in (mirror(wo), mirror(view(60.0 + 1e-9))):
        for sampler in SAMPLERS:
            value = pb.reference.pdf(material, wi, wo, specular_sampler=sampler)
            assert np.isfinite(value) and value > 1e4


@pytest.mark.parametrize("sampler", SAMPLERS)
def test_below_the_horizon_pdf_and_weight_are_zero(sampler):
    rng = seeded_rng("below", sampler)
    n = 50_000
    _, material, wo_up, u = random_batch(rng, n)
    wo_down = below_horizon_directions(rng, n)
    # wo below (or on) the horizon: every sample has pdf 0 and weight 0, and finite wi
    s = pb.reference.sample(material, wo_down, u, specular_sampler=sampler)
    assert np.all(np.isfinite(s.wi)) and np.all(s.pdf == 0) and np.all(s.weight == 0)
    # pdf() with either direction at or below the horizon
    up = random_directions(rng, n)
    assert np.all(pb.reference.pdf(material, wo_down, wo_up, specular_sampler=sampler) == 0)
    assert np.all(pb.reference.pdf(material, up, wo_down, specular_sampler=sampler) == 0)
    horizon = np.array([np.cos(0.3), np.sin(0.3), 0.0])
    assert pb.reference.pdf(pb.Material(), horizon, view(30.0), specular_sampler=sampler) == 0
    assert pb.reference.pdf(pb.Material(), view(30.0), horizon, specular_sampler=sampler) == 0
    # wi = -wo: H = 0, no NaN
    assert np.all(pb.reference.pdf(material, -wo_up, wo_up, specular_sampler=sampler) == 0)
    assert pb.reference.pdf(pb.Material(), -horizon, horizon, specular_sampler=sampler) == 0


def test_end_of_unit_interval_conventions():
    """u2 = 1 sends the specular and clearcoat lobes to a horizontal h, hence wi.z = -wo.z:
    below the horizon (pdf 0, weight 0); the one 0/0 of the caps construction (u2 = 1,
    φ opposite the stretched view; or wo = n) gives h = 0, i.e. wi = -wo. The clearcoat
    draw takes cos θh = sqrt(1 - sin²θh) (one exponential per lane), so its h is
    horizontal to the rounding of sin²θh: |wi.z + wo.z| ~ sqrt(eps)."""
    material = pb.Material(roughness=0.5, clearcoat=1.0, metallic=1.0)  # P0 = 0: lobe 1 if u0 < P1
    for theta in (0.0, 40.0):
        wo = view(theta, 0.0)
        p1 = pb.reference.lobe_probabilities(material, wo)[1]
        for sampler in SAMPLERS:
            for u0, tolerance in ((0.0, 1e-12), (p1 + 1e-9, 1e-7)):  # specular, clearcoat
                for u1 in (0.0, 0.25, 0.5, 0.9):
                    s = pb.reference.sample(material, wo, [u0, u1, 1.0], specular_sampler=sampler)
                    assert s.pdf == 0 and np.all(s.weight == 0)
                    assert s.wi[2] == pytest.approx(-wo[2], abs=tolerance)
    s = pb.reference.sample(material, [0.0, 0.0, 1.0], [0.0, 0.3, 1.0])
    np.testing.assert_array_equal(s.wi, [0.0, 0.0, -1.0])
    # u2 = 1 (cosine lobe) is the horizon itself
    s = pb.reference.sample(pb.Material(), view(30.0), [0.0, 0.3, 1.0])
    assert s.lobe == 0 and s.wi[2] == 0 and s.pdf == 0
    # u0 = 1 without clearcoat: lobe 1, never the empty lobe 2
    assert pb.reference.sample(pb.Material(), view(30.0), [1.0, 0.5, 0.5]).lobe == 1
    assert pb.reference.sample(pb.Material(clearcoat=1.0), view(30.0), [1.0, 0.5, 0.5]).lobe == 2


# --------------------------------------------------------------------------
# Python API: shapes, broadcasting, bad input (docs/bad-input.md)


def test_broadcasting_matches_element_by_element():
    rng = seeded_rng("broadcasting")
    material = pb.Material(roughness=np.array([[0.1], [0.6]]), clearcoat=0.5)  # shape (2, 1)
    wo = random_directions(rng, 3)  # (3, 3)
    u = rng.random((2, 3, 3))
    s = pb.reference.sample(material, wo, u)
    assert s.wi.shape == (2, 3, 3) and s.pdf.shape == (2, 3) and s.weight.shape == (2, 3, 3)
    assert s.lobe.shape == (2, 3)
    for i in range(2):
        for j in range(3):
            one = pb.reference.sample(pb.Material(roughness=[0.1, 0.6][i], clearcoat=0.5), wo[j], u[i, j])
            assert one.wi.shape == (3,) and one.pdf.shape == () and one.lobe.shape == ()
            np.testing.assert_array_equal(one.wi, s.wi[i, j])
            assert one.pdf == s.pdf[i, j] and one.lobe == s.lobe[i, j]
            np.testing.assert_array_equal(one.weight, s.weight[i, j])
    density = pb.reference.pdf(material, s.wi, wo)
    np.testing.assert_array_equal(density, s.pdf)
    assert pb.reference.lobe_probabilities(material, wo).shape == (2, 3, 3)
    # one u for many view directions, and a uniform material with a single everything
    s = pb.reference.sample(pb.Material(), wo, [0.1, 0.2, 0.3])
    assert s.wi.shape == (3, 3)
    s = pb.reference.sample(pb.Material(), [0.0, 0.0, 1.0], np.full((4, 3), 0.5))
    assert s.wi.shape == (4, 3) and np.all(s.wi == s.wi[0])


def test_empty_batches():
    s = pb.reference.sample(pb.Material(), np.zeros((0, 3)), np.zeros((0, 3)))
    assert s.wi.shape == (0, 3) and s.pdf.shape == (0,) and s.lobe.dtype == np.int32
    assert pb.reference.pdf(pb.Material(), np.zeros((0, 3)), [0, 0, 1.0]).shape == (0,)
    assert pb.reference.lobe_probabilities(pb.Material(), np.zeros((0, 3))).shape == (0, 3)


@pytest.mark.parametrize(
    "call, error, pattern",
    [
        (lambda: pb.reference.sample(pb.Material(), [0, 0, 1.0], [[0.1, 0.2, 0.3], [0.1, 1.5, 0.3]]),
         ValueError, r"u\[1, 1\]: 1.5 is outside its domain \[0, 1\]"),
        (lambda: pb.reference.sample(pb.Material(), [0, 0, 1.0], [0.1, -0.0001, 0.3]), ValueError, r"u\[1\]"),
        (lambda: pb.reference.sample(pb.Material(), [0, 0, 1.0], [0.1, np.nan, 0.3]), ValueError,
         r"u\[1\]: nan is not a finite number"),
        (lambda: pb.reference.sample(pb.Material(), [0, 0, 1.0], [0.1, 0.2]), ValueError, r"u: expected shape"),
        (lambda: pb.reference.sample(pb.Material(), [0, 0, 1.0], "abc"), TypeError, r"u:"),
        (lambda: pb.reference.sample(pb.Material(), [0, 0, 1.1], [0.1, 0.2, 0.3]), ValueError, r"wo: length"),
        (lambda: pb.reference.sample(pb.Material(), np.ones((2, 3)) / np.sqrt(3), np.full((3, 3), 0.5)),
         ValueError, r"do not broadcast"),
        (lambda: pb.reference.sample(pb.Material(), [0, 0, 1.0], [0.1, 0.2, 0.3], specular_sampler="vndf"),
         ValueError, r"specular_sampler"),
        (lambda: pb.reference.sample(pb.Material(), [0, 0, 1.0], [0.1, 0.2, 0.3], model="disney2016"),
         ValueError, r"model"),
        (lambda: pb.reference.sample({"roughness": 0.5}, [0, 0, 1.0], [0.1, 0.2, 0.3]), TypeError, r"material"),
        (lambda: pb.reference.pdf(pb.Material(), [[0, 0, 1.0], [0, 0, 2.0]], [0, 0, 1.0]), ValueError, r"wi\[1\]"),
        (lambda: pb.reference.pdf(pb.Material(), [0, 0, 1.0], [0, 0, 1.0], specular_sampler=1), ValueError,
         r"specular_sampler"),
        (lambda: pb.reference.lobe_probabilities(pb.Material(), [np.inf, 0, 1.0]), ValueError, r"wo\[0\]"),
    ],
)
def test_bad_input(call, error, pattern):
    with pytest.raises(error, match=pattern):
        call()
