// Special functions in double for the microfacet family (docs/model.md "The
// microfacet family"): the Gauss hypergeometric function 2F1 for the
// arguments the Student-t Λ needs, the ratio Γ(x - 1/2) / Γ(x), the
// regularised incomplete gamma function and its inverse, and a Gauss-Legendre
// rule. Written here (not taken from Boost or GSL, neither of which the build
// depends on) because only a narrow slice of each is needed, and that slice
// can be made accurate with short series whose terms are all positive.
#pragma once

#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace principled_brdf::special {

inline constexpr double kSqrtPi = 1.772453850905516027298;
inline constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

// Σ t_k with t_0 = 1 and t_{k+1} / t_k = ratio(k) z, stopped when a term no
// longer changes the sum (or after max_terms).
template <class Ratio>
double power_series(double z, Ratio ratio, int max_terms = 200000) {
    double term = 1.0, sum = 1.0;
    for (int k = 0; k < max_terms; ++k) {
        term *= ratio(k) * z;
        sum += term;
        if (std::abs(term) <= 0.25 * kEpsilon * std::abs(sum)) break;
    }
    return sum;
}

// ln Σ t_k of the same series, the sum rescaled by 1e-250 whenever it passes 1e250
// (the Pfaff series of the Student-t head grows to ~e^(γ w) before its prefactor cancels it)
template <class Ratio>
double log_power_series(double z, Ratio ratio, int max_terms = 200000) {
    double term = 1.0, sum = 1.0, log_scale = 0.0;
    for (int k = 0; k < max_terms; ++k) {
        term *= ratio(k) * z;
        sum += term;
        if (sum > 1e250) {
            sum *= 1e-250;
            term *= 1e-250;
            log_scale += 575.6462732485114;  // 250 ln 10
        }
        if (std::abs(term) <= 0.25 * kEpsilon * std::abs(sum)) break;
    }
    return std::log(sum) + log_scale;
}

// 2F1(a, b; c; z) by its defining series (DLMF 15.2.1), |z| <= 1/2.
inline double hypergeometric_series(double a, double b, double c, double z) {
    return power_series(z, [&](int k) { return (a + k) * (b + k) / ((c + k) * (k + 1.0)); });
}

// ln(Γ(x - 1/2) / Γ(x)), x > 1/2: from std::tgamma for x < 20 (both exact to
// a few ulps there), else Stirling's series (DLMF 5.11.1) with the large terms
// (x - 1) ln(x - 1/2) - (x - 1/2) ln x combined as -ln(x)/2 + (x - 1) log1p(-1/(2x)),
// so that nothing cancels as x -> ∞ (lgamma(x - 1/2) - lgamma(x) would lose ln x digits).
inline double log_gamma_ratio_half(double x) {
    if (x < 20.0) return std::log(std::tgamma(x - 0.5) / std::tgamma(x));
    const auto stirling = [](double y) {
        const double r = 1.0 / (y * y);
        return (1.0 / 12.0 - r * (1.0 / 360.0 - r * (1.0 / 1260.0 - r / 1680.0))) / y;
    };
    return -0.5 * std::log(x) + (x - 1.0) * std::log1p(-0.5 / x) + 0.5 + (stirling(x - 0.5) - stirling(x));
}

// The Student-t integrals (Ribardière et al. 2017 eq. 9-11) for ν = γ - 1 > 1/2
// and a >= 0, x = a²/ν:
//   head(a) = a 2F1(1/2, γ - 1/2; 3/2; -x) = ∫_0^a (1 + q²/ν)^(1/2-γ) dq
//   tail(a) = ∫_a^∞ (1 + q²/ν)^(1/2-γ) dq
// each from whichever of two positive-term series is shorter:
//   head = a (1 + x)^(1/2-γ) 2F1(1, γ - 1/2; 3/2; w),  w = x / (1 + x)   (DLMF 15.8.1, Pfaff),
//   tail = sqrt(ν)/2 B_y(ν, 1/2) = sqrt(ν)/(2ν) y^ν sqrt(1 - y) 2F1(ν + 1/2, 1; ν + 1; y),  y = 1/(1 + x)
// (the incomplete beta function by DLMF 8.17.8; head + tail = sqrt(ν) B(ν, 1/2)/2).
// The first series needs about (γ - 1/2) w / (1 - w) terms to pass its peak,
// the second about 37 / ln(1/y).
struct StudentTIntegrals {
    double head, tail;
};

