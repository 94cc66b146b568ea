// The float64 toolkit of the microfacet family (docs/microfacet.md,
// docs/model.md "The microfacet family"): Student-t, exponential power,
// Blinn-Phong and Beckmann with Walter's rational Λ, each the model's type
// (model/distribution_family.hpp) instantiated for double, with the
// toolkit's clamps and two-sided conventions (microfacet.hpp), and GGX's
// combined G2 / (4 cos θi cos θo) with its two approximations.
//
// Every distribution offers the same set, written once below over its type:
// D, the pdf of its draw (D cos θh), Λ, G1 = 1/(1 + Λ), the separable G2 =
// G1(wi) G1(wo), the height-correlated G2 = 1/(1 + Λ(wi) + Λ(wo)) (Heitz
// 2014 eq. 99), the draw of D cos θh and the density of visible normals
// G1(wo) max(0, wo·h) D(h) / |wo·n| (Heitz 2014 eq. 38).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "microfacet.hpp"
#include "model/f64_family.hpp"

namespace principled_brdf::microfacet {

inline constexpr double kMinStudentGamma = 1.5;  // exclusive: Λ diverges at γ = 3/2

// Beckmann with Walter et al. 2007 eq. 27's rational Λ in place of the exact one.
struct BeckmannWalter {
    Beckmann<double> beckmann;
    f64::Stretch<double> stretch;
    double d(const f64::HalfVector<double>& h) const { return beckmann.d(h); }
    double lambda(const ModelVec3& w) const {
        return w.x == 0.0 && w.y == 0.0 ? 0.0 : f64::beckmann_lambda_walter(stretch.cot_projected(w));
    }
    ModelVec3 sample_distribution(double sin_phi, double cos_phi, double u2) const {
        return beckmann.sample_distribution(sin_phi, cos_phi, u2);
    }
};

// Each distribution from (alpha_x, alpha_y, shape), clamped as the toolkit clamps.
template <class Distribution>
Distribution make_distribution(double alpha_x, double alpha_y, double shape);

template <>
inline f64::StudentT<double> make_distribution(double ax, double ay, double gamma) {
    return f64::StudentT<double>::from(clamp_alpha(ax), clamp_alpha(ay), std::max(gamma, kMinStudentGamma + 1e-9));
}
template <>
inline f64::ExponentialPower<double> make_distribution(double ax, double ay, double p) {
    return f64::ExponentialPower<double>::from(clamp_alpha(ax), clamp_alpha(ay), std::clamp(p, 0.05, 20.0));
}
template <>
inline f64::BlinnPhong<double> make_distribution(double ax, double ay, double) {
    return f64::BlinnPhong<double>::from_alphas(clamp_gtr_alpha(ax), clamp_gtr_alpha(ay));
}
template <>
inline BeckmannWalter make_distribution(double ax, double ay, double) {
    ax = clamp_alpha(ax);
    ay = clamp_alpha(ay);
    return {Beckmann<double>::from_alphas(ax, ay), f64::Stretch<double>::from_alphas(ax, ay)};
}

template <class Distribution>
double family_d(const Vec3& h, double ax, double ay, double shape) {
    if (h.z <= 0.0) return 0.0;
    return make_distribution<Distribution>(ax, ay, shape).d(half_of(h));
}

template <class Distribution>
double family_pdf(const Vec3& h, double ax, double ay, double shape) {
    return h.z <= 0.0 ? 0.0 : family_d<Distribution>(h, ax, ay, shape) * h.z;
}

// Λ(w) reads |w·n| (two-sided): 0 at the normal, +inf at grazing
template <class Distribution>
double family_lambda(const Vec3& w, double ax, double ay, double shape) {
    return make_distribution<Distribution>(ax, ay, shape).lambda(upper(w));
}

template <class Distribution>
double family_g1(const Vec3& w, double ax, double ay, double shape) {
    return 1.0 / (1.0 + family_lambda<Distribution>(w, ax, ay, shape));
}

template <class Distribution>
double family_g2_separable(const Vec3& wi, const Vec3& wo, double ax, double ay, double shape) {
    return family_g1<Distribution>(wi, ax, ay, shape) * family_g1<Distribution>(wo, ax, ay, shape);
}

template <class Distribution>
double family_g2_height_correlated(const Vec3& wi, const Vec3& wo, double ax, double ay, double shape) {
    const Distribution distribution = make_distribution<Distribution>(ax, ay, shape);
    return 1.0 / (1.0 + distribution.lambda(upper(wi)) + distribution.lambda(upper(wo)));
}

template <class Distribution>
Vec3 family_sample(double u1, double u2, double ax, double ay, double shape) {
    const auto [sin_phi, cos_phi] = f64::sincos_turns(u1);
    return normalized_draw(make_distribution<Distribution>(ax, ay, shape).sample_distribution(sin_phi, cos_phi, u2));
}

// G1(wo) max(0, wo·h) D(h) / |wo·n| = max(0, wo·h) D(h) / (|wo·n| (1 + Λ(wo))), wo
// mirrored above the horizon; 0 for a grazing wo (where |wo·n| Λ is ∞ · 0 in double)
template <class Distribution>
double family_pdf_visible(const Vec3& h, const Vec3& wo, double ax, double ay, double shape) {
    const Vec3 view = mirrored_above(wo);
    const double cos_view_h = dot(view, h);
    if (cos_view_h <= 0.0 || h.z <= 0.0 || view.z <= 0.0) return 0.0;
    const Distribution distribution = make_distribution<Distribution>(ax, ay, shape);
    const double lambda = distribution.lambda(model_vec(view));
    return cos_view_h * distribution.d(half_of(h)) / (view.z * (1.0 + lambda));
}

// ---------------------------------------------------------------------------
// GGX: G2 / (4 |n·wi| |n·wo|), the combined height-correlated term ("V").
enum class GgxVisibility { exact = 0, karis = 1, hammon = 2 };

// the projected roughness α_o of w (Heitz 2014 eq. 80): sqrt((ax² wx² + ay² wy²) / (wx² + wy²)), ax at the normal
inline double projected_alpha(const Vec3& w, double ax, double ay) {
    const double sin2 = w.x * w.x + w.y * w.y;
    return sin2 > 0.0 ? std::sqrt((ax * ax * w.x * w.x + ay * ay * w.y * w.y) / sin2) : ax;
}

// exact: 2 μi μo / (μi |Vo| + μo |Vi|) / (4 μi μo) = 0.5 / (μo |Vi| + μi |Vo|), |V| the stretched
// length sqrt(α_o² (1 - μ²) + μ²) (Heitz 2014 eq. 99 with eq. 72; Lagarde & de Rousiers 2014's form).
// karis: the separable Schlick-GGX of Karis 2013 (UE4 course notes), G1 ≈ μ / (μ (1 - k) + k),
// k = α_o / 2, so V ≈ 1 / (4 (μi (1 - ki) + ki) (μo (1 - ko) + ko)).
// hammon: Hammon 2017 (GDC), |V| ≈ lerp(μ, 1, α_o) in the exact form:
// V ≈ 0.5 / (μo lerp(μi, 1, αi) + μi lerp(μo, 1, αo)) = 0.5 / lerp(2 μi μo, μi + μo, α) isotropically.
inline double ggx_g2_over_4cos(const Vec3& wi, const Vec3& wo, double ax, double ay, GgxVisibility form) {
    ax = clamp_alpha(ax);
    ay = clamp_alpha(ay);
    const double mu_i = std::abs(wi.z), mu_o = std::abs(wo.z);
    switch (form) {
        case GgxVisibility::karis: {
            const double ki = 0.5 * projected_alpha(wi, ax, ay), ko = 0.5 * projected_alpha(wo, ax, ay);
            return 0.25 / ((mu_i * (1.0 - ki) + ki) * (mu_o * (1.0 - ko) + ko));
        }
        case GgxVisibility::hammon: {
            const double a_i = projected_alpha(wi, ax, ay), a_o = projected_alpha(wo, ax, ay);
            return 0.5 / (mu_o * (mu_i * (1.0 - a_i) + a_i) + mu_i * (mu_o * (1.0 - a_o) + a_o));
        }
        case GgxVisibility::exact:
        default: {
            const Ggx<double> ggx = ggx_of(ax, ay);
            const double length_i = std::sqrt(ggx.stretched_length2(upper(wi)));
            const double length_o = std::sqrt(ggx.stretched_length2(upper(wo)));
            return 0.5 / (mu_o * length_i + mu_i * length_o);
        }
    }
}

// Beckmann's height-correlated G2 with the exact Λ (the separable one is G1 G1, microfacet.hpp's Λ)
inline double beckmann_g2_separable(const Vec3& wi, const Vec3& wo, double ax, double ay) {
    return beckmann_g1(wi, ax, ay) * beckmann_g1(wo, ax, ay);
}
inline double beckmann_g2_height_correlated(const Vec3& wi, const Vec3& wo, double ax, double ay) {
    return 1.0 / (1.0 + beckmann_lambda(wi, ax, ay) + beckmann_lambda(wo, ax, ay));
}
inline double beckmann_pdf_visible_h(const Vec3& h, const Vec3& wo, double ax, double ay) {
    const Vec3 view = mirrored_above(wo);
    const double cos_view_h = dot(view, h);
    if (cos_view_h <= 0.0 || h.z <= 0.0 || view.z <= 0.0) return 0.0;
    return cos_view_h * beckmann_d(h, ax, ay) / (view.z * (1.0 + beckmann_lambda(view, ax, ay)));
}

// ---------------------------------------------------------------------------
// Beckmann's visible normals (Heitz & d'Eon 2014, Jakob 2014): wo stretched to
// unit roughness, a visible slope drawn there, rotated, unstretched.

// erf⁻¹(y), |y| < 1: Giles 2010's single-precision approximation, then Newton steps on erf
inline double inverse_erf(double y) {
    if (!(y > -1.0)) return -std::numeric_limits<double>::infinity();
    if (!(y < 1.0)) return std::numeric_limits<double>::infinity();
    double w = -std::log((1.0 - y) * (1.0 + y)), p;
    if (w < 5.0) {
        w -= 2.5;
        p = 2.81022636e-08;
        for (double c : {3.43273939e-07, -3.5233877e-06, -4.39150654e-06, 0.00021858087, -0.00125372503,
                         -0.00417768164, 0.246640727, 1.50140941})
            p = c + p * w;
    } else {
        w = std::sqrt(w) - 3.0;
        p = -0.000200214257;
        for (double c : {0.000100950558, 0.00134934322, -0.00367342844, 0.00573950773, -0.0076224613, 0.00943887047,
                         1.00167406, 2.83297682})
            p = c + p * w;
    }
    double x = p * y;
    for (int i = 0; i < 3; ++i) {
        const double density = 1.1283791670955126 * std::exp(-x * x);
        if (!(density > 0.0)) break;  // |x| > 27: erf is ±1 in double, the approximation stands
        x -= (std::erf(x) - y) / density;
    }
    return x;
}

// A slope (x, y) of the unit-roughness Beckmann surface visible from elevation θ (cos θ > 0),
// seen along +x: x from the CDF of visible slopes in erf's domain b = erf(x),
//   C(b) = (1 + b + tan θ exp(-x²) / √π) / (1 + erf(cot θ) + tan θ exp(-cot²θ) / √π),
// inverted by Newton's iteration kept inside a bisection bracket (Heitz & d'Eon 2014's
// starting point), y Gaussian: erf⁻¹(2 u2 - 1).
inline std::pair<double, double> beckmann_visible_slope(double cos_theta, double u1, double u2) {
    const double u_y = std::clamp(2.0 * u2 - 1.0, -1.0 + 1e-16, 1.0 - 1e-16);
    if (cos_theta > 0.99999999) {
        const double r = std::sqrt(-std::log1p(-std::min(u1, 1.0 - 1e-16)));
        const double phi = 2.0 * kPi * u2;
        return {r * std::cos(phi), r * std::sin(phi)};
    }
    const double sin_theta = std::sqrt(std::max(0.0, (1.0 - cos_theta) * (1.0 + cos_theta)));
    const double tan_theta = sin_theta / cos_theta, cot_theta = cos_theta / sin_theta;
    constexpr double kInvSqrtPi = 0.5641895835477563;
    double lo = -1.0, hi = std::erf(cot_theta);
    const double u = std::clamp(u1, 1e-16, 1.0 - 1e-16);
    const double theta = std::acos(cos_theta);
    const double fit = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
    double b = hi - (1.0 + hi) * std::pow(1.0 - u, fit);
    const double norm = 1.0 / (1.0 + hi + kInvSqrtPi * tan_theta * std::exp(-cot_theta * cot_theta));
    for (int iteration = 0; iteration < 100; ++iteration) {
        if (!(b > lo && b < hi)) b = 0.5 * (lo + hi);
        const double x = inverse_erf(b);
        if (!std::isfinite(x)) break;
        const double value = norm * (1.0 + b + kInvSqrtPi * tan_theta * std::exp(-x * x)) - u;
        if (std::abs(value) < 1e-15) break;
        if (value > 0.0) hi = b; else lo = b;
        if (hi - lo < 1e-16) break;
        b -= value / (norm * (1.0 - x * tan_theta));
    }
    return {inverse_erf(std::clamp(b, -1.0 + 1e-16, 1.0 - 1e-16)), inverse_erf(u_y)};
}

// visible normals of wo (mirrored above the horizon), density beckmann_pdf_visible_h
inline Vec3 beckmann_sample_visible_h(const Vec3& wo, double u1, double u2, double ax, double ay) {
    ax = clamp_alpha(ax);
    ay = clamp_alpha(ay);
    const Vec3 view = mirrored_above(wo);
    const Vec3 stretched = normalize({ax * view.x, ay * view.y, std::max(view.z, 1e-300)});
    const double sin_phi_length = std::hypot(stretched.x, stretched.y);
    const double cos_phi = sin_phi_length > 0.0 ? stretched.x / sin_phi_length : 1.0;
    const double sin_phi = sin_phi_length > 0.0 ? stretched.y / sin_phi_length : 0.0;
    auto [x, y] = beckmann_visible_slope(stretched.z, u1, u2);
    const double rotated_x = cos_phi * x - sin_phi * y, rotated_y = sin_phi * x + cos_phi * y;
    return normalize({-ax * rotated_x, -ay * rotated_y, 1.0});
}

}  // namespace principled_brdf::microfacet
