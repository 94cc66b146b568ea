"""docs/validation.md: the 2015 solid's sampler over the whole sphere. Pearson's
test of the drawn directions against the mixture pdf on an equal-area grid of
the sphere (tests/chi_square.py, sphere=True), samples with pdf 0 (a draw on
the wrong side, total internal reflection at the microfacet) in the invalid
cell, which expects N (1 - ∫ pdf). Views from outside and from inside the
solid; the float64 reference's sampler and every instruction set's.
"""

from __future__ import annotations

import numpy as np
import pytest

import chi_square as cs
import principled_brdf as pb
from conftest import seeded_rng

SAMPLES = 200_000
ISAS = pb.cpu_info()["available"]

MATERIALS = {
    "glass": dict(base_color=(1.0, 1.0, 1.0), spec_trans=1.0, roughness=0.3, ior=1.5),
    "frosted": dict(base_color=(0.9, 0.95, 1.0), spec_trans=1.0, roughness=0.6, ior=1.5),
    "water": dict(base_color=(0.8, 0.9, 1.0), spec_trans=1.0, roughness=0.2, ior=1.33),
    "diamond": dict(base_color=(1.0, 1.0, 1.0), spec_trans=1.0, roughness=0.25, ior=2.4),
    "anisotropic": dict(base_color=(1.0, 1.0, 1.0), spec_trans=1.0, roughness=0.4, anisotropic=0.8, ior=1.5),
    "everything": dict(base_color=(0.7, 0.4, 0.2), spec_trans=0.5, roughness=0.5, metallic=0.2, sheen=0.5,
                       clearcoat=0.6, clearcoat_gloss=0.7, flatness=0.5, specular_tint=0.3, ior=1.45),
}
VIEWS = {"outside-30": 30.0, "outside-75": 75.0, "inside-25": 180.0 - 25.0, "inside-50": 180.0 - 50.0}
CASES = [(m, v) for m in MATERIALS for v in VIEWS]
SIMD_CASES = [("glass", "outside-30"), ("everything", "inside-25")]
THRESHOLD = cs.sidak_threshold(len(CASES) + len(SIMD_CASES) * len(ISAS))


def view(theta_degrees):
    theta = np.radians(theta_degrees)
    return np.array([np.sin(theta) * np.cos(0.3), np.sin(theta) * np.sin(0.3), np.cos(theta)])


def chi_square(material, wo, drawn):
    """The test of ``drawn`` (a Sample) against the reference pdf, with the lobes' peaks and jumps named."""
    eta = float(material.ior)
    eta_t = eta if wo[2] > 0 else 1.0 / eta
    up = np.sign(wo[2])
    refracted = pb.microfacet.refract(wo * [1, 1, up], eta_t) * [1, 1, up]
    mirror = np.array([-wo[0], -wo[1], wo[2]])
    alpha = float(material.roughness) ** 2
    return cs.chi_square_test(
        drawn.wi, lambda w: pb.reference.pdf(material, w, wo, model="disney2015"), sphere=True,
        invalid=drawn.pdf == 0, peaks=[mirror, refracted], peak_width=alpha,
        cos_breaks=[-wo[2], -wo[2] / eta, -wo[2] * eta],
    )


@pytest.mark.parametrize("case", CASES, ids=[f"{m}-{v}" for m, v in CASES])
def test_the_reference_sampler_draws_its_pdf_over_the_sphere(case):
    name, view_name = case
    material, wo = pb.Material(**MATERIALS[name]), view(VIEWS[view_name])
    u = seeded_rng("bsdf2015-chi-square", name, view_name).random((SAMPLES, 3))
    drawn = pb.reference.sample(material, wo, u, model="disney2015")
    transmitted = drawn.wi[:, 2] * wo[2] < 0
    beyond_critical = wo[2] < 0 and np.hypot(wo[0], wo[1]) * float(material.ior) > 0.9  # (mostly reflected inside)
    assert transmitted.mean() > (0.001 if beyond_critical else 0.02), "the case must exercise the transmission"
    result = chi_square(material, wo, drawn)
    assert result.p_value > THRESHOLD, f"{name} {view_name}: {result.describe()}"


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("case", SIMD_CASES, ids=[f"{m}-{v}" for m, v in SIMD_CASES])
def test_the_simd_sampler_draws_the_reference_pdf(case, isa):
    name, view_name = case
    material, wo = pb.Material(**MATERIALS[name]), view(VIEWS[view_name])
    drawn = pb.sample(material, wo.astype(np.float32), n=SAMPLES, seed=7, model="disney2015", isa=isa)
    result = chi_square(material, wo.astype(np.float32).astype(np.float64), drawn)
    assert result.p_value > THRESHOLD, f"{isa} {name} {view_name}: {result.describe()}"