inline double student_t_half_integral(double nu) {  // ∫_0^∞ (1 + q²/ν)^(1/2-γ) dq = sqrt(ν) B(ν, 1/2) / 2
    return 0.5 * kSqrtPi / (std::sqrt(nu) * std::exp(log_gamma_ratio_half(nu + 1.0)));
}

inline bool student_t_prefers_tail(double nu, double x) {
    const double w = x / (1.0 + x);
    const double head_terms = (nu + 0.5) * x + 37.0 / std::max(-std::log(std::max(w, 1e-300)), 1e-300);
    const double tail_terms = 37.0 / std::max(std::log1p(x), 1e-300);
    return tail_terms < head_terms;
}

// ln 2F1(1, γ - 1/2; 3/2; w)
inline double student_t_log_head_series(double nu, double x) {
    const double w = x / (1.0 + x);
    const double b = nu + 0.5;  // γ - 1/2
    return log_power_series(w, [&](int k) { return (b + k) / (1.5 + k); });
}

inline double student_t_tail_series(double nu, double x) {
    const double y = 1.0 / (1.0 + x);
    return power_series(y, [&](int k) { return (nu + 0.5 + k) / (nu + 1.0 + k); });
}

inline StudentTIntegrals student_t_integrals(double nu, double a) {
    const double half = student_t_half_integral(nu);
    if (a <= 0.0) return {0.0, half};
    if (std::isinf(a)) return {half, 0.0};
    const double x = a * a / nu;
    const double log1p_x = std::log1p(x);
    if (student_t_prefers_tail(nu, x)) {
        // y^ν sqrt(1 - y) = (1 + x)^(-ν) sqrt(x / (1 + x))
        const double tail = 0.5 / std::sqrt(nu) * std::exp(-nu * log1p_x) * std::sqrt(x / (1.0 + x)) *
                            student_t_tail_series(nu, x);
        return {half - tail, tail};
    }
    const double head = a * std::exp(student_t_log_head_series(nu, x) - (nu + 0.5) * log1p_x);
    return {head, half - head};
}

// 2F1(a, b; c; z) for the arguments the Student-t Λ needs, (a, c) = (1/2, 3/2),
// b > 1/2 and any z <= 0, through student_t_integrals with ν = b - 1/2 (the
// larger of head and tail directly, the smaller as their complement only
// where it is not the one asked for); the defining series for any other
// (a, b, c) with |z| <= 1/2, and Pfaff's z / (z - 1) (DLMF 15.8.1) for
// z in [-1, -1/2). NaN outside these.
inline double hypergeometric_2f1(double a, double b, double c, double z) {
    if (a == 0.5 && c == 1.5 && b > 0.5 && z <= 0.0) {
        if (z == 0.0) return 1.0;
        const double nu = b - 0.5;
        const double q = std::sqrt(-z * nu);  // a of the integrals, x = -z
        const double x = -z;
        if (!student_t_prefers_tail(nu, x)) return std::exp(student_t_log_head_series(nu, x) - b * std::log1p(x));
        return student_t_integrals(nu, q).head / q;
    }
    if (std::abs(z) <= 0.5) return hypergeometric_series(a, b, c, z);
    if (z >= -1.0 && z < -0.5) return std::pow(1.0 - z, -a) * hypergeometric_series(a, c - b, c, z / (z - 1.0));
    return std::numeric_limits<double>::quiet_NaN();
}

// ---------------------------------------------------------------------------
// The regularised incomplete gamma functions P(s, x) and Q(s, x) = 1 - P(s, x)
// (DLMF 8.2.4), each with full relative accuracy: the series DLMF 8.11.4 where
// x < s + 1, Legendre's continued fraction DLMF 8.9.2 (modified Lentz) else.
struct GammaPQ {
    double p, q;
};

