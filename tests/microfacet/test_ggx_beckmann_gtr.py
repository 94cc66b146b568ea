"""The microfacet toolkit, principled_brdf.microfacet (docs/model.md, "The model"; docs/validation.md:
every D integrates to 1, the weak white furnace, samplers by chi-square, finite everywhere).

Integrals over the hemisphere of half vectors use a product rule in (θ, ψ):
ψ is the stretched azimuth, tan φ = (αy/αx) tan ψ, in which GGX and Beckmann
are exactly uniform, so the periodic trapezoid rule in ψ is exact for them; θ
is cut into geometric panels from min(α)/4 up to π/2 (each panel as wide as
the distance to the complex poles of D, which lie about α away) with
Gauss-Legendre nodes on each. Where an integrand has a kink (max(0, wo·h)),
the kink's θ on each ψ row is one more panel end. Normalisations come out at
~1e-15, far below the stated bounds, which is what lets the tests use tight
tolerances.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from principled_brdf import microfacet as mf

TWO_PI = 2.0 * np.pi

# --------------------------------------------------------------------------
# quadrature over the hemisphere of h


def theta_breaks(alpha_min: float) -> np.ndarray:
    """Panel ends in θ: 0, α/4, α/2, α, 2α, ... and a few panels shrinking towards π/2."""
    breaks = [0.0]
    edge = alpha_min / 4.0
    while edge < 0.75 * (np.pi / 2):
        breaks.append(edge)
        edge *= 2.0
    breaks += [np.pi / 2 - d for d in (0.5, 0.25, 0.125) if np.pi / 2 - d > breaks[-1]]
    breaks.append(np.pi / 2)
    return np.array(breaks)


def stretched_azimuth(psi, stretch_x, stretch_y):
    """φ(ψ) with tan φ = (αy/αx) tan ψ, and dφ/dψ."""
    phi = np.arctan2(stretch_y * np.sin(psi), stretch_x * np.cos(psi))
    dphi_dpsi = stretch_x * stretch_y / ((stretch_x * np.cos(psi)) ** 2 + (stretch_y * np.sin(psi)) ** 2)
    return phi, dphi_dpsi


def polar_direction(theta, phi):
    theta, phi = np.broadcast_arrays(theta, phi)
    sin_theta = np.sin(theta)
    return np.stack([sin_theta * np.cos(phi), sin_theta * np.sin(phi), np.cos(theta)], axis=-1)


def hemisphere_nodes(alpha_x, alpha_y, n_psi=256, n_gl=24, kink=None):
    """Nodes h (n_psi, m, 3) and weights (n_psi, m) of ∫ g(h) dω_h over the upper hemisphere."""
    x, w = np.polynomial.legendre.leggauss(n_gl)
    psi = TWO_PI * (np.arange(n_psi) + 0.5) / n_psi
    phi, dphi_dpsi = stretched_azimuth(psi, alpha_x, alpha_y)
    common = theta_breaks(min(alpha_x, alpha_y))
    breaks = np.broadcast_to(common, (n_psi, common.size))
    if kink is not None:
        breaks = np.sort(np.concatenate([breaks, kink(phi)[:, None]], axis=1), axis=1)
    lo, hi = breaks[:, :-1, None], breaks[:, 1:, None]
    theta = (0.5 * (lo + hi) + 0.5 * (hi - lo) * x).reshape(n_psi, -1)
    theta_weight = (0.5 * (hi - lo) * w).reshape(n_psi, -1)
    weight = theta_weight * np.sin(theta) * (dphi_dpsi * TWO_PI / n_psi)[:, None]
    return polar_direction(theta, phi[:, None]), weight


def hemisphere_integral(g, alpha_x, alpha_y, **options) -> float:
    h, weight = hemisphere_nodes(alpha_x, alpha_y, **options)
    return float(np.sum(g(h) * weight))


def horizon_of(wo):
    """On each azimuth φ, the θ where wo·h changes sign (π/2 where it stays positive)."""
    sin_o, cos_o = np.hypot(wo[0], wo[1]), wo[2]
    phi_o = np.arctan2(wo[1], wo[0])

    def kink(phi):
        c = np.cos(phi - phi_o)
        with np.errstate(invalid="ignore"):
            return np.where(c < 0.0, np.arctan2(cos_o, -sin_o * c), np.pi / 2)

    return kink


def direction(theta_deg, phi=0.0):
    t = np.radians(theta_deg)
    return np.array([np.sin(t) * np.cos(phi), np.sin(t) * np.sin(phi), np.cos(t)])


def half_vector(cos_theta_h):
    """Half vectors ``(..., 3)`` in the xz plane at the polar cosines given (GTR's D reads cos θh only)."""
    c = np.asarray(cos_theta_h, dtype=np.float64)
    return np.stack([np.sqrt(np.maximum(0.0, 1.0 - c * c)), np.zeros_like(c), c], axis=-1)


# --------------------------------------------------------------------------
# normalization: ∫ D(h) cos θh dω_h = 1 (stated bound 1e-4; the quadrature reaches ~1e-15)

NORMALISATION_TOLERANCE = 1e-9
GTR_ALPHAS = (0.001, 0.01, 0.05, 0.1, 0.2, 0.35, 0.5, 0.75, 0.9, 0.99, 1.0 - 1e-9, 1.0)
GTR_GAMMAS = (0.25, 0.5, 1.0 - 1e-7, 1.0, 1.0 + 1e-7, 1.5, 2.0, 2.5, 3.0, 10.0)
ANISO_ALPHAS = [(0.05, 0.05), (0.5, 0.05), (0.05, 0.5), (1.0, 0.1), (0.3, 0.03), (0.2, 0.6), (1.0, 1.0),
                (0.01, 0.1)]


@pytest.mark.parametrize("closed_forms", [True, False], ids=["closed", "general"])
@pytest.mark.parametrize("gamma", GTR_GAMMAS)
def test_gtr_normalised(gamma, closed_forms):
    for alpha in GTR_ALPHAS:
        via_h = hemisphere_integral(lambda h: mf.GTR(alpha, gamma, closed_forms=closed_forms).pdf(h), alpha, alpha,
                                    n_psi=4)
        assert abs(via_h - 1.0) < NORMALISATION_TOLERANCE, (alpha, via_h)
        # D itself, which reads cos θh only: 2π ∫ D(cos θ) cos θ sin θ dθ
        h, weight = hemisphere_nodes(alpha, alpha, n_psi=1)
        via_cos = np.sum(mf.GTR(alpha, gamma, closed_forms=closed_forms).d(h) * h[..., 2] * weight)
        assert abs(via_cos - 1.0) < 1e-7, (alpha, via_cos)  # cos θ near 1 carries less of θ


@pytest.mark.parametrize("alpha_x, alpha_y", ANISO_ALPHAS)
def test_ggx_normalised(alpha_x, alpha_y):
    total = hemisphere_integral(lambda h: mf.GGX(alpha_x, alpha_y).pdf(h), alpha_x, alpha_y)
    assert abs(total - 1.0) < NORMALISATION_TOLERANCE
    total_d = hemisphere_integral(lambda h: mf.GGX(alpha_x, alpha_y).d(h) * h[..., 2], alpha_x, alpha_y)
    assert abs(total_d - 1.0) < NORMALISATION_TOLERANCE


@pytest.mark.parametrize("alpha_x, alpha_y", ANISO_ALPHAS)
def test_beckmann_normalised(alpha_x, alpha_y):
    total = hemisphere_integral(lambda h: mf.Beckmann(alpha_x, alpha_y).pdf(h), alpha_x, alpha_y)
    assert abs(total - 1.0) < NORMALISATION_TOLERANCE
    total_d = hemisphere_integral(lambda h: mf.Beckmann(alpha_x, alpha_y).d(h) * h[..., 2], alpha_x, alpha_y)
    assert abs(total_d - 1.0) < NORMALISATION_TOLERANCE


def test_quadrature_is_not_blind():
    # a 1e-6 slip in a normaliser must show: the rule integrates a mis-scaled D to its scale
    total = hemisphere_integral(lambda h: 1.000001 * mf.GGX(0.5, 0.05).pdf(h), 0.5, 0.05)
    assert abs(total - 1.000001) < 1e-12


# --------------------------------------------------------------------------
# weak white furnace: ∫ G1(wo) D(h) / (4 |wo_z|) dwi = 1 over the sphere of wi.
# With wi = 2 (wo·h) h - wo, dwi = 4 |wo·h| dω_h on {wo·h > 0}: the integral is
# ∫ G1(wo) D(h) max(0, wo·h) / |wo_z| dω_h.

FURNACE_ALPHAS = [(0.05, 0.05), (0.5, 0.05), (0.05, 0.5), (1.0, 0.1), (0.3, 0.3), (1.0, 1.0), (0.8, 0.25)]
FURNACE_VIEWS = [(0.0, 0.0), (30.0, 0.3), (60.0, 0.0), (60.0, 1.2), (80.0, 0.7), (89.0, 0.0), (89.9, 0.7),
                 (89.99, 2.0)]


def furnace_tolerance(theta_deg):
    # the ψ rule loses its exactness where the kink reaches the horizon; that matters only at grazing wo
    return 1e-9 if theta_deg <= 80.0 else 1e-4  # stated bound 1e-3


@pytest.mark.parametrize("alpha_x, alpha_y", FURNACE_ALPHAS)
def test_ggx_weak_white_furnace(alpha_x, alpha_y):
    for theta_deg, phi in FURNACE_VIEWS:
        wo = direction(theta_deg, phi)
        g1 = float(mf.GGX(alpha_x, alpha_y).g1(wo))

        def integrand(h):
            return g1 * mf.GGX(alpha_x, alpha_y).d(h) * np.maximum(0.0, h @ wo) / abs(wo[2])

        total = hemisphere_integral(integrand, alpha_x, alpha_y, n_psi=384, kink=horizon_of(wo))
        assert abs(total - 1.0) < furnace_tolerance(theta_deg), (theta_deg, phi, total)


@pytest.mark.parametrize("alpha_x, alpha_y", [(0.05, 0.05), (1.0, 0.1), (0.3, 0.3), (0.6, 0.6)])
def test_beckmann_weak_white_furnace(alpha_x, alpha_y):
    # holds only with the exact Λ of eq. (3-30): the rational fit (3-31) misses by ~1e-3
    for theta_deg, phi in FURNACE_VIEWS[:-2]:
        wo = direction(theta_deg, phi)
        g1 = float(mf.Beckmann(alpha_x, alpha_y).g1(wo))

        def integrand(h):
            return g1 * mf.Beckmann(alpha_x, alpha_y).d(h) * np.maximum(0.0, h @ wo) / abs(wo[2])

        total = hemisphere_integral(integrand, alpha_x, alpha_y, n_psi=384, kink=horizon_of(wo))
        assert abs(total - 1.0) < furnace_tolerance(theta_deg), (theta_deg, phi, total)


def sphere_nodes(wo, n_z=48, n_phi=128, n_gl=16):
    """Nodes wi and weights over the whole sphere in (z, φ), z split at -wo_z where h crosses the horizon."""
    x, w = np.polynomial.legendre.leggauss(n_gl)
    edges = np.concatenate([np.linspace(-1.0, -wo[2], n_z // 2 + 1)[:-1], np.linspace(-wo[2], 1.0, n_z // 2 + 1)])
    z = (0.5 * (edges[:-1, None] + edges[1:, None]) + 0.5 * np.diff(edges)[:, None] * x).ravel()
    z_weight = (0.5 * np.diff(edges)[:, None] * w).ravel()
    phi_edges = np.linspace(0.0, TWO_PI, n_phi + 1)
    phi = (0.5 * (phi_edges[:-1, None] + phi_edges[1:, None]) + 0.5 * np.diff(phi_edges)[:, None] * x).ravel()
    phi_weight = (0.5 * np.diff(phi_edges)[:, None] * w).ravel()
    zz, pp = np.meshgrid(z, phi, indexing="ij")
    s = np.sqrt(np.maximum(0.0, 1.0 - zz * zz))
    wi = np.stack([s * np.cos(pp), s * np.sin(pp), zz], axis=-1)
    return wi, z_weight[:, None] * phi_weight[None, :]


@pytest.mark.parametrize("alpha_x, alpha_y, theta_deg", [(0.7, 0.3, 45.0), (1.0, 0.1, 75.0)])
def test_ggx_weak_white_furnace_over_wi(alpha_x, alpha_y, theta_deg):
    # the same integral without the change of variables, straight over the sphere of wi
    wo = direction(theta_deg, 0.6)
    wi, weight = sphere_nodes(wo)
    half = wi + wo
    half /= np.linalg.norm(half, axis=-1, keepdims=True)
    value = mf.GGX(alpha_x, alpha_y).g1(wo) * mf.GGX(alpha_x, alpha_y).d(half) / (4.0 * abs(wo[2]))
    assert abs(np.sum(value * weight) - 1.0) < 1e-4


@pytest.mark.parametrize("alpha_x, alpha_y", FURNACE_ALPHAS)
def test_visible_normal_pdf_normalised(alpha_x, alpha_y):
    views = [direction(t, p) for t, p in FURNACE_VIEWS] + [direction(90.0, 0.4), direction(120.0, 1.0)]
    for wo in views:
        theta_deg = np.degrees(np.arccos(abs(wo[2])))
        mirrored = wo if wo[2] >= 0 else -wo  # the pdf serves a wo below the horizon as -wo
        total = hemisphere_integral(lambda h: mf.GGX(alpha_x, alpha_y).pdf_visible(h, wo), alpha_x, alpha_y,
                                    n_psi=384, kink=horizon_of(mirrored))
        assert abs(total - 1.0) < furnace_tolerance(theta_deg), (wo, total)


# --------------------------------------------------------------------------
# formulas against independent transcriptions


def random_unit(rng, n, min_z=-1.0):
    z = rng.uniform(min_z, 1.0, n)
    phi = rng.uniform(0.0, TWO_PI, n)
    s = np.sqrt(1.0 - z * z)
    return np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=-1)


def test_ggx_formulas(rng):
    n = 2000
    h = random_unit(rng, n, min_z=0.01)
    w = random_unit(rng, n, min_z=0.01)
    wi = random_unit(rng, n, min_z=0.01)
    ax = rng.uniform(0.01, 1.5, n)
    ay = rng.uniform(0.01, 1.5, n)

    d = 1.0 / (np.pi * ax * ay * ((h[:, 0] / ax) ** 2 + (h[:, 1] / ay) ** 2 + h[:, 2] ** 2) ** 2)  # eq. (13)
    np.testing.assert_allclose(mf.GGX(ax, ay).d(h), d, rtol=1e-13)
    np.testing.assert_allclose(mf.GGX(ax, ay).pdf(h), d * h[:, 2], rtol=1e-13)

    def lam(v):  # docs/model.md, "The model", literally
        return (-1.0 + np.sqrt(1.0 + ((ax * v[:, 0]) ** 2 + (ay * v[:, 1]) ** 2) / v[:, 2] ** 2)) / 2.0

    np.testing.assert_allclose(mf.GGX(ax, ay).lambda_(w), lam(w), rtol=1e-10)
    np.testing.assert_allclose(mf.GGX(ax, ay).g1(w), 1.0 / (1.0 + lam(w)), rtol=1e-13)
    np.testing.assert_allclose(mf.GGX(ax, ay).g2(wi, w, correlated=False), 1.0 / ((1 + lam(wi)) * (1 + lam(w))), rtol=1e-13)
    np.testing.assert_allclose(mf.GGX(ax, ay).g2(wi, w), 1.0 / (1 + lam(wi) + lam(w)), rtol=1e-13)
    visible = (1.0 / (1.0 + lam(w))) * np.maximum(0.0, np.sum(w * h, axis=-1)) * d / w[:, 2]
    np.testing.assert_allclose(mf.GGX(ax, ay).pdf_visible(h, w), visible, rtol=1e-12, atol=1e-300)

    # isotropic GGX is GTR with γ = 2
    iso = ax <= 1.0
    np.testing.assert_allclose(mf.GGX(ax[iso], ax[iso]).d(h[iso]) * h[iso, 2], mf.GTR(ax[iso], 2.0).pdf(h[iso]),
                               rtol=1e-13)


def test_beckmann_formulas(rng):
    n = 2000
    h = random_unit(rng, n, min_z=0.05)
    ax = rng.uniform(0.02, 1.5, n)
    ay = rng.uniform(0.02, 1.5, n)
    cos2 = h[:, 2] ** 2
    slope2 = (h[:, 0] / ax) ** 2 + (h[:, 1] / ay) ** 2
    d = np.exp(-slope2 / cos2) / (np.pi * ax * ay * cos2 * cos2)  # eq. (3-29), stretched
    np.testing.assert_allclose(mf.Beckmann(ax, ay).d(h), d, rtol=1e-12, atol=1e-290)
    np.testing.assert_allclose(mf.Beckmann(ax, ay).pdf(h), d * h[:, 2], rtol=1e-12, atol=1e-290)
    # isotropic: the seed's form with cos θ only
    alpha = ax
    d_iso = np.exp((cos2 - 1.0) / (alpha ** 2 * cos2)) / (np.pi * alpha ** 2 * cos2 ** 2)
    np.testing.assert_allclose(mf.Beckmann(alpha, alpha).d(h), d_iso, rtol=1e-9, atol=1e-290)


def test_beckmann_lambda_exact():
    import mpmath
    mpmath.mp.dps = 40
    alpha = 0.37
    for a in (1e-6, 1e-3, 0.05, 0.3, 1.0, 1.6, 2.5, 4.0, 6.0):
        # a direction with 1 / (α tan θ) = a
        tan_theta = 1.0 / (alpha * a)
        w = np.array([np.sin(np.arctan(tan_theta)), 0.0, np.cos(np.arctan(tan_theta))])
        a_exact = mpmath.mpf(w[2]) / (alpha * mpmath.mpf(w[0]))
        lam = (mpmath.erf(a_exact) - 1) / 2 + mpmath.exp(-a_exact ** 2) / (2 * a_exact * mpmath.sqrt(mpmath.pi))
        got = float(mf.Beckmann(alpha).lambda_(w))
        tolerance = 1e-13 * (1.0 + 2.0 * a * a)  # (erf - 1) and exp(-a²)/… cancel by ~2a²
        assert abs(got - float(lam)) <= tolerance * float(lam), (a, got, float(lam))
        assert float(mf.Beckmann(alpha).g1(w)) == pytest.approx(float(1 / (1 + lam)), rel=1e-14)
    assert float(mf.Beckmann(0.3).lambda_([0.0, 0.0, 1.0])) == 0.0
    assert float(mf.Beckmann(0.3).lambda_([1.0, 0.0, 0.0])) == np.inf
    assert float(mf.Beckmann(0.3).g1([1.0, 0.0, 0.0])) == 0.0


def gtr_d_exact(mpmath, cos_theta, alpha, gamma):
    """Appendix B eq. (1) (eq. (4) at γ = 1) in 50-digit arithmetic, for the float inputs as given."""
    c, a2, g = mpmath.mpf(cos_theta), mpmath.mpf(alpha) ** 2, mpmath.mpf(gamma)
    if a2 == 1:
        return 1 / mpmath.pi
    t = 1 + (a2 - 1) * c * c
    if g == 1:
        return (a2 - 1) / (mpmath.pi * mpmath.log(a2) * t)
    return (g - 1) * (a2 - 1) / (mpmath.pi * (1 - a2 ** (1 - g))) / t ** g


NEAR_SINGULAR_GAMMAS = (0.01, 0.5, 1.0 - 1e-7, 1.0 - 1e-12, 1.0, 1.0 + 1e-12, 1.0 + 1e-7, 1.5 - 1e-9, 1.5,
                        1.5 + 1e-9, 2.0 - 1e-9, 2.0, 2.0 + 1e-9, 3.0, 10.0, 100.0)
NEAR_SINGULAR_ALPHAS = (1e-6, 1e-3, 0.05, 0.3, 0.9, 1.0 - 1e-6, 1.0 - 1e-12, 1.0)


@pytest.mark.parametrize("closed_forms", [True, False], ids=["closed", "general"])
def test_gtr_d_accurate_near_singular_points(closed_forms):
    import mpmath
    mpmath.mp.dps = 50
    cosines = (0.0, 0.3, 0.9, 0.999, 1.0)
    for gamma in NEAR_SINGULAR_GAMMAS:
        for alpha in NEAR_SINGULAR_ALPHAS:
            got = mf.GTR(alpha, gamma, closed_forms=closed_forms).d(half_vector(cosines))
            for c, value in zip(cosines, got):
                if c == 0.0:
                    assert value == 0.0  # D is 0 for h·n <= 0, the horizon included
                    continue
                exact = float(gtr_d_exact(mpmath, c, alpha, gamma))
                # relative accuracy of pow(t, γ) with t ~ α²: a few ulp of γ ln t
                tolerance = 4e-15 * (10.0 + gamma * abs(np.log(alpha * alpha + c * c)))
                assert abs(value - exact) <= tolerance * exact + 1e-300, (gamma, alpha, c, value, exact)


def test_gtr_closed_forms_match_general_formula():
    c = np.linspace(0.0, 1.0, 101)
    for gamma in (1.0, 1.5, 2.0):
        for alpha in NEAR_SINGULAR_ALPHAS:
            closed = mf.GTR(alpha, gamma).d(half_vector(c))
            general = mf.GTR(alpha, gamma, closed_forms=False).d(half_vector(c))
            np.testing.assert_allclose(general, closed, rtol=1e-13)
            # the seed's closed forms written out literally (away from α = 1, where (4) is 0/0, and
            # from tiny α, where 1 + (α²-1) cos²θh cancels)
            if 1e-3 <= alpha < 0.95:
                a2 = alpha * alpha
                t = 1.0 + (a2 - 1.0) * c * c
                literal = {1.0: (a2 - 1.0) / (np.pi * np.log(a2) * t),
                           1.5: (a2 + alpha) / (2.0 * np.pi * t ** 1.5),
                           2.0: a2 / (np.pi * t * t)}[gamma]
                # the literal form loses ~eps/α² to cancellation near cos θh = 1
                np.testing.assert_allclose(closed[1:], literal[1:], rtol=max(1e-12, 1e-15 / (alpha * alpha)))


def test_gtr_continuous_in_gamma_and_alpha():
    c = np.linspace(0.0, 1.0, 41)
    for gamma in (1.0, 1.5, 2.0):
        for alpha in (0.01, 0.1, 0.5, 0.9):
            at = mf.GTR(alpha, gamma).d(half_vector(c))
            for delta in (1e-7, 1e-12):
                # |d ln D / dγ| <= |ln t| + |ln α²| + 1
                bound = delta * (2.0 + 4.0 * abs(np.log(alpha)))
                for side in (-1.0, 1.0):
                    np.testing.assert_allclose(mf.GTR(alpha, gamma + side * delta).d(half_vector(c)), at, rtol=bound)
    for gamma in (0.3, 1.0, 1.0 + 1e-9, 1.5, 2.0, 3.0):
        for eps in (1e-6, 1e-12, 0.0):
            np.testing.assert_allclose(mf.GTR(1.0 - eps, gamma).d(half_vector(c[1:])), 1.0 / np.pi, rtol=10 * eps * gamma + 1e-15)
        np.testing.assert_allclose(mf.GTR(1.0, gamma, closed_forms=False).d(half_vector(c[1:])), 1.0 / np.pi, rtol=1e-15)


def gtr_cos2_exact(mpmath, u2, alpha, gamma):
    """cos²θh of eq. (3) (eq. (5) at γ = 1) in 50-digit arithmetic."""
    u, a2, g = mpmath.mpf(u2), mpmath.mpf(alpha) ** 2, mpmath.mpf(gamma)
    if a2 == 1:
        return 1 - u
    if g == 1:
        return (1 - a2 ** (1 - u)) / (1 - a2)
    return (1 - (a2 ** (1 - g) * (1 - u) + u) ** (1 / (1 - g))) / (1 - a2)


@pytest.mark.parametrize("closed_forms", [True, False], ids=["closed", "general"])
def test_gtr_sample_accurate_near_singular_points(closed_forms):
    import mpmath
    mpmath.mp.dps = 80  # the power 1/(1-γ) magnifies rounding by up to 1e12
    u2 = np.array([0.0, 1e-9, 0.01, 0.3, 0.5, 0.9, 0.999999, 1.0])
    for gamma in NEAR_SINGULAR_GAMMAS:
        for alpha in NEAR_SINGULAR_ALPHAS:
            h = mf.GTR(alpha, gamma, closed_forms=closed_forms).sample(0.1, u2)
            np.testing.assert_allclose(np.linalg.norm(h, axis=-1), 1.0, rtol=1e-15)
            for u, hv in zip(u2, h):
                if u == 0.0:
                    assert tuple(hv) == (0.0, 0.0, 1.0)
                    continue
                cos2 = gtr_cos2_exact(mpmath, u, alpha, gamma)
                cos2 = min(max(cos2, 0), 1)
                cos_exact, sin_exact = float(mpmath.sqrt(cos2)), float(mpmath.sqrt(1 - cos2))
                sin_got = np.hypot(hv[0], hv[1])
                tolerance = 1e-13 * (1.0 + 0.05 * gamma)
                assert abs(hv[2] - cos_exact) <= tolerance * max(cos_exact, 1e-300) + 1e-300, (gamma, alpha, u, hv)
                assert abs(sin_got - sin_exact) <= tolerance * sin_exact + 1e-300, (gamma, alpha, u, hv)
                assert np.arctan2(hv[1], hv[0]) == pytest.approx(0.2 * np.pi) or sin_got == 0.0


def test_height_correlated_g2_at_least_separable(rng):
    n = 20000
    wi = random_unit(rng, n)
    wo = random_unit(rng, n)
    wi[:200, 2] = 0.0
    wi[:200, :2] /= np.linalg.norm(wi[:200, :2], axis=-1, keepdims=True)
    ax = np.exp(rng.uniform(np.log(1e-4), np.log(3.0), n))
    ay = np.exp(rng.uniform(np.log(1e-4), np.log(3.0), n))
    separable = mf.GGX(ax, ay).g2(wi, wo, correlated=False)
    correlated = mf.GGX(ax, ay).g2(wi, wo)
    g1i, g1o = mf.GGX(ax, ay).g1(wi), mf.GGX(ax, ay).g1(wo)
    assert np.all(correlated >= separable * (1.0 - 1e-15))
    assert np.all(correlated <= np.minimum(g1i, g1o) * (1.0 + 1e-15))
    assert np.all((separable >= 0.0) & (correlated >= 0.0) & (correlated <= 1.0))
    assert np.all(correlated[:200] == 0.0) and np.all(separable[:200] == 0.0)


def test_smith_at_the_normal_and_grazing():
    n, x = [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]
    assert float(mf.GGX(0.3, 0.1).lambda_(n)) == 0.0 and float(mf.GGX(0.3, 0.1).g1(n)) == 1.0
    assert float(mf.GGX(0.3, 0.1).lambda_(x)) == np.inf and float(mf.GGX(0.3, 0.1).g1(x)) == 0.0
    # Λ ≈ α sinθ / (2 cosθ) close to grazing: finite, no overflow, no cancellation
    tiny = 1e-200
    w = [np.sqrt(1.0 - tiny * tiny), 0.0, tiny]
    assert float(mf.GGX(0.3, 0.1).lambda_(w)) == pytest.approx(0.3 / (2.0 * tiny), rel=1e-14)
    # visible-normal density stays finite for a grazing wo
    h = mf.GGX(0.3, 0.1).sample_visible(x, 0.3, 0.4)
    assert np.isfinite(mf.GGX(0.3, 0.1).pdf_visible(h, x)) and float(mf.GGX(0.3, 0.1).pdf_visible(h, x)) > 0.0


# --------------------------------------------------------------------------
# samplers against their pdf (chi-square; docs/validation.md "each D with its own sampler")

GTR_SAMPLER_CASES = [(a, g, cf) for g in (0.5, 1.0, 1.5, 2.0, 3.0) for a in (0.05, 0.3, 1.0)
                     for cf in ((True, False) if g in (1.0, 1.5, 2.0) else (True,))]
ANISO_SAMPLER_ALPHAS = [(0.05, 0.05), (0.5, 0.05), (1.0, 0.1), (0.3, 0.7)]
VISIBLE_SAMPLER_CASES = [(ax, ay, t, p) for ax, ay in [(0.3, 0.3), (0.5, 0.05), (0.05, 0.5), (1.0, 0.1)]
                         for t, p in [(0.0, 0.0), (30.0, 0.4), (60.0, 2.0), (85.0, 0.9)]]
VISIBLE_SAMPLER_CASES += [(0.2, 0.6, 90.0, 0.3), (0.4, 0.4, 130.0, 1.0), (0.01, 0.01, 45.0, 0.0)]
EQUAL_AREA_CASES = ["gtr-1", "gtr-1.5", "gtr-2", "gtr-3", "ggx", "beckmann", "visible-0", "visible-60",
                    "visible-85"]
CHI2_CASE_COUNT = (len(GTR_SAMPLER_CASES) + 2 * len(ANISO_SAMPLER_ALPHAS) + len(VISIBLE_SAMPLER_CASES)
                   + len(EQUAL_AREA_CASES))
CHI2_SIGNIFICANCE = 1.0 - 0.99 ** (1.0 / CHI2_CASE_COUNT)  # 0.01 overall, Šidák


def sample_coordinates(h, stretch_x, stretch_y):
    theta = np.arctan2(np.hypot(h[:, 0], h[:, 1]), h[:, 2])
    psi = np.arctan2(stretch_x * h[:, 1], stretch_y * h[:, 0])  # tan ψ = (αx/αy) tan φ
    return theta, psi


def refine(edges, extra=(), parts=2):
    """Finer panel ends inside ``edges`` (each piece split in ``parts``), and the coarse bin of each panel."""
    inside = [e for e in extra if edges[0] < e < edges[-1]]
    ends = np.unique(np.concatenate([edges, inside]))
    starts = (ends[:-1, None] + np.diff(ends)[:, None] * np.arange(parts) / parts).ravel()
    fine = np.unique(np.append(starts, ends[-1]))
    return fine, np.searchsorted(edges, 0.5 * (fine[:-1] + fine[1:])) - 1


def panel_nodes(edges, n_gl):
    x, w = np.polynomial.legendre.leggauss(n_gl)
    lo, hi = edges[:-1, None], edges[1:, None]
    return (0.5 * (lo + hi) + 0.5 * (hi - lo) * x).ravel(), (0.5 * (hi - lo) * w).ravel()


def bin_probabilities(pdf, theta_edges, psi_edges, stretch_x, stretch_y, n_gl=8):
    """∫ pdf dω over each (θ, ψ) cell: Gauss-Legendre on sub-panels (split at the geometric θ breaks)."""
    theta_fine, theta_bin = refine(theta_edges, theta_breaks(min(stretch_x, stretch_y)), parts=3)
    psi_fine, psi_bin = refine(psi_edges, parts=3)
    theta, theta_weight = panel_nodes(theta_fine, n_gl)
    psi, psi_weight = panel_nodes(psi_fine, n_gl)
    phi, dphi_dpsi = stretched_azimuth(psi, stretch_x, stretch_y)
    h = polar_direction(theta[:, None], phi[None, :])
    cell = pdf(h) * (theta_weight * np.sin(theta))[:, None] * (psi_weight * dphi_dpsi)[None, :]
    cell = cell.reshape(len(theta_fine) - 1, n_gl, len(psi_fine) - 1, n_gl).sum(axis=(1, 3))
    probabilities = np.zeros((len(theta_edges) - 1, len(psi_edges) - 1))
    np.add.at(probabilities, (theta_bin[:, None], psi_bin[None, :]), cell)
    return probabilities


def adaptive_theta_edges(pdf, stretch_x, stretch_y, n_bins):
    """θ edges at equal steps of the marginal cdf of θ (from the quadrature, not from samples)."""
    h, weight = hemisphere_nodes(stretch_x, stretch_y, n_psi=64, n_gl=12)
    theta = np.arctan2(np.hypot(h[0, :, 0], h[0, :, 1]), h[0, :, 2])
    cdf = np.cumsum(np.sum(pdf(h) * weight, axis=0))
    cdf /= cdf[-1]
    edges = np.interp(np.linspace(0.0, 1.0, n_bins + 1)[1:-1], cdf, theta)
    return np.unique(np.concatenate([[0.0], edges, [np.pi / 2]]))


def chi_square_p_value(observed, expected):
    """Pearson chi-square with every cell of expected count below 5 pooled into one."""
    observed, expected = observed.ravel().astype(float), expected.ravel()
    small = expected < 5.0
    if 0.0 < expected[small].sum() < 5.0:
        small[np.argmin(np.where(small, np.inf, expected))] = True
    obs = np.append(observed[~small], observed[small].sum())
    exp = np.append(expected[~small], expected[small].sum())
    keep = exp > 0
    assert np.all(obs[~keep] == 0), "samples fell where the pdf is zero"
    return stats.chisquare(obs[keep], exp[keep] * obs[keep].sum() / exp[keep].sum()).pvalue


def check_sampler(h, pdf, stretch_x, stretch_y, *, equal_area=False):
    n = len(h)
    assert np.all(np.isfinite(h))
    np.testing.assert_allclose(np.linalg.norm(h, axis=-1), 1.0, rtol=1e-14)
    assert np.all(h[:, 2] >= 0.0)
    if equal_area:  # docs/validation.md grid: 50 x 50 cells equal in (cos θ, φ)
        stretch_x = stretch_y = 1.0
        theta_edges = np.arccos(np.linspace(1.0, 0.0, 51))
        psi_edges = np.linspace(-np.pi, np.pi, 51)
    else:
        theta_edges = adaptive_theta_edges(pdf, stretch_x, stretch_y, 24)
        psi_edges = np.linspace(-np.pi, np.pi, 17)
    probabilities = bin_probabilities(pdf, theta_edges, psi_edges, stretch_x, stretch_y)
    # (the cell rule is only approximate where a cell straddles the kink of a visible-normal pdf)
    assert abs(probabilities.sum() - 1.0) < 1e-4, probabilities.sum()
    theta, psi = sample_coordinates(h, stretch_x, stretch_y)
    observed, _, _ = np.histogram2d(theta, psi, bins=(theta_edges, psi_edges))
    assert observed.sum() == n
    p_value = chi_square_p_value(observed, probabilities * n)
    assert p_value > CHI2_SIGNIFICANCE, p_value


def test_chi_square_is_not_blind(rng):
    # samples of α = 0.3 must fail against the pdf of α = 0.31 (and γ = 1 against γ = 1.05)
    u1, u2 = uniforms(rng, 200_000)
    for h, pdf, stretch in [
        (mf.GGX(0.3, 0.3).sample(u1, u2), lambda v: mf.GGX(0.31, 0.31).pdf(v), 0.31),
        (mf.GTR(0.2, 1.0).sample(u1, u2), lambda v: mf.GTR(0.2, 1.05).pdf(v), 0.2),
    ]:
        with pytest.raises(AssertionError):
            check_sampler(h, pdf, stretch, stretch)


def uniforms(rng, n):
    return rng.random(n), rng.random(n)


@pytest.mark.parametrize("alpha, gamma, closed_forms", GTR_SAMPLER_CASES)
def test_gtr_sampler_matches_pdf(rng, alpha, gamma, closed_forms):
    u1, u2 = uniforms(rng, 200_000)
    h = mf.GTR(alpha, gamma, closed_forms=closed_forms).sample(u1, u2)
    check_sampler(h, lambda v: mf.GTR(alpha, gamma, closed_forms=closed_forms).pdf(v), alpha, alpha)


@pytest.mark.parametrize("alpha_x, alpha_y", ANISO_SAMPLER_ALPHAS)
def test_ggx_sampler_matches_pdf(rng, alpha_x, alpha_y):
    u1, u2 = uniforms(rng, 200_000)
    h = mf.GGX(alpha_x, alpha_y).sample(u1, u2)
    check_sampler(h, lambda v: mf.GGX(alpha_x, alpha_y).pdf(v), alpha_x, alpha_y)


@pytest.mark.parametrize("alpha_x, alpha_y", ANISO_SAMPLER_ALPHAS)
def test_beckmann_sampler_matches_pdf(rng, alpha_x, alpha_y):
    u1, u2 = uniforms(rng, 200_000)
    h = mf.Beckmann(alpha_x, alpha_y).sample(u1, u2)
    check_sampler(h, lambda v: mf.Beckmann(alpha_x, alpha_y).pdf(v), alpha_x, alpha_y)


@pytest.mark.parametrize("alpha_x, alpha_y, theta_deg, phi", VISIBLE_SAMPLER_CASES)
def test_visible_normal_sampler_matches_pdf(rng, alpha_x, alpha_y, theta_deg, phi):
    wo = direction(theta_deg, phi)
    u1, u2 = uniforms(rng, 200_000)
    h = mf.GGX(alpha_x, alpha_y).sample_visible(wo, u1, u2)
    mirrored = wo if wo[2] >= 0 else -wo
    assert np.all(h @ mirrored >= -1e-15)  # only visible normals
    check_sampler(h, lambda v: mf.GGX(alpha_x, alpha_y).pdf_visible(v, wo), alpha_x, alpha_y)


EQUAL_AREA_SAMPLERS = {
    "gtr-1": (lambda a, b: mf.GTR(0.5, 1.0).sample(a, b), lambda v: mf.GTR(0.5, 1.0).pdf(v)),
    "gtr-1.5": (lambda a, b: mf.GTR(0.5, 1.5).sample(a, b), lambda v: mf.GTR(0.5, 1.5).pdf(v)),
    "gtr-2": (lambda a, b: mf.GTR(0.5, 2.0).sample(a, b), lambda v: mf.GTR(0.5, 2.0).pdf(v)),
    "gtr-3": (lambda a, b: mf.GTR(0.5, 3.0).sample(a, b), lambda v: mf.GTR(0.5, 3.0).pdf(v)),
    "ggx": (lambda a, b: mf.GGX(0.8, 0.08).sample(a, b), lambda v: mf.GGX(0.8, 0.08).pdf(v)),
    "beckmann": (lambda a, b: mf.Beckmann(0.8, 0.08).sample(a, b), lambda v: mf.Beckmann(0.8, 0.08).pdf(v)),
    "visible-0": (lambda a, b: mf.GGX(0.6, 0.2).sample_visible(direction(0.0), a, b),
                  lambda v: mf.GGX(0.6, 0.2).pdf_visible(v, direction(0.0))),
    "visible-60": (lambda a, b: mf.GGX(0.6, 0.2).sample_visible(direction(60.0, 0.5), a, b),
                   lambda v: mf.GGX(0.6, 0.2).pdf_visible(v, direction(60.0, 0.5))),
    "visible-85": (lambda a, b: mf.GGX(0.6, 0.2).sample_visible(direction(85.0, 1.0), a, b),
                   lambda v: mf.GGX(0.6, 0.2).pdf_visible(v, direction(85.0, 1.0))),
}


@pytest.mark.parametrize("case", EQUAL_AREA_CASES)
def test_sampler_equal_area_grid(rng, case):
    # docs/validation.md's grid: 10^6 samples, 50 x 50 cells of equal solid angle
    sample, pdf = EQUAL_AREA_SAMPLERS[case]
    h = sample(*uniforms(rng, 1_000_000))
    check_sampler(h, pdf, 1.0, 1.0, equal_area=True)


def test_samplers_at_the_ends_of_the_unit_interval():
    u = np.array([0.0, 1e-300, 0.5, 1.0 - 2.0 ** -53, 1.0])
    u1, u2 = np.meshgrid(u, u)
    for h in (mf.GTR(0.3, 1.0).sample(u1, u2), mf.GTR(0.3, 2.7).sample(u1, u2), mf.GGX(0.3, 0.03).sample(u1, u2),
              mf.Beckmann(0.3, 0.03).sample(u1, u2), mf.GGX(0.3, 0.03).sample_visible([0.6, 0.0, 0.8], u1, u2),
              mf.GGX(0.3, 0.03).sample_visible([1.0, 0.0, 0.0], u1, u2)):
        assert h.shape == (5, 5, 3)
        assert np.all(np.isfinite(h)) and np.all(h[..., 2] >= 0.0)
        np.testing.assert_allclose(np.linalg.norm(h, axis=-1), 1.0, rtol=1e-15)
    # u2 = 0 is the normal and u2 = 1 the horizon for the distribution samplers
    for sample in (lambda a, b: mf.GTR(0.3, 1.7).sample(a, b), lambda a, b: mf.GGX(0.3, 0.5).sample(a, b),
                   lambda a, b: mf.Beckmann(0.3, 0.5).sample(a, b)):
        np.testing.assert_array_equal(sample(0.3, 0.0), [0.0, 0.0, 1.0])
        assert sample(0.3, 1.0)[2] == pytest.approx(0.0, abs=1e-16)


# --------------------------------------------------------------------------
# finite everywhere in the domain (docs/validation.md)


def test_no_nan_or_inf_anywhere():
    alphas = np.array([5e-324, 1e-300, 1e-12, 1e-4, 0.001, 0.3, 1.0 - 1e-16, 1.0])
    gammas = np.array([5e-324, 1e-6, 0.5, 1.0 - 1e-15, 1.0, 1.0 + 1e-15, 1.5, 2.0, 3.0, 50.0, 1e6])
    cosines = np.array([-1.0, -1e-300, 0.0, 5e-324, 1e-150, 1e-8, 0.5, 1.0 - 1e-16, 1.0])
    u = np.array([0.0, 5e-324, 1e-300, 0.5, 1.0 - 2.0 ** -53, 1.0])
    grid = np.meshgrid(cosines, alphas, gammas, indexing="ij")
    h_grid = half_vector(grid[0])
    d = mf.GTR(grid[1], grid[2]).d(h_grid)
    assert np.all(np.isfinite(d)) and np.all(d >= 0.0)
    assert np.all(np.isfinite(mf.GTR(grid[1], grid[2], closed_forms=False).d(h_grid)))
    ua, ub, a, g = np.meshgrid(u, u, alphas, gammas, indexing="ij")
    for closed in (True, False):
        h = mf.GTR(a, g, closed_forms=closed).sample(ua, ub)
        assert np.all(np.isfinite(h))
        assert np.all(np.isfinite(mf.GTR(a, g, closed_forms=closed).pdf(h)))

    zs = np.array([-1.0, -0.5, -1e-300, 0.0, 5e-324, 1e-200, 1e-8, 0.3, 1.0 - 1e-16, 1.0])
    phis = np.array([0.0, 0.3, np.pi / 2, 2.0])
    z, phi = np.meshgrid(zs, phis, indexing="ij")
    s = np.sqrt(1.0 - z * z)
    w = np.stack([s * np.cos(phi), s * np.sin(phi), z], axis=-1).reshape(-1, 3)
    ggx_alphas = np.array([5e-324, 1e-12, 1e-3, 0.3, 1.0, 50.0, 1e300])
    ax, ay = np.meshgrid(ggx_alphas, ggx_alphas, indexing="ij")
    ax, ay = ax.ravel()[:, None], ay.ravel()[:, None]
    wi, wo = w[None, :, None, :], w[None, None, :, :]
    axx, ayy = ax[..., None], ay[..., None]
    for name, values in [
        ("ggx_d", mf.GGX(ax, ay).d(w)),
        ("ggx_pdf", mf.GGX(ax, ay).pdf(w)),
        ("ggx_g1", mf.GGX(ax, ay).g1(w)),
        ("ggx_g2_separable", mf.GGX(axx, ayy).g2(wi, wo, correlated=False)),
        ("ggx_g2_height_correlated", mf.GGX(axx, ayy).g2(wi, wo)),
        ("ggx_pdf_visible", mf.GGX(axx, ayy).pdf_visible(wi, wo)),
        ("beckmann_d", mf.Beckmann(ax, ay).d(w)),
        ("beckmann_pdf", mf.Beckmann(ax, ay).pdf(w)),
        ("beckmann_g1", mf.Beckmann(ax, ay).g1(w)),
    ]:
        assert np.all(np.isfinite(values)), name
        assert np.all(values >= 0.0), name
    for lam in (mf.GGX(ax, ay).lambda_(w), mf.Beckmann(ax, ay).lambda_(w)):
        assert not np.any(np.isnan(lam)) and np.all(lam >= 0.0)
        # +inf only where the true Λ ~ α sinθ / (2|cosθ|) is beyond the double range
        assert np.all(np.isfinite(lam) | (np.abs(np.broadcast_to(w[:, 2], lam.shape)) < 1e-290))
    u1, u2 = np.meshgrid(u, u)
    for a_x in ggx_alphas:
        for a_y in ggx_alphas:
            for h in (mf.GGX(a_x, a_y).sample(u1, u2), mf.Beckmann(a_x, a_y).sample(u1, u2),
                      mf.GGX(a_x, a_y).sample_visible(w[:, None, None, :], u1, u2)):
                assert np.all(np.isfinite(h)), (a_x, a_y)


# --------------------------------------------------------------------------
# the Python API: broadcasting, shapes, dtypes


def test_broadcasting_and_shapes():
    c = np.linspace(0.0, 1.0, 4).reshape(4, 1)
    alpha = np.array([0.1, 0.5, 1.0])
    d = mf.GTR(alpha, 2.0).d(half_vector(c))
    assert d.shape == (4, 3) and d.dtype == np.float64
    np.testing.assert_array_equal(d[2], [float(mf.GTR(a, 2.0).d(half_vector(c[2, 0]))) for a in alpha])
    assert isinstance(mf.GTR(0.5, 1.0).d(half_vector(0.5)), np.ndarray)
    assert mf.GTR(0.5, 1.0).d(half_vector(0.5)).shape == ()
    assert mf.GTR(0.3, 1.0).sample(0.1, 0.2).shape == (3,)
    assert mf.GTR(0.3, 1.0).sample([0.1, 0.2], [[0.2], [0.3], [0.4]]).shape == (3, 2, 3)
    h = mf.GGX(0.2, np.array([0.1, 0.2, 0.3, 0.4, 0.5])).sample(np.full((2, 5), 0.3), 0.5)
    assert h.shape == (2, 5, 3)
    assert mf.GGX(0.2, 0.1).d(h).shape == (2, 5)
    assert mf.GGX(np.array([0.1, 0.2]), 0.1).d(h[0, 0]).shape == (2,)
    assert mf.GGX(0.2, 0.1).pdf_visible(h, [0.0, 0.0, 1.0]).shape == (2, 5)
    assert mf.GGX(0.2).g2(h[:, :1], h[:1, :], correlated=False).shape == (2, 5)
    assert mf.GGX(0.3).sample_visible(h, 0.5, 0.5).shape == (2, 5, 3)
    assert mf.Beckmann(0.3).lambda_(np.zeros((0, 3))).shape == (0,)
    assert mf.GTR(0.3, 1.0).sample(np.zeros(0), 0.5).shape == (0, 3)
    # alpha_y defaults to alpha_x; integer and list inputs are read as float64
    np.testing.assert_array_equal(mf.GGX(0.2).d(h), mf.GGX(0.2, 0.2).d(h))
    assert float(mf.GGX(1).g1([0, 0, 1])) == 1.0
    # directions are normalised before use (length off by < 1e-3 is accepted)
    np.testing.assert_allclose(mf.GGX(0.3).d([0.0, 0.0, 1.0005]), mf.GGX(0.3).d([0.0, 0.0, 1.0]), rtol=1e-15)
    # non-contiguous and float32 inputs
    hh = np.ascontiguousarray(np.broadcast_to(h[..., None], h.shape + (2,)))[..., 0]
    np.testing.assert_array_equal(mf.Beckmann(0.2, 0.4).d(hh), mf.Beckmann(0.2, 0.4).d(h))
    h32 = np.array([0.484375, 0.0, 0.875], dtype=np.float32)  # exact in float32, of length 1 within 1.3e-4
    np.testing.assert_array_equal(mf.GTR(0.5, 1.5).d(h32), mf.GTR(0.5, 1.5).d(h32.astype(np.float64)))


BAD_INPUT = [
    (lambda: mf.GTR(0.0, 1.0).d([0.0, 0.0, 1.0]), ValueError, "alpha"),
    (lambda: mf.GTR([0.5, 1.2], 1.0).d([0.0, 0.0, 1.0]), ValueError, r"alpha\[1\]"),
    (lambda: mf.GTR(0.5, [[1.0, 2.0], [0.0, 1.0]]).d([0.0, 0.0, 1.0]), ValueError, r"gamma\[1, 0\]"),
    (lambda: mf.GTR(0.5, -1.0).d([0.0, 0.0, 1.0]), ValueError, "gamma"),
    (lambda: mf.GTR(0.5, 2e6).d([0.0, 0.0, 1.0]), ValueError, "gamma"),
    (lambda: mf.GTR(0.5, np.nan).d([0.0, 0.0, 1.0]), ValueError, "gamma"),
    (lambda: mf.GTR(0.5, 1.0).d([[0.0, 0.0, 1.0], [0.0, 0.0, 1.5]]), ValueError, r"h\[1\]"),
    (lambda: mf.GTR(0.5, 1.0).d([[0.0, 0.0, 1.0], [np.inf, 0.0, 1.0]]), ValueError, r"h\[1, 0\]"),
    (lambda: mf.GTR(0.5, 1.0).d("0.5"), TypeError, "h"),
    (lambda: mf.GTR(0.5, 1.0).d(0.5), ValueError, r"h: expected shape \(\.\.\., 3\)"),
    (lambda: mf.GTR(0.5 + 0.1j, 1.0).d([0.0, 0.0, 1.0]), TypeError, "alpha"),
    (lambda: mf.GTR(None, 1.0).d([0.0, 0.0, 1.0]), TypeError, "alpha"),
    (lambda: mf.GTR(np.full(2, 0.5), 1.0).d(np.zeros((3, 3)) + [0.0, 0.0, 1.0]), ValueError, "broadcast"),
    (lambda: mf.GTR(0.5, 1.0).sample(-0.1, 0.5), ValueError, "u1"),
    (lambda: mf.GTR(0.5, 1.0).sample(0.1, [0.5, 1.0 + 1e-12]), ValueError, r"u2\[1\]"),
    (lambda: mf.GTR(0.5, 1.0).pdf([0.0, 0.0, 1.1]), ValueError, "h"),
    (lambda: mf.GTR(0.5, 1.0).pdf([[0.0, 0.0, 1.0], [0.0, 0.0, 0.5]]), ValueError, r"h\[1\]"),
    (lambda: mf.GGX(0.5).d([0.0, 1.0]), ValueError, "h"),
    (lambda: mf.GGX(-0.5).d([0.0, 0.0, 1.0]), ValueError, "alpha_x"),
    (lambda: mf.GGX(0.5, [0.1, 0.0]).d([0.0, 0.0, 1.0]), ValueError, r"alpha_y\[1\]"),
    (lambda: mf.GGX(0.5, np.inf).d([0.0, 0.0, 1.0]), ValueError, "alpha_y"),
    (lambda: mf.GGX("rough").d([0.0, 0.0, 1.0]), TypeError, "alpha_x"),
    (lambda: mf.GGX(0.5).d(np.array([["a", "b", "c"]])), TypeError, "h"),
    (lambda: mf.GGX(0.5).sample(0.5, 2.0), ValueError, "u2"),
    (lambda: mf.GGX(0.5).sample_visible([np.nan, 0.0, 1.0], 0.5, 0.5), ValueError, r"wo"),
    (lambda: mf.GGX(0.5).sample_visible([0.0, 0.0, 1.0], 0.5, -0.5), ValueError, "u2"),
    (lambda: mf.GGX(0.5).pdf_visible([0.0, 0.0, 1.0], [0.0, 0.0, 2.0]), ValueError, "wo"),
    (lambda: mf.GGX(0.5).lambda_([[0.0, 0.0, 1.0]] * 2 + [[1.0, 1.0, 1.0]]), ValueError, r"w\[2\]"),
    (lambda: mf.GGX(0.0).g1([0.0, 0.0, 1.0]), ValueError, "alpha_x"),
    (lambda: mf.GGX(0.5).g2([0.0, 0.0, 1.0], [0.0, 0.0, 0.9], correlated=False), ValueError, "wo"),
    (lambda: mf.GGX(0.5).g2([0.0, 0.0, 0.9], [0.0, 0.0, 1.0]), ValueError, "wi"),
    (lambda: mf.GGX(0.5).g2(np.zeros((2, 3)) + [0, 0, 1], np.zeros((3, 3)) + [0, 0, 1]),
     ValueError, "broadcast"),
    (lambda: mf.Beckmann(0.5, -1.0).d([0.0, 0.0, 1.0]), ValueError, "alpha_y"),
    (lambda: mf.Beckmann(np.nan).lambda_([0.0, 0.0, 1.0]), ValueError, "alpha_x"),
    (lambda: mf.Beckmann(0.5).g1([0.0, 0.0]), ValueError, "w"),
    (lambda: mf.Beckmann(0.5).sample(0.5, np.nan), ValueError, "u2"),
    (lambda: mf.Beckmann(0.5, object()).pdf([0.0, 0.0, 1.0]), TypeError, "alpha_y"),
]


@pytest.mark.parametrize("call, error, pattern", BAD_INPUT)
def test_bad_input(call, error, pattern):
    with pytest.raises(error, match=pattern):
        call()
