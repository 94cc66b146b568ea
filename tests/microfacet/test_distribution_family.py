"""The microfacet family of principled_brdf.microfacet: Student-t, exponential power, Blinn-Phong,
Beckmann's rational Λ and GGX's combined G2 / (4 cos θi cos θo) with its approximations.

Two independent quadratures check the library's formulas:

- over the hemisphere of half vectors in (θ, ψ), ψ the stretched azimuth (tan φ = (αy/αx) tan ψ,
  periodic trapezoid rule), θ cut into panels doubling from min(α)/8 and halving towards π/2 down
  to 1e-40 (the Student-t D grows like cos^(2γ-4) θ at the horizon), Gauss-Legendre on each; the
  kink of max(0, wo·h) is one more panel end on each ψ row;
- over the plane of slopes (x, y) = (αx r cos ψ, αy r sin ψ) in (ψ, ln r), where Smith's
  definition (Heitz 2014 eq. 72 in slope space) reads
      Λ(w) = (1 / w·n) ∫∫ max(0, x w_x + y w_y - w·n) P22(x, y) dx dy,   P22 = D(m) cos⁴θm,
  the outer integral in ψ by scipy's adaptive quad (the integrand has algebraic ends), the inner
  one in ln r by Gauss-Legendre panels of unit width from the kink out to where the tail is below
  1e-8 of the integral.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy import integrate

import chi_square as cs
from principled_brdf import microfacet as mf

TWO_PI = 2.0 * np.pi


def direction(theta_deg: float, phi: float = 0.0) -> np.ndarray:
    t = np.radians(theta_deg)
    return np.array([np.sin(t) * np.cos(phi), np.sin(t) * np.sin(phi), np.cos(t)])


# --------------------------------------------------------------------------
# the family as (name, shape values, D, Λ, sampler, pdf, visible pdf, tail of the slope density)


def student_t(gamma):
    return dict(
        d=lambda h, ax, ay: mf.StudentT(ax, ay, gamma=gamma).d(h),
        pdf=lambda h, ax, ay: mf.StudentT(ax, ay, gamma=gamma).pdf(h),
        lam=lambda w, ax, ay: mf.StudentT(ax, ay, gamma=gamma).lambda_(w),
        g1=lambda w, ax, ay: mf.StudentT(ax, ay, gamma=gamma).g1(w),
        sample=lambda u1, u2, ax, ay: mf.StudentT(ax, ay, gamma=gamma).sample(u1, u2),
        visible=lambda h, wo, ax, ay: mf.StudentT(ax, ay, gamma=gamma).pdf_visible(h, wo),
        # the slope density falls as r^-2γ: Smith's integrand as r^(3-2γ) beyond sqrt(γ-1)
        tail_span=lambda s0: max(s0, 0.5 * np.log(gamma - 1.0)) + 18.0 / (2.0 * gamma - 3.0) + 3.0,
    )


def exponential_power(p):
    return dict(
        d=lambda h, ax, ay: mf.ExponentialPower(ax, ay, p=p).d(h),
        pdf=lambda h, ax, ay: mf.ExponentialPower(ax, ay, p=p).pdf(h),
        lam=lambda w, ax, ay: mf.ExponentialPower(ax, ay, p=p).lambda_(w),
        g1=lambda w, ax, ay: mf.ExponentialPower(ax, ay, p=p).g1(w),
        sample=lambda u1, u2, ax, ay: mf.ExponentialPower(ax, ay, p=p).sample(u1, u2),
        visible=lambda h, wo, ax, ay: mf.ExponentialPower(ax, ay, p=p).pdf_visible(h, wo),
        # exp(-r^(2p)) < e^-60 beyond r = 60^(1/2p)
        tail_span=lambda s0: max(s0 + 3.0, np.log(60.0) / (2.0 * p) + 1.0),
        step=min(1.0, 0.5 / p),  # r^(2p) changes by e^(2p step) across a panel
    )


BLINN_PHONG = dict(
    d=lambda h, ax, ay: mf.BlinnPhong(ax, ay).d(h),
    pdf=lambda h, ax, ay: mf.BlinnPhong(ax, ay).pdf(h),
    lam=lambda w, ax, ay: mf.BlinnPhong(ax, ay).lambda_(w),
    g1=lambda w, ax, ay: mf.BlinnPhong(ax, ay).g1(w),
    sample=lambda u1, u2, ax, ay: mf.BlinnPhong(ax, ay).sample(u1, u2),
    visible=lambda h, wo, ax, ay: mf.BlinnPhong(ax, ay).pdf_visible(h, wo),
    tail_span=lambda s0: max(s0 + 3.0, 4.0),
)

STUDENT_GAMMAS = (1.6, 2.0, 2.5, 4.0, 20.0)
EXPONENTIAL_PS = (0.3, 0.5, 1.0, 2.0, 4.0)
FAMILY = ([(f"student_t-{g}", student_t(g)) for g in STUDENT_GAMMAS]
          + [(f"exponential_power-{p}", exponential_power(p)) for p in EXPONENTIAL_PS])
FAMILY_IDS = [name for name, _ in FAMILY]
FAMILY_MEMBERS = [member for _, member in FAMILY]
ALPHAS = [(0.05, 0.05), (0.3, 0.3), (1.0, 1.0), (0.5, 0.08), (0.1, 0.7)]


# --------------------------------------------------------------------------
# the hemisphere rule


def theta_breaks(alpha_min: float, horizon_halvings: int = 130) -> np.ndarray:
    breaks = [0.0]
    edge = alpha_min / 8.0
    while edge < np.pi / 4:
        breaks.append(edge)
        edge *= 2.0
    breaks += [np.pi / 2 - (np.pi / 4) * 0.5 ** k for k in range(horizon_halvings)]
    breaks.append(np.pi / 2)
    return np.unique(np.array(breaks))


def hemisphere_nodes(alpha_x, alpha_y, n_psi=64, n_gl=12, kink=None, split=1):
    """Nodes h (n_psi, m, 3) and weights (n_psi, m) of ∫ g(h) dω_h over the upper hemisphere
    (each θ panel cut into ``split`` equal ones)."""
    x, w = np.polynomial.legendre.leggauss(n_gl)
    psi = TWO_PI * (np.arange(n_psi) + 0.5) / n_psi
    phi = np.arctan2(alpha_y * np.sin(psi), alpha_x * np.cos(psi))
    dphi_dpsi = alpha_x * alpha_y / ((alpha_x * np.cos(psi)) ** 2 + (alpha_y * np.sin(psi)) ** 2)
    common = theta_breaks(min(alpha_x, alpha_y))
    if split > 1:
        common = np.concatenate([np.linspace(a, b, split, endpoint=False) for a, b in zip(common[:-1], common[1:])]
                                + [common[-1:]])
    breaks = np.broadcast_to(common, (n_psi, common.size))
    if kink is not None:
        breaks = np.sort(np.concatenate([breaks, kink(phi)[:, None]], axis=1), axis=1)
    lo, hi = breaks[:, :-1, None], breaks[:, 1:, None]
    theta = (0.5 * (lo + hi) + 0.5 * (hi - lo) * x).reshape(n_psi, -1)
    weight = (0.5 * (hi - lo) * w).reshape(n_psi, -1) * np.sin(theta) * (dphi_dpsi * TWO_PI / n_psi)[:, None]
    s = np.sin(theta)
    # cos θ as sin(π/2 - θ): full relative precision next to the horizon
    h = np.stack([s * np.cos(phi)[:, None], s * np.sin(phi)[:, None], np.sin(np.pi / 2 - theta)], axis=-1)
    return h, weight


def horizon_of(wo):
    """On each azimuth φ, the θ where wo·h changes sign (π/2 where it stays positive)."""
    sin_o, cos_o = np.hypot(wo[0], wo[1]), wo[2]
    phi_o = np.arctan2(wo[1], wo[0])

    def kink(phi):
        c = np.cos(phi - phi_o)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(c < 0.0, np.arctan2(cos_o, -sin_o * c), np.pi / 2)

    return kink


def hemisphere_integral(g, alpha_x, alpha_y, **options) -> float:
    h, weight = hemisphere_nodes(alpha_x, alpha_y, **options)
    return float(np.sum(g(h.reshape(-1, 3)).reshape(weight.shape) * weight))


# --------------------------------------------------------------------------
# Smith's Λ by its definition in slope space

_GL_X, _GL_W = np.polynomial.legendre.leggauss(12)


def lambda_by_definition(d_fn, tail_span, w, alpha_x, alpha_y, step=1.0) -> float:
    cz = w[2]
    cx, cy = alpha_x * w[0], alpha_y * w[1]
    projected = math.hypot(cx, cy)
    psi0 = math.atan2(cy, cx)

    def inner(chi):
        c = projected * math.cos(chi)
        if c <= 0.0:
            return 0.0
        s0 = math.log(cz / c)
        edges = np.arange(s0, tail_span(s0) + step, step)
        s = (0.5 * (edges[:-1, None] + edges[1:, None]) + 0.5 * step * _GL_X).ravel()
        weight = np.broadcast_to(0.5 * step * _GL_W, (edges.size - 1, _GL_X.size)).ravel()
        r = np.exp(s)
        psi = psi0 + chi
        x, y = alpha_x * r * math.cos(psi), alpha_y * r * math.sin(psi)
        norm2 = 1.0 + x * x + y * y
        m = np.stack([x, y, np.ones_like(x)], axis=-1) / np.sqrt(norm2)[:, None]
        p22 = d_fn(m, alpha_x, alpha_y) / (norm2 * norm2)
        # dx dy = αx αy r dr dψ = αx αy r² ds dψ
        return float(np.sum(weight * (r * c - cz) * p22 * alpha_x * alpha_y * r * r))

    with warnings.catch_warnings():  # quad may report round-off at 1e-10 where it has reached ~1e-12
        warnings.simplefilter("ignore", integrate.IntegrationWarning)
        value, _ = integrate.quad(inner, -np.pi / 2, np.pi / 2, epsabs=0.0, epsrel=1e-10, limit=200)
    return value / cz


# --------------------------------------------------------------------------
# normalisation: ∫ D(h) cos θh dω_h = 1 (bound 1e-4; the rule reaches ~1e-9, ~1e-6 for the
# steep shoulder of exp(-r^8) at p = 4)


@pytest.mark.parametrize("member", FAMILY_MEMBERS + [BLINN_PHONG], ids=FAMILY_IDS + ["blinn_phong"])
def test_normalised(member):
    for alpha_x, alpha_y in ALPHAS:
        total = hemisphere_integral(lambda h: member["d"](h, alpha_x, alpha_y) * h[:, 2], alpha_x, alpha_y)
        assert abs(total - 1.0) < 1e-5, (alpha_x, alpha_y, total)
        total_pdf = hemisphere_integral(lambda h: member["pdf"](h, alpha_x, alpha_y), alpha_x, alpha_y, n_psi=16)
        assert abs(total_pdf - 1.0) < 1e-5, (alpha_x, alpha_y, total_pdf)


def test_normalised_across_the_shape_range():
    # the ends of the ranges: γ just above 3/2 (the heaviest tail), large γ; p = 0.1 and 10
    cases = [student_t(1.52), student_t(1e4), exponential_power(0.15), exponential_power(10.0)]
    for member in cases:
        for alpha_x, alpha_y in [(0.05, 0.05), (0.6, 0.2), (1.0, 1.0)]:
            # split: the shoulder of exp(-r^20) at p = 10 is nearly a step
            total = hemisphere_integral(lambda h: member["pdf"](h, alpha_x, alpha_y), alpha_x, alpha_y, n_psi=16,
                                        n_gl=16, split=8)
            assert abs(total - 1.0) < 1e-4, (alpha_x, alpha_y, total)


def test_quadrature_is_not_blind():
    total = hemisphere_integral(lambda h: 1.00001 * mf.StudentT(0.5, 0.05, gamma=1.6).pdf(h), 0.5, 0.05)
    assert abs(total - 1.00001) < 1e-7


# --------------------------------------------------------------------------
# Λ against Smith's definition (bound 1e-6 relative)

LAMBDA_VIEWS = [(20.0, 0.3), (60.0, 1.1), (85.0, 2.0)]
LAMBDA_ALPHAS = [(0.3, 0.3), (0.6, 0.1)]


@pytest.mark.parametrize("member", FAMILY_MEMBERS, ids=FAMILY_IDS)
def test_lambda_matches_its_definition(member):
    for alpha_x, alpha_y in LAMBDA_ALPHAS:
        for theta_deg, phi in LAMBDA_VIEWS:
            w = direction(theta_deg, phi)
            expected = lambda_by_definition(member["d"], member["tail_span"], w, alpha_x, alpha_y,
                                            member.get("step", 1.0))
            got = float(member["lam"](w, alpha_x, alpha_y))
            assert abs(got - expected) <= 1e-6 * expected + 1e-12, (alpha_x, alpha_y, theta_deg, got, expected)


def test_beckmann_lambda_matches_its_definition():
    # the harness itself, on the exact Beckmann Λ (erf form)
    for theta_deg, phi in LAMBDA_VIEWS:
        w = direction(theta_deg, phi)
        expected = lambda_by_definition(lambda h, ax, ay: mf.Beckmann(ax, ay).d(h), BLINN_PHONG["tail_span"], w, 0.6, 0.1)
        assert abs(float(mf.Beckmann(0.6, 0.1).lambda_(w)) - expected) <= 1e-8 * expected + 1e-14


def test_blinn_phong_lambda_is_beckmanns_approximation():
    # Beckmann's Λ for Blinn-Phong's own D (Walter et al. 2007 §5.2): G1 against the Smith G1 of
    # that D (1/(1 + Λ) with Λ by the definition) is off by 2.2e-5 at α = 0.05, 2.2e-2 at 0.3,
    # 0.13 at 0.6, 0.64 at 1 (worst at 85°): good for smooth surfaces only
    for alpha, bound in [(0.3, 2.5e-2), (0.6, 0.14), (1.0, 0.66)]:
        for theta_deg, phi in LAMBDA_VIEWS:
            w = direction(theta_deg, phi)
            expected = lambda_by_definition(BLINN_PHONG["d"], BLINN_PHONG["tail_span"], w, alpha, alpha)
            got = float(mf.BlinnPhong(alpha).lambda_(w))
            assert got == float(mf.Beckmann(alpha).lambda_(w))
            assert abs(float(mf.BlinnPhong(alpha).g1(w)) * (1.0 + expected) - 1.0) < bound, (alpha, theta_deg)


# --------------------------------------------------------------------------
# weak white furnace: ∫ G1(wo) D(h) max(0, wo·h) / |wo·n| dω_h = 1 (bound 1e-3)

FURNACE_VIEWS = [(0.0, 0.0), (45.0, 0.3), (75.0, 1.2), (88.0, 0.7)]
FURNACE_ALPHAS = [(0.05, 0.05), (0.3, 0.3), (1.0, 0.2)]


def furnace(member, wo, alpha_x, alpha_y):
    g1 = float(member["g1"](wo, alpha_x, alpha_y))

    def integrand(h):
        return g1 * member["d"](h, alpha_x, alpha_y) * np.maximum(0.0, h @ wo) / abs(wo[2])

    return hemisphere_integral(integrand, alpha_x, alpha_y, n_psi=192, kink=horizon_of(wo))


@pytest.mark.parametrize("member", FAMILY_MEMBERS, ids=FAMILY_IDS)
def test_weak_white_furnace(member):
    for alpha_x, alpha_y in FURNACE_ALPHAS:
        for theta_deg, phi in FURNACE_VIEWS:
            total = furnace(member, direction(theta_deg, phi), alpha_x, alpha_y)
            assert abs(total - 1.0) < 1e-3, (alpha_x, alpha_y, theta_deg, total)


def test_blinn_phong_weak_white_furnace_with_beckmanns_lambda():
    # not exact (Beckmann's Λ is not Blinn-Phong's): it misses 1 by 2.8e-4 at α = 0.05,
    # 2.9e-2 at 0.3, 0.15 at 0.6 and 0.73 at 1, each at the 88° view
    for alpha, bound in [(0.05, 1e-3), (0.3, 3e-2), (0.6, 0.16), (1.0, 0.75)]:
        for theta_deg, phi in FURNACE_VIEWS:
            total = furnace(BLINN_PHONG, direction(theta_deg, phi), alpha, alpha)
            assert abs(total - 1.0) < bound, (alpha, theta_deg, total)


def test_walter_weak_white_furnace():
    # Beckmann's D with Walter's rational G1: it misses 1 by up to 3.0e-3 (α = 0.3, 88°)
    for alpha in (0.05, 0.3, 1.0):
        for theta_deg, phi in FURNACE_VIEWS:
            wo = direction(theta_deg, phi)
            g1 = float(mf.Beckmann(alpha, approximation="walter").g1(wo))
            total = hemisphere_integral(lambda h: g1 * mf.Beckmann(alpha).d(h) * np.maximum(0.0, h @ wo) / wo[2],
                                        alpha, alpha, n_psi=192, kink=horizon_of(wo))
            assert abs(total - 1.0) < 3.5e-3, (alpha, theta_deg, total)


# --------------------------------------------------------------------------
# the samplers, by the chi-square of tests/chi_square.py

SAMPLER_CASES = [("student_t-1.6", student_t(1.6), 0.3, 0.3), ("student_t-3", student_t(3.0), 0.5, 0.1),
                 ("exponential_power-0.5", exponential_power(0.5), 0.3, 0.3),
                 ("exponential_power-2", exponential_power(2.0), 0.5, 0.1),
                 ("blinn_phong", BLINN_PHONG, 0.3, 0.3), ("blinn_phong-aniso", BLINN_PHONG, 0.6, 0.2)]
SAMPLER_THRESHOLD = cs.sidak_threshold(len(SAMPLER_CASES))


@pytest.mark.parametrize("name, member, alpha_x, alpha_y", SAMPLER_CASES, ids=[c[0] for c in SAMPLER_CASES])
def test_sampler_matches_pdf(name, member, alpha_x, alpha_y):
    rng = np.random.default_rng(20170421 + len(name))
    u1, u2 = rng.random((2, 40_000))
    h = member["sample"](u1, u2, alpha_x, alpha_y)
    np.testing.assert_allclose(np.linalg.norm(h, axis=-1), 1.0, atol=1e-12)
    result = cs.chi_square_test(h, lambda w: member["pdf"](w, alpha_x, alpha_y), peaks=[[0.0, 0.0, 1.0]],
                                peak_width=min(alpha_x, alpha_y), rtol=1e-5)
    assert abs(result.integral - 1.0) < 1e-4, result.describe()
    assert result.p_value > SAMPLER_THRESHOLD, result.describe()


BECKMANN_VISIBLE_CASES = [(0.3, 0.3, 40.0, 0.5), (0.5, 0.1, 75.0, 2.0), (1.0, 0.6, 0.0, 0.0)]


@pytest.mark.parametrize("alpha_x, alpha_y, theta_deg, phi", BECKMANN_VISIBLE_CASES)
def test_beckmann_visible_sampler_matches_pdf(alpha_x, alpha_y, theta_deg, phi):
    rng = np.random.default_rng(2014 + int(theta_deg))
    u1, u2 = rng.random((2, 40_000))
    wo = direction(theta_deg, phi)
    h = mf.Beckmann(alpha_x, alpha_y).sample_visible(wo, u1, u2)
    np.testing.assert_allclose(np.linalg.norm(h, axis=-1), 1.0, atol=1e-12)
    assert np.all(h @ wo > -1e-12)
    result = cs.chi_square_test(h, lambda w: mf.Beckmann(alpha_x, alpha_y).pdf_visible(w, wo), peaks=[[0.0, 0.0, 1.0]],
                                peak_width=min(alpha_x, alpha_y), rtol=1e-5)
    assert abs(result.integral - 1.0) < 1e-3, result.describe()
    assert result.p_value > cs.sidak_threshold(len(BECKMANN_VISIBLE_CASES)), result.describe()


def test_chi_square_is_not_blind():
    rng = np.random.default_rng(7)
    u1, u2 = rng.random((2, 40_000))
    h = mf.StudentT(0.3, 0.3, gamma=1.6).sample(u1, u2)
    wrong = cs.chi_square_test(h, lambda w: mf.StudentT(0.36, 0.3, gamma=1.6).pdf(w), peaks=[[0.0, 0.0, 1.0]],
                               peak_width=0.3)
    assert wrong.p_value < 1e-6, wrong.describe()


def test_samplers_at_the_ends_of_the_unit_interval():
    for sample in (lambda u1, u2: mf.StudentT(0.3, 0.1, gamma=1.7).sample(u1, u2),
                   lambda u1, u2: mf.ExponentialPower(0.3, 0.1, p=0.4).sample(u1, u2),
                   lambda u1, u2: mf.BlinnPhong(0.3, 0.1).sample(u1, u2),
                   lambda u1, u2: mf.Beckmann(0.5, 0.1).sample_visible(direction(75.0, 2.0), u1, u2)):
        h = sample(np.array([0.0, 0.3, 1.0, 0.7]), np.array([0.0, 1.0, 1e-300, 1.0 - 1e-16]))
        assert np.all(np.isfinite(h))
        np.testing.assert_allclose(np.linalg.norm(h, axis=-1), 1.0, atol=1e-12)
        assert h[0, 2] >= 0.0


def test_visible_normal_pdfs_are_normalised():
    for member in (student_t(1.8), exponential_power(0.6), BLINN_PHONG):
        for theta_deg in (30.0, 80.0):
            wo = direction(theta_deg, 0.4)
            total = hemisphere_integral(lambda h: member["visible"](h, wo, 0.4, 0.15), 0.4, 0.15, n_psi=128,
                                        kink=horizon_of(wo))
            bound = 3e-2 if member is BLINN_PHONG else 1e-3  # Blinn-Phong's Λ is Beckmann's
            assert abs(total - 1.0) < bound, (theta_deg, total)


# --------------------------------------------------------------------------
# limits (bound 1e-6 relative)


def random_unit(rng, n):
    v = rng.normal(size=(n, 3))
    v[:, 2] = np.abs(v[:, 2]) + 1e-3
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def test_student_t_at_gamma_2_is_ggx():
    rng = np.random.default_rng(11)
    h, w = random_unit(rng, 2000), random_unit(rng, 2000)
    ax, ay = rng.uniform(0.05, 1.0, (2, 2000))
    np.testing.assert_allclose(mf.StudentT(ax, ay, gamma=2.0).d(h), mf.GGX(ax, ay).d(h), rtol=1e-12)
    np.testing.assert_allclose(mf.StudentT(ax, ay, gamma=2.0).lambda_(w), mf.GGX(ax, ay).lambda_(w), rtol=1e-12)
    np.testing.assert_allclose(mf.StudentT(ax, ay, gamma=2.0).g2(h, w),
                               mf.GGX(ax, ay).g2(h, w), rtol=1e-12)
    u1, u2 = rng.random((2, 2000))
    np.testing.assert_allclose(mf.StudentT(ax, ay, gamma=2.0).sample(u1, u2), mf.GGX(ax, ay).sample(u1, u2),
                               rtol=1e-10, atol=1e-12)


def test_student_t_tends_to_beckmann():
    # the difference falls as 1/γ: at γ = 1e10 it is 2.4e-8 relative in D, 1.2e-7 in Λ (where
    # Λ > 1e-8) and 4e-11 in G1
    rng = np.random.default_rng(12)
    h, w = random_unit(rng, 2000), random_unit(rng, 2000)
    ax, ay = rng.uniform(0.05, 1.0, (2, 2000))
    beckmann_d, beckmann_lambda = mf.Beckmann(ax, ay).d(h), mf.Beckmann(ax, ay).lambda_(w)
    keep = beckmann_d > 1e-8 * beckmann_d.max()
    np.testing.assert_allclose(mf.StudentT(ax, ay, gamma=1e10).d(h)[keep], beckmann_d[keep], rtol=1e-6)
    visible = beckmann_lambda > 1e-8
    np.testing.assert_allclose(mf.StudentT(ax, ay, gamma=1e10).lambda_(w)[visible], beckmann_lambda[visible],
                               rtol=1e-6)
    np.testing.assert_allclose(mf.StudentT(ax, ay, gamma=1e10).g1(w), mf.Beckmann(ax, ay).g1(w), rtol=1e-6)
    # and as 1/γ: ten times γ, a tenth of the difference
    differences = [np.abs(mf.StudentT(ax, ay, gamma=g).lambda_(w) - beckmann_lambda)[visible].max()
                   for g in (1e3, 1e4)]
    assert 5.0 < differences[0] / differences[1] < 20.0, differences


def test_student_t_lambda_against_mpmath():
    # Ribardière et al. 2017's closed form in 30 digits: below 1e-12 relative for γ <= 20; at large
    # γ the two terms cancel where Λ is small, leaving ~1e-15 absolutely (3e-6 relative at Λ = 4e-10)
    mpmath = pytest.importorskip("mpmath")
    mpmath.mp.dps = 30
    for gamma in (1.51, 1.6, 2.5, 4.0, 20.0, 300.0):
        g = mpmath.mpf(gamma)
        for a in (1e-3, 0.05, 0.3, 1.0, 2.0, 4.0):
            big_a = mpmath.mpf(a)
            s1 = ((g - 1) + big_a * big_a) ** (mpmath.mpf(1.5) - g) / big_a
            s2 = big_a * mpmath.hyp2f1(0.5, g - 0.5, 1.5, -big_a * big_a / (g - 1), maxterms=10 ** 6)
            expected = float(mpmath.gamma(g - 0.5) / (mpmath.gamma(g) * mpmath.sqrt(mpmath.pi))
                             * ((g - 1) ** g / (2 * g - 3) * s1 + mpmath.sqrt(g - 1) * s2) - 0.5)
            w = np.array([1.0, 0.0, a]) / math.hypot(1.0, a)  # a = cot θ / α at α = 1
            got = float(mf.StudentT(1.0, gamma=gamma).lambda_(w))
            assert abs(got - expected) <= 1e-12 * expected + (1e-14 if gamma > 20 else 0.0), (gamma, a, got, expected)


def test_exponential_power_at_p_1_is_beckmann():
    rng = np.random.default_rng(13)
    h, w = random_unit(rng, 2000), random_unit(rng, 2000)
    ax, ay = rng.uniform(0.05, 1.0, (2, 2000))
    np.testing.assert_allclose(mf.ExponentialPower(ax, ay, p=1.0).d(h), mf.Beckmann(ax, ay).d(h), rtol=1e-12,
                               atol=1e-300)
    np.testing.assert_allclose(mf.ExponentialPower(ax, ay, p=1.0).lambda_(w), mf.Beckmann(ax, ay).lambda_(w),
                               rtol=1e-9, atol=1e-300)  # 6e-11 at Λ ~ 1e-250
    u1, u2 = rng.random((2, 2000))
    np.testing.assert_allclose(mf.ExponentialPower(ax, ay, p=1.0).sample(u1, u2), mf.Beckmann(ax, ay).sample(u1, u2),
                               rtol=1e-9, atol=1e-12)


# --------------------------------------------------------------------------
# 2F1 against mpmath (bound 1e-12)


def test_hyp2f1_against_mpmath():
    mpmath = pytest.importorskip("mpmath")
    mpmath.mp.dps = 20
    worst = 0.0
    for gamma in (1.5001, 1.6, 2.0, 2.5, 3.0, 7.0, 40.0, 300.0):
        for z in (-1e-6, -0.01, -0.3, -0.5, -0.9, -1.0, -2.0, -10.0, -1e3, -1e6):
            expected = mpmath.hyp2f1(0.5, mpmath.mpf(gamma) - 0.5, 1.5, z, maxterms=10 ** 6)
            got = float(mf.hyp2f1(0.5, gamma - 0.5, 1.5, z))
            worst = max(worst, abs(got / float(expected) - 1.0))
    for a, b, c, z in [(0.3, 1.7, 2.2, 0.45), (1.0, -2.5, 0.7, -0.49), (2.0, 3.0, 4.5, -0.8), (0.5, 2.0, 1.25, 0.2)]:
        expected = mpmath.hyp2f1(a, b, c, z)
        worst = max(worst, abs(float(mf.hyp2f1(a, b, c, z)) / float(expected) - 1.0))
    assert worst < 1e-12, worst
    assert np.isnan(mf.hyp2f1(1.0, 1.0, 2.0, -3.0))  # outside what it offers


# --------------------------------------------------------------------------
# the approximations' error bounds, over dense grids


def cot_grid():
    # a = cot θ / α_o over (0.01, 6]: where Walter's fit is used and beyond its cut at 1.6
    return np.geomspace(0.01, 6.0, 2001)


def test_walter_lambda_error():
    a = cot_grid()
    w = np.stack([np.ones_like(a), np.zeros_like(a), a], axis=-1) / np.hypot(1.0, a)[:, None]  # α = 1
    exact_g1 = mf.Beckmann(1.0).g1(w)
    walter_g1 = mf.Beckmann(1.0, approximation="walter").g1(w)
    relative = np.abs(walter_g1 / exact_g1 - 1.0)
    # Walter et al. 2007 eq. 27: at most 3.13e-3 relative in G1 (at a = 1.33)
    assert relative.max() < 3.2e-3, relative.max()
    # in Λ: the same bound relative to 1 + Λ, and 1.8e-3 absolutely beyond the cut at a = 1.6
    exact = mf.Beckmann(1.0).lambda_(w)
    walter = mf.Beckmann(1.0, approximation="walter").lambda_(w)
    assert np.all(np.abs(walter - exact) < 3.2e-3 * (1.0 + exact))
    assert np.abs(walter - exact)[a >= 1.6].max() < 1.8e-3
    # and it is the same function of a at any alpha and azimuth
    w2 = direction(70.0, 0.8)
    a2 = w2[2] / math.hypot(0.4 * w2[0], 0.1 * w2[1])
    assert float(mf.Beckmann(0.4, 0.1, approximation="walter").lambda_(w2)) == pytest.approx(
        (1 - 1.259 * a2 + 0.396 * a2 * a2) / (3.535 * a2 + 2.181 * a2 * a2), rel=1e-14)
    g2 = mf.Beckmann(0.4, 0.1, approximation="walter").g2(w2, direction(20.0))
    assert 0.0 < float(g2) <= 1.0


def test_ggx_g2_over_4cos():
    mu = np.linspace(0.05, 1.0, 60)
    mi, mo = (m.ravel() for m in np.meshgrid(mu, mu))
    wi = np.stack([np.sqrt(1 - mi * mi), np.zeros_like(mi), mi], axis=-1)
    wo = np.stack([-np.sqrt(1 - mo * mo) * 0.6, np.sqrt(1 - mo * mo) * 0.8, mo], axis=-1)
    low = {"karis": 0.0, "hammon": 0.0}
    for alpha in np.linspace(0.05, 1.0, 20):
        exact = mf.GGX(alpha).g2_over_4cos(wi, wo)
        # the exact form is G2 / (4 μi μo) with the height-correlated G2
        np.testing.assert_allclose(exact, mf.GGX(alpha).g2(wi, wo) / (4 * mi * mo), rtol=1e-13)
        for name in low:
            relative = mf.GGX(alpha).g2_over_4cos(wi, wo, approximation=name) / exact - 1.0
            assert relative.max() < 1e-12  # neither overestimates
            low[name] = min(low[name], relative.min())
        # Karis's G1 against the exact G1 (what Karis 2013 approximates): within 18.5%
        k = alpha / 2.0
        karis_g1 = mi / (mi * (1.0 - k) + k)
        assert np.all(np.abs(karis_g1 / mf.GGX(alpha).g1(wi) - 1.0) < 0.185)
    # the docstring's bounds: Karis (separable) down to -82% of the height-correlated V
    # (both directions grazing, α = 1), Hammon down to -27.6% (grazing, α = 0.05)
    assert low["karis"] > -0.82 and low["hammon"] > -0.276, low
    # anisotropic exact form equals G2 / (4 μi μo) too
    np.testing.assert_allclose(mf.GGX(0.5, 0.1).g2_over_4cos(wi, wo),
                               mf.GGX(0.5, 0.1).g2(wi, wo) / (4 * mi * mo), rtol=1e-13)


# --------------------------------------------------------------------------
# masking-shadowing relations and bad input


@pytest.mark.parametrize("cls, shape", [(mf.StudentT, {"gamma": 2.7}), (mf.ExponentialPower, {"p": 0.6}),
                                        (mf.BlinnPhong, {}), (mf.Beckmann, {})],
                         ids=["student_t", "exponential_power", "blinn_phong", "beckmann"])
def test_g2_relations(cls, shape):
    rng = np.random.default_rng(14)
    wi, wo = random_unit(rng, 500), random_unit(rng, 500)
    dist = cls(0.4, 0.2, **shape)
    separable = dist.g2(wi, wo, correlated=False)
    correlated = dist.g2(wi, wo)
    np.testing.assert_allclose(separable, dist.g1(wi) * dist.g1(wo), rtol=1e-14)
    assert np.all(correlated >= separable - 1e-15) and np.all(correlated <= 1.0)
    assert float(dist.g1(np.array([0.0, 0.0, 1.0]))) == 1.0
    assert float(dist.g1(np.array([1.0, 0.0, 0.0]))) == 0.0


@pytest.mark.parametrize("call, pattern", [
    (lambda: mf.StudentT(0.3, gamma=1.5).d([0, 0, 1]), "gamma.*outside its domain"),
    (lambda: mf.StudentT(0.3, gamma=np.nan).lambda_([0, 0, 1]), "gamma"),
    (lambda: mf.ExponentialPower(0.3, p=0.05).d([0, 0, 1]), "p.*outside its domain"),
    (lambda: mf.BlinnPhong(1.2).d([0, 0, 1]), "alpha_x.*outside its domain"),
    (lambda: mf.Beckmann(0.3, approximation="karis").lambda_([0, 0, 1]), "approximation"),
    (lambda: mf.GGX(0.3).g2_over_4cos([0, 0, 1], [0, 0, 1], approximation="walter"), "approximation"),
])
def test_bad_input(call, pattern):
    with pytest.raises(ValueError, match=pattern):
        call()


def test_no_nan_anywhere():
    rng = np.random.default_rng(15)
    w = random_unit(rng, 300)
    w[:3] = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.6, 0.8, 1e-200]]
    for alpha in (1e-4, 0.05, 1.0):
        for values in (mf.StudentT(alpha, gamma=1.51).d(w), mf.StudentT(alpha, gamma=1e9).lambda_(w),
                       mf.ExponentialPower(alpha, p=0.1).d(w), mf.ExponentialPower(alpha, p=10.0).lambda_(w),
                       mf.BlinnPhong(alpha).d(w), mf.BlinnPhong(alpha).g1(w),
                       mf.StudentT(alpha, gamma=3.0).pdf_visible(w, w[::-1])):
            assert not np.any(np.isnan(values))