inline GammaPQ regularized_gamma(double s, double x) {
    if (x <= 0.0) return {0.0, 1.0};
    if (std::isinf(x)) return {1.0, 0.0};
    const double log_prefactor = s * std::log(x) - x - std::lgamma(s);
    if (x < s + 1.0) {
        const double series = power_series(x, [&](int k) { return 1.0 / (s + 1.0 + k); });
        const double p = std::exp(log_prefactor) * series / s;
        return {p, 1.0 - p};
    }
    const double tiny = 1e-300;
    double b = x + 1.0 - s, c = 1.0 / tiny, d = 1.0 / b, h = d;
    for (int i = 1; i < 100000; ++i) {
        const double an = -i * (i - s);
        b += 2.0;
        d = an * d + b;
        if (std::abs(d) < tiny) d = tiny;
        c = b + an / c;
        if (std::abs(c) < tiny) c = tiny;
        d = 1.0 / d;
        const double delta = d * c;
        h *= delta;
        if (std::abs(delta - 1.0) <= kEpsilon) break;
    }
    const double q = std::exp(log_prefactor) * h;
    return {1.0 - q, q};
}

// x with P(s, x) = u, given u and 1 - u (whichever is smaller decides which of
// P and Q is matched, so that neither tail loses digits): Halley's iteration
// from the starting points of Numerical Recipes (3rd ed., §6.2.1, after
// DiDonato & Morris 1986), to a relative step of 1e-15. 0 at u = 0, +inf at u = 1.
inline double inverse_regularized_gamma(double s, double u, double u_complement) {
    if (u <= 0.0) return 0.0;
    if (u_complement <= 0.0) return std::numeric_limits<double>::infinity();
    const bool lower = u <= u_complement;
    const double lgs = std::lgamma(s);
    double x;
    if (s > 1.0) {
        const double pp = lower ? u : u_complement;
        const double t = std::sqrt(-2.0 * std::log(pp));
        double z = (2.30753 + t * 0.27061) / (1.0 + t * (0.99229 + t * 0.04481)) - t;
        if (lower) z = -z;
        x = std::max(1e-3, s * std::pow(1.0 - 1.0 / (9.0 * s) - z / (3.0 * std::sqrt(s)), 3.0));
    } else {
        const double t = 1.0 - s * (0.253 + s * 0.12);
        x = u < t ? std::pow(u / t, 1.0 / s) : 1.0 - std::log1p(-(u - t) / (1.0 - t));
        if (!lower && u_complement < 1e-300) x = 750.0;
    }
    for (int iteration = 0; iteration < 200; ++iteration) {
        if (x <= 0.0) return 0.0;
        const GammaPQ pq = regularized_gamma(s, x);
        const double error = lower ? pq.p - u : u_complement - pq.q;
        const double density = std::exp((s - 1.0) * std::log(x) - x - lgs);
        if (density == 0.0) break;
        const double newton = error / density;
        const double step = newton / (1.0 - 0.5 * std::min(1.0, newton * ((s - 1.0) / x - 1.0)));
        double next = x - step;
        if (next <= 0.0) next = 0.5 * x;
        const bool converged = std::abs(next - x) <= 1e-15 * x;
        x = next;
        if (converged) break;
    }
    return x;
}

// ---------------------------------------------------------------------------
// The N-point Gauss-Legendre rule on [0, 1] (nodes by Newton's iteration on
// the Legendre polynomial, to machine precision).
template <int N>
struct GaussLegendre {
    std::array<double, N> node, weight;

    GaussLegendre() {
        for (int i = 0; i < (N + 1) / 2; ++i) {
            double z = std::cos(3.14159265358979323846 * (i + 0.75) / (N + 0.5)), derivative = 1.0;
            for (int iteration = 0; iteration < 100; ++iteration) {
                double p0 = 1.0, p1 = 0.0;
                for (int j = 0; j < N; ++j) {
                    const double p2 = p1;
                    p1 = p0;
                    p0 = ((2.0 * j + 1.0) * z * p1 - j * p2) / (j + 1.0);
                }
                derivative = N * (z * p0 - p1) / (z * z - 1.0);
                const double previous = z;
                z = previous - p0 / derivative;
                if (std::abs(z - previous) <= 1e-16) break;
            }
            const double w = 1.0 / ((1.0 - z * z) * derivative * derivative);  // half of 2/((1-z²)P'²): on [0, 1]
            node[i] = 0.5 * (1.0 - z);
            node[N - 1 - i] = 0.5 * (1.0 + z);
            weight[i] = weight[N - 1 - i] = w;
        }
    }

    static const GaussLegendre& rule() {
        static const GaussLegendre instance;
        return instance;
    }
};

}  // namespace principled_brdf::special
