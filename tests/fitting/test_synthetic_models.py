"""The other models the fit benchmark measures (pb.synthetic) are the BRDFs their papers write.

Reciprocity, the normalisations the papers state, energy conservation of the
layered plastic (all the light that enters a white body leaves), Oren-Nayar at
σ = 0 is Lambert, and named errors for out-of-domain parameters.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import principled_brdf as pb
from conftest import random_direction_pairs, seeded_rng

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
import fit_quality as benchmark  # noqa: E402

S = pb.synthetic
MODELS = {
    "layered plastic, Oren-Nayar": S.layered_plastic((0.5, 0.2, 0.1), 0.2, sigma=0.4),
    "layered plastic, Blinn-Phong": S.layered_plastic((0.3, 0.3, 0.3), 0.3, distribution="blinn_phong"),
    "Ward": S.ward("gold", 0.1, 0.3),
    "Ashikhmin-Shirley": S.ashikhmin_shirley("copper", 200.0, 20.0),
    "satin": S.satin((0.3, 0.03, 0.05), (0.6, 0.3, 0.3), 0.4),
    "Blinn-Phong conductor": S.conductor("silver", 0.1, distribution="blinn_phong"),
}


def _above(n, seed):
    wi, wo = random_direction_pairs(seeded_rng(seed), n)
    wi[:, 2], wo[:, 2] = np.abs(wi[:, 2]) + 1e-3, np.abs(wo[:, 2]) + 1e-3
    return (wi / np.linalg.norm(wi, axis=-1, keepdims=True), wo / np.linalg.norm(wo, axis=-1, keepdims=True))


@pytest.mark.parametrize("name", list(MODELS))
def test_reciprocal_positive_and_nan_below_the_horizon(name):
    f = MODELS[name]
    wi, wo = _above(4000, 3)
    forward, backward = f(wi, wo), f(wo, wi)
    np.testing.assert_allclose(forward, backward, rtol=1e-9, atol=0.0)  # (h·n)^e amplifies rounding
    assert np.all(np.isfinite(forward)) and np.all(forward >= 0.0)
    below = wi * np.array([1.0, 1.0, -1.0])
    assert np.all(np.isnan(f(below, wo)))


def test_a_white_body_under_a_smooth_coat_returns_all_the_light():
    """ρ = 1 and a nearly smooth coat: the directional albedo is 1 but for the coat's
    rough-surface losses (small at α 0.02)."""
    white = S.layered_plastic(1.0, 0.02, distribution="beckmann")
    for mu in (1.0, 0.7, 0.4):
        wo = np.array([np.sqrt(1.0 - mu**2), 0.0, mu])
        albedo = benchmark.directional_albedo(white, wo)
        np.testing.assert_allclose(albedo, 1.0, atol=0.01)


def test_the_body_is_dimmed_by_the_coats_fresnel_at_grazing_views():
    plastic = S.layered_plastic(0.5, 0.3)
    l = np.array([[0.0, 0.0, 1.0]])
    grazing = np.array([[np.sin(1.5), 0.0, np.cos(1.5)]])
    normal = np.array([[0.6, 0.0, 0.8]])
    # away from the specular peak the body dominates; at 86° its light leaves through F ≈ 0.5
    body_normal = plastic(l, normal)[0] - 0.0
    body_grazing = plastic(l, grazing)[0]
    assert np.all(body_grazing < 0.8 * body_normal)


def test_oren_nayar_at_zero_slope_is_lambert():
    a = S.layered_plastic((0.5, 0.2, 0.1), 0.2, sigma=0.0)
    wi, wo = _above(500, 5)
    ratio = a(wi, wo) / S.layered_plastic((0.5, 0.2, 0.1), 0.2, sigma=1e-9)(wi, wo)
    np.testing.assert_allclose(ratio, 1.0, rtol=1e-9)


def test_the_sheen_distribution_is_normalised():
    """Charlie: ∫ D(h) cos θh dωh = 1 (Estevez & Kulla 2017)."""
    for alpha in (0.2, 0.5, 1.0):
        theta = np.linspace(0.0, np.pi / 2, 200001)
        d = (2.0 + 1.0 / alpha) * np.sin(theta) ** (1.0 / alpha) / (2.0 * np.pi)
        assert np.trapezoid(d * np.cos(theta) * np.sin(theta), theta) * 2.0 * np.pi == pytest.approx(1.0, abs=1e-6)
    satin = S.satin(0.0, 1.0, 0.5)
    wi, wo = _above(200, 6)
    h = (wi + wo) / np.linalg.norm(wi + wo, axis=-1, keepdims=True)
    d = (2.0 + 2.0) * np.sqrt(1.0 - h[:, 2] ** 2) ** 2.0 / (2.0 * np.pi)
    visibility = 1.0 / (4.0 * (wi[:, 2] + wo[:, 2] - wi[:, 2] * wo[:, 2]))
    np.testing.assert_allclose(satin(wi, wo)[:, 0], d * visibility, rtol=1e-12)


def test_ward_is_normalised_for_a_narrow_lobe():
    """Ward's lobe integrates to about its specular albedo at normal incidence for small α
    (the Gaussian's integral, Ward 1992): with a conductor's F, to F(1) within 2 %."""
    for alpha_x, alpha_y in ((0.05, 0.05), (0.03, 0.08)):
        metal = S.ward("silver", alpha_x, alpha_y)
        albedo = benchmark.directional_albedo(metal, np.array([0.0, 0.0, 1.0]))
        np.testing.assert_allclose(albedo, S.conductor("silver", 0.1).f0, rtol=0.02)


def test_ashikhmin_shirley_is_its_paper_formula():
    nu, nv = 300.0, 30.0
    metal = S.ashikhmin_shirley("chrome", nu, nv)
    wi, wo = _above(300, 8)
    h = (wi + wo) / np.linalg.norm(wi + wo, axis=-1, keepdims=True)
    off_normal = 1.0 - h[:, 2] ** 2 > 1e-9  # at h = n any exponent gives 1
    wi, wo, h = wi[off_normal], wo[off_normal], h[off_normal]
    e = (nu * h[:, 0] ** 2 + nv * h[:, 1] ** 2) / (1.0 - h[:, 2] ** 2)
    k = np.clip(np.sum(wi * h, axis=-1), -1.0, 1.0)
    lobe = np.sqrt((nu + 1) * (nv + 1)) / (8 * np.pi) * h[:, 2] ** e / (k * np.maximum(wi[:, 2], wo[:, 2]))
    fresnel = np.stack([pb.microfacet.fresnel_conductor(k, eta, kk) for eta, kk in zip(*S.CONDUCTORS["chrome"])], -1)
    np.testing.assert_allclose(metal(wi, wo), lobe[:, None] * fresnel, rtol=1e-10)


@pytest.mark.parametrize("make, message", [
    (lambda: S.layered_plastic(0.5, 0.2, ior=1.0), "ior"),
    (lambda: S.layered_plastic(1.5, 0.2), "albedo"),
    (lambda: S.layered_plastic(0.5, 0.2, sigma=-0.1), "sigma"),
    (lambda: S.ward("gold", 0.0, 0.1), "alpha_x"),
    (lambda: S.ward("gold", 0.1, np.nan), "alpha_y"),
    (lambda: S.ashikhmin_shirley("gold", -1.0, 10.0), "nu"),
    (lambda: S.satin(0.5, 2.0, 0.5), "sheen"),
    (lambda: S.satin(0.5, 0.5, 0.0), "alpha"),
    (lambda: S.ward("unobtainium", 0.1, 0.1), "metal"),
    (lambda: S.conductor("gold", 0.1, distribution="phong"), "distribution"),
])
def test_out_of_domain_parameters_are_named_errors(make, message):
    with pytest.raises(ValueError, match=message):
        make()
