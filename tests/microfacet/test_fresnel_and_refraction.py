"""The dielectric and conductor interfaces of the toolkit (docs/microfacet.md):
Fresnel factors against independent formulas, Snell's law, the generalized half
vector and the refraction Jacobian against a numerical one."""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb

mf = pb.microfacet
RNG = np.random.default_rng(2015)


def fresnel_by_g(c, eta):
    """Walter et al. 2007 eq. 22 as printed: g² = η² - 1 + c²,
    F = ½ (g-c)²/(g+c)² (1 + ((c(g+c) - 1)/(c(g-c) + 1))²), 1 where g² < 0."""
    c = np.abs(c)
    g2 = eta**2 - 1.0 + c**2
    g = np.sqrt(np.maximum(g2, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        f = 0.5 * (g - c) ** 2 / (g + c) ** 2 * (1.0 + ((c * (g + c) - 1.0) / (c * (g - c) + 1.0)) ** 2)
    return np.where(g2 < 0.0, 1.0, f)


def conductor_real_form(c, eta, k):
    """The unpolarised conductor Fresnel factor in real arithmetic (pbrt-v3's FrConductor form)."""
    c2 = c * c
    s2 = 1.0 - c2
    t0 = eta**2 - k**2 - s2
    a2b2 = np.sqrt(t0**2 + 4.0 * eta**2 * k**2)
    a = np.sqrt(0.5 * (a2b2 + t0))
    rs = (a2b2 + c2 - 2.0 * a * c) / (a2b2 + c2 + 2.0 * a * c)
    t3 = c2 * a2b2 + s2 * s2
    rp = rs * (t3 - 2.0 * a * c * s2) / (t3 + 2.0 * a * c * s2)
    return 0.5 * (rs + rp)


def unit(n):
    v = RNG.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def test_dielectric_fresnel_is_walters_formula():
    c = RNG.uniform(-1, 1, 20000)
    eta = np.exp(RNG.uniform(np.log(0.3), np.log(3.0), c.size))
    got, want = mf.fresnel_dielectric(c, eta), fresnel_by_g(c, eta)
    # the g form cancels near grazing and normal incidence; compare where it holds digits
    np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-13)


def test_dielectric_fresnel_limits():
    eta = np.array([1.001, 1.33, 1.5, 2.4])
    np.testing.assert_allclose(mf.fresnel_dielectric(1.0, eta), ((eta - 1) / (eta + 1)) ** 2, rtol=1e-14)
    assert (mf.fresnel_dielectric(0.0, eta) == 1.0).all()
    assert (mf.fresnel_dielectric(RNG.uniform(-1, 1, 100), 1.0) < 1e-26).all()  # 0 to rounding
    # total internal reflection beyond the critical angle, sin θc = 1/η
    critical = np.sqrt(1.0 - (1.0 / 1.5) ** 2)
    assert (mf.fresnel_dielectric(critical * (1 - 1e-9), 1 / 1.5) == 1.0)
    assert mf.fresnel_dielectric(critical * (1 + 1e-6), 1 / 1.5) < 1.0


def test_dielectric_fresnel_is_the_same_from_both_sides():
    """F(cos θi; η) = F(cos θt; 1/η): the reflectance of a ray and of its reverse."""
    c = RNG.uniform(0, 1, 5000)
    eta = RNG.uniform(1.01, 3.0, c.size)
    cos_t = np.sqrt(1.0 - (1.0 - c**2) / eta**2)
    np.testing.assert_allclose(mf.fresnel_dielectric(c, eta), mf.fresnel_dielectric(cos_t, 1.0 / eta), rtol=1e-11,
                               atol=1e-15)


def test_conductor_fresnel_against_the_real_form_and_the_dielectric():
    c = RNG.uniform(0, 1, 20000)
    eta = RNG.uniform(0.05, 4.0, c.size)
    k = RNG.uniform(0.0, 8.0, c.size)
    np.testing.assert_allclose(mf.fresnel_conductor(c, eta, k), conductor_real_form(c, eta, k), rtol=1e-10,
                               atol=1e-13)
    above = RNG.uniform(1.01, 3.0, c.size)
    np.testing.assert_allclose(mf.fresnel_conductor(c, above, 0.0), mf.fresnel_dielectric(c, above), rtol=1e-12,
                               atol=1e-15)
    # gold near 550 nm, (η, k) ≈ (0.43, 2.45): F0 = ((η-1)² + k²) / ((η+1)² + k²)
    eta_gold, k_gold = 0.43, 2.45
    f0 = ((eta_gold - 1) ** 2 + k_gold**2) / ((eta_gold + 1) ** 2 + k_gold**2)
    np.testing.assert_allclose(mf.fresnel_conductor(1.0, eta_gold, k_gold), f0, rtol=1e-14)
    assert mf.fresnel_conductor(0.0, eta_gold, k_gold) == pytest.approx(1.0, abs=1e-15)


@pytest.mark.parametrize("eta", [1.33, 1.5, 2.4, 1 / 1.5])
def test_refraction_obeys_snell(eta):
    w = unit(5000)
    wt = mf.refract(w, eta)
    sin_i = np.hypot(w[:, 0], w[:, 1])
    transmits = sin_i / eta < 1.0
    assert (wt[~transmits] == 0.0).all()
    wt, w = wt[transmits], w[transmits]
    np.testing.assert_allclose(np.linalg.norm(wt, axis=1), 1.0, rtol=1e-14)
    np.testing.assert_allclose(np.hypot(wt[:, 0], wt[:, 1]), np.hypot(w[:, 0], w[:, 1]) / eta, rtol=1e-12, atol=1e-15)
    assert (np.sign(wt[:, 2]) == -np.sign(w[:, 2])).all()
    np.testing.assert_allclose(wt[:, :2] * eta, -w[:, :2], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(mf.refract(wt, 1.0 / eta), w, atol=1e-13)


@pytest.mark.parametrize("eta", [1.001, 1.5, 2.4])
def test_the_generalized_half_vector_of_a_refracted_pair_is_the_normal(eta):
    wo = unit(2000)
    wo[:, 2] = np.abs(wo[:, 2]) + 1e-3
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    wi = mf.refract(wo, eta)  # inside, where the index is η
    h = mf.generalized_half_vector(wi, wo, eta)
    np.testing.assert_allclose(h, np.broadcast_to([0.0, 0.0, 1.0], h.shape), atol=1e-12)
    # reflection: the usual half vector
    wr = wo * [-1, -1, 1]
    both = wo + unit(2000)
    both /= np.linalg.norm(both, axis=1, keepdims=True)
    np.testing.assert_allclose(mf.generalized_half_vector(wr, wo, 1.0), np.broadcast_to([0, 0, 1.0], wo.shape),
                               atol=1e-14)
    assert (mf.generalized_half_vector(-wo, wo, 1.0) == 0.0).all()


def spherical_triangle_area(a, b, c):
    """The solid angle of a small spherical triangle (Van Oosterom & Strackee 1983)."""
    numerator = np.abs(np.sum(a * np.cross(b, c), axis=-1))
    denominator = 1.0 + np.sum(a * b, axis=-1) + np.sum(b * c, axis=-1) + np.sum(c * a, axis=-1)
    return 2.0 * np.arctan2(numerator, denominator)


@pytest.mark.parametrize("eta", [1.33, 1.5, 2.4])
def test_the_refraction_jacobian_is_the_ratio_of_solid_angles(eta):
    """dω_h/dω_i by mapping a tiny triangle of wi directions to half vectors."""
    rng = np.random.default_rng(17)
    wo = unit(400)
    wo[:, 2] = np.abs(wo[:, 2]) + 0.2
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    wi = unit(400)
    wi[:, 2] = -np.abs(wi[:, 2]) - 0.2
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    # keep pairs whose half vector refracts both (each sees the microfacet from its own side)
    h = mf.generalized_half_vector(wi, wo, eta)
    keep = (np.sum(wo * h, axis=1) > 0.05) & (np.sum(wi * h, axis=1) < -0.05)
    wi, wo = wi[keep], wo[keep]
    assert len(wi) > 50
    step = 1e-5
    e1 = np.cross(wi, rng.normal(size=wi.shape))
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(wi, e1)
    corners = [wi, wi + step * e1, wi + step * e2]
    corners = [c / np.linalg.norm(c, axis=1, keepdims=True) for c in corners]
    halves = [mf.generalized_half_vector(c, wo, eta) for c in corners]
    numerical = spherical_triangle_area(*halves) / spherical_triangle_area(*corners)
    np.testing.assert_allclose(mf.refraction_jacobian(wi, wo, eta), numerical, rtol=1e-4)


def test_interface_arguments_are_checked():
    with pytest.raises(ValueError, match=r"cos_theta\[1\]: 1.5 is outside"):
        mf.fresnel_dielectric([0.5, 1.5], 1.5)
    with pytest.raises(ValueError, match=r"eta: 0.0 is outside"):
        mf.fresnel_dielectric(0.5, 0.0)
    with pytest.raises(ValueError, match=r"k: -1.0 is outside"):
        mf.fresnel_conductor(0.5, 0.2, -1.0)
    with pytest.raises(ValueError, match=r"w\[0\]: length"):
        mf.refract([[0.0, 0.0, 2.0]], 1.5)
    with pytest.raises(ValueError, match=r"wo\[0\]: nan"):
        mf.generalized_half_vector([0, 0, 1.0], [np.nan, 0, 1.0], 1.5)