def test_the_albedo_from_both_sides():
    """pb.albedo's mean weights ∫ f |cos θl| dωl, split by the side of wi: for clear glass in importance
    mode at most 1 (the energy bound), and as the roughness vanishes the reflectance tends to
    F_D(cos θv) and the transmittance to its complement, from outside and from inside."""
    cos_o = np.array([0.94, 0.5, -0.87, -0.6])
    eta_t = np.where(cos_o > 0, 1.5, 1 / 1.5)
    fresnel = pb.microfacet.fresnel_dielectric(np.abs(cos_o), eta_t)
    for roughness, tolerance in ((0.5, None), (0.02, 0.01)):
        glass = pb.Material(base_color=(1, 1, 1), spec_trans=1.0, roughness=roughness, ior=1.5)
        result = pb.albedo(glass, cos_o, samples=1 << 17, seed=11, model="disney2015", mode="importance")
        np.testing.assert_allclose(result.reflectance + result.transmittance, result.total, rtol=1e-12)
        np.testing.assert_allclose(result.lobes.transmission, result.transmittance, rtol=1e-12)
        assert np.all(result.total[:, 0] <= 1.0 + 3 * result.total_error[:, 0]), result.total
        if tolerance:
            np.testing.assert_allclose(result.reflectance[:, 0], fresnel, atol=tolerance)
            np.testing.assert_allclose(result.transmittance[:, 0], 1 - fresnel, atol=tolerance)
    brdf = pb.albedo(pb.Material(), [0.3, 1.0], samples=1024)
    assert np.all(brdf.transmittance == 0) and np.array_equal(brdf.reflectance, brdf.total)
    with pytest.raises(ValueError, match="cos_theta_o"):
        pb.albedo(pb.Material(), -0.5)


@pytest.mark.parametrize("isa", ISAS)
def test_the_weights_of_white_glass_stay_below_the_interfaces_bound(isa):
    """The interface split at each microfacet keeps a sample's weight f |cos θl| / pdf near
    G2/G1 <= 1 on either branch, times 1/η_t² for the radiance refracted: <= 1 from outside, <= η²
    from inside. A choice by the view's own Fresnel factor weighs a reflection off a steep
    microfacet by F_D(wo·h) / F_D(cos θv), up to 1/F_D(cos θv) (25 for glass): fireflies."""
    rng = seeded_rng("bsdf2015-weights", isa)
    n = 1 << 18
    wo = rng.normal(size=(n, 3))
    wo = (wo / np.linalg.norm(wo, axis=1, keepdims=True)).astype(np.float32)
    outside = wo[:, 2] > 0
    for roughness in (0.1, 0.3, 0.6):
        glass = pb.Material(base_color=(1, 1, 1), spec_trans=1.0, roughness=roughness, ior=1.5)
        weight = pb.sample(glass, wo, seed=7, model="disney2015", isa=isa).weight.max(axis=1)
        assert weight[outside].max() <= 1.0 + 1e-5, (roughness, weight[outside].max())
        assert weight[~outside].max() <= 1.5**2 * (1.0 + 1e-5), (roughness, weight[~outside].max())
        assert np.median(weight[outside]) > 0.4  # (not small: the draws land where f is; refracted, near 1/η²)
    reference = pb.reference.sample(glass, wo[:4000].astype(np.float64), u=rng.uniform(size=(4000, 3)),
                                    model="disney2015")
    assert reference.weight[outside[:4000]].max() <= 1.0 + 1e-12
