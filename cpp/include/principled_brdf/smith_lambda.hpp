// Smith's Λ of the shape-invariant slope distributions that have no
// elementary one, in double (docs/model.md "The microfacet family"). For a
// shape-invariant distribution with unit-roughness radial slope density f(r)
// (2π ∫ f(r) r dr = 1), Λ depends on the direction only through
// a = cos θ / sqrt((w·x ax)² + (w·y ay)²) (Heitz 2014 §5.1), and Smith's
// definition Λ = (1/a) ∫_a^∞ (q - a) P2(q) dq over the marginal slope density
// P2 (Heitz 2014 eq. 72 in slope space) becomes, in polar slope coordinates
// with r² = a² + t²,
//   Λ(a) = (2/a) ∫_0^∞ f(sqrt(a² + t²)) (t - a atan(t/a)) t dt.
#pragma once

#include <cmath>
#include <limits>

#include "special_functions.hpp"

namespace principled_brdf::special {

inline constexpr double kInfinity = std::numeric_limits<double>::infinity();

// Student-t slopes (Ribardière et al. 2017), ν = γ - 1 > 1/2:
//   Λ = K ν (1 + a²/ν)^(1/2-ν) / ((2ν - 1) a) - K tail(a),   K = 1 / (2 head(∞)),
// their Λ's two terms with its 2F1 as head(a) = a 2F1(1/2, γ - 1/2; 3/2; -a²/ν) and
// 1/2 - K head(a) = K tail(a) (student_t_integrals: no cancellation in the tail). The two
// terms still cancel where Λ is small at large γ: ~1e-15 absolute error there.
inline double student_t_lambda(double nu, double a) {
    if (!(a > 0.0)) return kInfinity;
    if (std::isinf(a)) return 0.0;
    const double log1p_x = std::log1p(a * a / nu);
    const double log_first = (0.5 - nu) * log1p_x;
    if (log_first < -740.0) return 0.0;  // both terms below the double range
    const StudentTIntegrals integrals = student_t_integrals(nu, a);
    const double k = 0.5 / student_t_half_integral(nu);
    const double value = k * (nu * std::exp(log_first) / ((2.0 * nu - 1.0) * a) - integrals.tail);
    return std::max(value, 0.0);
}

// t - a atan(t/a) = a (u - atan u), u = t/a, by its series where u < 0.3
// (there the difference would cancel)
inline double minus_atan_term(double t, double a) {
    const double u = t / a;
    if (u < 0.3) {
        const double u2 = u * u;
        double sum = 0.0, power = 1.0;
        for (int k = 0; k < 16; ++k) {
            sum += (k % 2 == 0 ? 1.0 : -1.0) * power / (2 * k + 3);
            power *= u2;
        }
        return a * u * u2 * sum;
    }
    return t - a * std::atan(u);
}

// Exponential-power slopes (Holzschuch & Pacanowski 2017), f(r) = p exp(-r^(2p)) / (π Γ(1/p)):
// Λ(a) by the integral above with exp(-(a² + t²)^p) = exp(-a^(2p)) exp(-Δ(t)),
// Δ = a^(2p) expm1(p log1p(t²/a²)) (no cancellation), on panels [0, t0], then
// [t0 2^k, t0 2^(k+1)] until Δ >= 60, 20 Gauss-Legendre nodes each; t1 (Δ(t1) = 1)
// sets the scale and t0 = t1 min(1, a/t1) / 16 resolves the bend of atan at t ~ a.
// Accuracy: within 2e-14 of Beckmann's erf form at p = 1 (6e-11 where Λ ~ 1e-250) and within
// 3.4e-10 of a fine two-dimensional quadrature of Smith's definition for p in [0.3, 4].
inline double exponential_power_lambda(double p, double a) {
    if (!(a > 0.0)) return kInfinity;
    if (std::isinf(a)) return 0.0;
    const double a2p = std::pow(a, 2.0 * p);
    if (a2p > 745.0) return 0.0;
    // Δ through expm1 where t << a (there (a² + t²)^p - a^(2p) would cancel), directly elsewhere
    // (where a^(2p) may underflow and the expm1 form be 0 · inf)
    const auto delta = [&](double t) {
        const double u = t / a;
        return u < 0.01 ? a2p * std::expm1(p * std::log1p(u * u)) : std::pow(a * a + t * t, p) - a2p;
    };
    const double t1 = a2p < 1e-100 ? 1.0 : a * std::sqrt(std::expm1(std::log1p(1.0 / a2p) / p));
    const double t0 = t1 * std::max(std::min(1.0, a / t1), 1e-7) / 16.0;
    const GaussLegendre<20>& rule = GaussLegendre<20>::rule();
    const auto panel = [&](double lo, double hi) {
        double sum = 0.0;
        for (int i = 0; i < 20; ++i) {
            const double t = lo + (hi - lo) * rule.node[i];
            sum += rule.weight[i] * std::exp(-delta(t)) * minus_atan_term(t, a) * t;
        }
        return sum * (hi - lo);
    };
    double integral = panel(0.0, t0);
    for (double lo = t0; lo < 1e300; lo *= 2.0) {
        integral += panel(lo, 2.0 * lo);
        if (delta(2.0 * lo) >= 60.0) break;
    }
    const double norm = p / (3.14159265358979323846 * std::tgamma(1.0 / p));
    return 2.0 * norm / a * std::exp(-a2p) * integral;
}

}  // namespace principled_brdf::special
