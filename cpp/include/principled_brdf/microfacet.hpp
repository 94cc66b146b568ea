// Microfacet toolkit in float64 (README "Microfacet toolkit"): the GTR family of
// Burley 2012 (appendix B), anisotropic GGX with Smith masking, and anisotropic
// Beckmann (Walter et al. 2007; its Smith Λ as in Heitz 2014). One small function per formula; each
// names the equation it implements.
//
// Conventions: local shading frame, n = (0,0,1), tangent x, bitangent y; every
// direction argument is a unit vector. A distribution D is zero for half
// vectors at or below the horizon, and is normalised so that
// ∫ D(h) cosθh dω_h = 1 over the hemisphere; "pdf_h" is that density of h in
// solid angle.
//
// Numerics. Angles are carried as the pair (cos²θ, sin²θ) wherever possible,
// so that sharp peaks (alpha down to kMinAlpha) keep full relative accuracy
// near θ = 0. The GTR normaliser (γ-1)(α²-1) / (π (1 - (α²)^(1-γ))) is 0/0 at
// γ = 1 and at α = 1; it is written with expm1 so that it is accurate right up
// to, and at, those points. Roughness is clamped to [kMinAlpha, kMaxAlpha]
// (GTR: [kMinAlpha, 1]) and γ to at most kMaxGamma; inside those ranges
// nothing returns NaN or overflows, except Λ ~ α sinθ / (2 |cosθ|), which is
// +inf at exactly grazing angles (its true value) and for |cosθ| below ~1e-298
// (where its true value is beyond the double range).
#pragma once

#include <algorithm>
#include <cmath>

#include "model/f64.hpp"

namespace principled_brdf::microfacet {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kSqrtPi = 1.77245385090551602730;
inline constexpr double kMinAlpha = 1e-10;
inline constexpr double kMaxAlpha = 1e10;
inline constexpr double kMaxGamma = 1e6;

struct Vec3 {
    double x, y, z;
};

inline double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline Vec3 scale(const Vec3& a, double s) { return {a.x * s, a.y * s, a.z * s}; }
inline Vec3 add(const Vec3& a, const Vec3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 normalize(const Vec3& a) { return scale(a, 1.0 / std::sqrt(dot(a, a))); }

// cos²θ and sin²θ of one direction, kept apart so neither is 1 minus the other.
struct Cos2Sin2 {
    double cos2;
    double sin2;
};

inline Cos2Sin2 cos2_sin2_from_cos(double cos_theta) {
    return {cos_theta * cos_theta, (1.0 - cos_theta) * (1.0 + cos_theta)};
}
inline Cos2Sin2 cos2_sin2_of(const Vec3& w) { return {w.z * w.z, w.x * w.x + w.y * w.y}; }

// h = (sinθ cosφ, sinθ sinφ, cosθ) with φ = 2π u1 (appendix B, eq. 2).
inline Vec3 spherical_direction(const Cos2Sin2& angle, double u1) {
    const double phi = 2.0 * kPi * u1;
    const double norm = std::sqrt(angle.cos2 + angle.sin2);
    const double sin_theta = std::sqrt(angle.sin2) / norm;
    return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), std::sqrt(angle.cos2) / norm};
}

inline double clamp_alpha(double alpha) { return std::clamp(alpha, kMinAlpha, kMaxAlpha); }
inline double clamp_gtr_alpha(double alpha) { return std::clamp(alpha, kMinAlpha, 1.0); }
inline double clamp_gamma(double gamma) { return std::min(gamma, kMaxGamma); }

// (e^x - 1) / x, with its limit 1 at x = 0.
inline double expm1_over_x(double x) { return x == 0.0 ? 1.0 : std::expm1(x) / x; }

// log((1 - w) + w e^z) = log(1 + w expm1(z)) for a weight w in [0, 1] given with its
// complement 1 - w: log1p where w expm1(z) is small, else the log of a sum of two
// positive terms (pulling e^z out when z > 0), so that it neither cancels nor overflows.
inline double log_mix_exp(double weight, double weight_complement, double z) {
    const double y = weight * std::expm1(z);
    if (z < 700.0 && std::abs(y) <= 0.5) return std::log1p(y);
    if (z > 0.0) return z + std::log(weight + weight_complement * std::exp(-z));
    return std::log(weight_complement + weight * std::exp(z));
}

// ---------------------------------------------------------------------------
// GTR, isotropic (appendix B.2). With a2 = α² and c = cosθh, every D below has
// the shape  norm / t^γ,  t = 1 + (a2 - 1) c², written as t = a2 cos²θh + sin²θh.

inline double gtr_t(const Cos2Sin2& h, double a2) { return a2 * h.cos2 + h.sin2; }

// Eq. (1), any γ > 0: D = (γ-1)(a2-1) / (π (1 - a2^(1-γ))) / t^γ.
// With L = ln a2 and x = (1-γ) L the normaliser is
//   (expm1(L)/L) / (π expm1(x)/x),
// which tends smoothly to eq. (4) as γ -> 1 and to 1/π as α -> 1. For γ > 1
// the factor e^(-x) = a2^(γ-1) is moved onto t^-γ, giving (a2/t)^γ / a2 with
// a2/t in (0, 1], so nothing overflows for small α and large γ.
inline double gtr_d_general(const Cos2Sin2& h, double alpha, double gamma) {
    if (h.cos2 <= 0.0) return 0.0;
    alpha = clamp_gtr_alpha(alpha);
    gamma = clamp_gamma(gamma);
    const double a2 = alpha * alpha;
    const double log_a2 = 2.0 * std::log(alpha);
    const double x = (1.0 - gamma) * log_a2;
    const double t = gtr_t(h, a2);
    if (x > 0.0) {
        const double norm_times_a2 = expm1_over_x(log_a2) / (kPi * expm1_over_x(-x));
        return norm_times_a2 / a2 * std::pow(a2 / t, gamma);
    }
    const double norm = expm1_over_x(log_a2) / (kPi * expm1_over_x(x));
    return norm * std::pow(t, -gamma);
}

// Eq. (4), γ = 1 (Berry; the clearcoat lobe): D = (a2-1) / (π ln a2) / t.
inline double gtr1_d(const Cos2Sin2& h, double alpha) {
    if (h.cos2 <= 0.0) return 0.0;
    alpha = clamp_gtr_alpha(alpha);
    const double a2 = alpha * alpha;
    return expm1_over_x(2.0 * std::log(alpha)) / (kPi * gtr_t(h, a2));
}

// Eq. (6), γ = 3/2: D = (a2 + α) / (2π) / t^(3/2).
inline double gtr3_2_d(const Cos2Sin2& h, double alpha) {
    if (h.cos2 <= 0.0) return 0.0;
    alpha = clamp_gtr_alpha(alpha);
    const double a2 = alpha * alpha;
    const double t = gtr_t(h, a2);
    return (a2 + alpha) / (2.0 * kPi * t * std::sqrt(t));
}

// Eq. (8), γ = 2 (isotropic GGX / Trowbridge-Reitz): D = a2 / (π t²).
inline double gtr2_d(const Cos2Sin2& h, double alpha) {
    if (h.cos2 <= 0.0) return 0.0;
    alpha = clamp_gtr_alpha(alpha);
    const double a2 = alpha * alpha;
    const double t = gtr_t(h, a2);
    return a2 / (kPi * t * t);
}

// D_GTR for any γ > 0, using the closed forms at γ = 1, 3/2 and 2 when asked.
// The sign of cosθh comes separately since (cos²θh, sin²θh) has lost it.
inline double gtr_d(double cos_theta_h, const Cos2Sin2& h, double alpha, double gamma, bool closed_forms = true) {
    if (cos_theta_h <= 0.0) return 0.0;
    if (closed_forms) {
        if (gamma == 1.0) return gtr1_d(h, alpha);
        if (gamma == 1.5) return gtr3_2_d(h, alpha);
        if (gamma == 2.0) return gtr2_d(h, alpha);
    }
    return gtr_d_general(h, alpha, gamma);
}

inline double gtr_d(double cos_theta_h, double alpha, double gamma, bool closed_forms = true) {
    return gtr_d(cos_theta_h, cos2_sin2_from_cos(cos_theta_h), alpha, gamma, closed_forms);
}

// Density of h in solid angle: D(h) cosθh.
inline double gtr_pdf_h(const Vec3& h, double alpha, double gamma, bool closed_forms = true) {
    if (h.z <= 0.0) return 0.0;
    return gtr_d(h.z, cos2_sin2_of(h), alpha, gamma, closed_forms) * h.z;
}

// Eq. (3), any γ > 0, as the pair (cos²θh, sin²θh). With L = ln a2 and k = 1-γ,
//   M = ln((1-u) a2^k + u) / k                  so that cos²θh = expm1(M) / expm1(L),
//   q = M - L = ln(u a2^-k + (1-u)) / k         and sin²θh = e^M expm1(-q) / expm1(L)
// needs no 1 - cos²θh. Both logarithms are log_mix_exp, and both tend to eq. (5)
// as k -> 0 (M -> (1-u) L, q -> -u L).
inline Cos2Sin2 gtr_sample_cos2_general(double u2, double alpha, double gamma) {
    if (u2 >= 1.0) return {0.0, 1.0};
    alpha = clamp_gtr_alpha(alpha);
    gamma = clamp_gamma(gamma);
    const double log_a2 = 2.0 * std::log(alpha);
    if (log_a2 == 0.0) return {1.0 - u2, u2};  // α = 1: cos²θh uniform
    const double k = 1.0 - gamma;
    const double m = k == 0.0 ? (1.0 - u2) * log_a2 : log_mix_exp(1.0 - u2, u2, k * log_a2) / k;
    const double q = k == 0.0 ? -u2 * log_a2 : log_mix_exp(u2, 1.0 - u2, -k * log_a2) / k;
    const double expm1_l = std::expm1(log_a2);
    const double cos2 = std::expm1(m) / expm1_l;
    const double sin2 = std::exp(m) * std::expm1(-q) / expm1_l;
    return {std::clamp(cos2, 0.0, 1.0), std::clamp(sin2, 0.0, 1.0)};
}

// Eq. (5), γ = 1: cos²θh = (1 - a2^(1-u)) / (1 - a2), sin²θh = (a2^(1-u) - a2) / (1 - a2).
inline Cos2Sin2 gtr1_sample_cos2(double u2, double alpha) {
    alpha = clamp_gtr_alpha(alpha);
    const double log_a2 = 2.0 * std::log(alpha);
    if (log_a2 == 0.0) return {1.0 - u2, u2};
    const double expm1_l = std::expm1(log_a2);
    const double m = (1.0 - u2) * log_a2;
    return {std::expm1(m) / expm1_l, std::exp(m) * std::expm1(u2 * log_a2) / expm1_l};
}

// Eq. (7), γ = 3/2, with b = 1 + (α-1) u = (1-u) + α u (no cancellation as u -> 1):
//   cos²θh = (1-u)(b+α) / (b² (1+α)),  sin²θh = a2 u (1+b) / (b² (1+α)),
// eq. (7) with the factor (1-α) cancelled, so α -> 1 is regular.
inline Cos2Sin2 gtr3_2_sample_cos2(double u2, double alpha) {
    alpha = clamp_gtr_alpha(alpha);
    const double b = (1.0 - u2) + alpha * u2;
    const double denom = b * b * (1.0 + alpha);
    return {(1.0 - u2) * (b + alpha) / denom, alpha * alpha * u2 * (1.0 + b) / denom};
}

// Eq. (9), γ = 2: cos²θh = (1-u) / (1 + (a2-1) u), sin²θh = a2 u / (1 + (a2-1) u).
inline Cos2Sin2 gtr2_sample_cos2(double u2, double alpha) {
    alpha = clamp_gtr_alpha(alpha);
    const double a2 = alpha * alpha;
    const double denom = (1.0 - u2) + a2 * u2;
    return {(1.0 - u2) / denom, a2 * u2 / denom};
}

inline Cos2Sin2 gtr_sample_cos2(double u2, double alpha, double gamma, bool closed_forms = true) {
    if (closed_forms) {
        if (gamma == 1.0) return gtr1_sample_cos2(u2, alpha);
        if (gamma == 1.5) return gtr3_2_sample_cos2(u2, alpha);
        if (gamma == 2.0) return gtr2_sample_cos2(u2, alpha);
    }
    return gtr_sample_cos2_general(u2, alpha, gamma);
}

// Eq. (2)-(3): a half vector with density gtr_pdf_h.
inline Vec3 gtr_sample_h(double u1, double u2, double alpha, double gamma, bool closed_forms = true) {
    return spherical_direction(gtr_sample_cos2(u2, alpha, gamma, closed_forms), u1);
}

// ---------------------------------------------------------------------------
// Anisotropic GGX (GTR2 aniso) and its Smith masking.

// Eq. (13): D = 1 / (π αx αy ((h·x/αx)² + (h·y/αy)² + (h·n)²)²), the model's
// distribution (model/distributions.hpp) with the toolkit's clamps.
inline double ggx_d(const Vec3& h, double alpha_x, double alpha_y) {
    if (h.z <= 0.0) return 0.0;
    const f64::HalfVector<double> half{h.x * h.x, h.y * h.y, h.z, h.z * h.z, dot(h, h)};
    return f64::Ggx<double>::from_alphas(clamp_alpha(alpha_x), clamp_alpha(alpha_y)).d(half);
}

inline double ggx_pdf_h(const Vec3& h, double alpha_x, double alpha_y) {
    return h.z <= 0.0 ? 0.0 : ggx_d(h, alpha_x, alpha_y) * h.z;
}

// Eq. (14)-(15): h' = sqrt(u2/(1-u2)) (αx cos 2πu1 x + αy sin 2πu1 y) + n,
// h = h'/|h'|; scaled by sqrt(1-u2) first so that u2 = 1 is the horizon.
inline Vec3 ggx_sample_h(double u1, double u2, double alpha_x, double alpha_y) {
    alpha_x = clamp_alpha(alpha_x);
    alpha_y = clamp_alpha(alpha_y);
    const double phi = 2.0 * kPi * u1;
    const double radius = std::sqrt(u2);
    return normalize({radius * alpha_x * std::cos(phi), radius * alpha_y * std::sin(phi), std::sqrt(1.0 - u2)});
}

// αx² wx² + αy² wy² = (α(φ) sinθ)², the projected roughness times sinθ, squared.
inline double projected_roughness2_sin2(const Vec3& w, double alpha_x, double alpha_y) {
    alpha_x = clamp_alpha(alpha_x);
    alpha_y = clamp_alpha(alpha_y);
    const double px = alpha_x * w.x;
    const double py = alpha_y * w.y;
    return px * px + py * py;
}

// Λ(w) = (-1 + sqrt(1 + (αx² wx² + αy² wy²) / wz²)) / 2, written
//   p² / (2 |wz| (sqrt(wz² + p²) + |wz|)),  p² = αx² wx² + αy² wy²,
// which neither cancels nor overflows as wz -> 0 (it is +inf at wz = 0).
inline double ggx_lambda(const Vec3& w, double alpha_x, double alpha_y) {
    const double p2 = projected_roughness2_sin2(w, alpha_x, alpha_y);
    const double cos_abs = std::abs(w.z);
    return p2 / (2.0 * cos_abs * (std::sqrt(cos_abs * cos_abs + p2) + cos_abs));
}

// G1 = 1 / (1 + Λ) = 2 |wz| / (|wz| + sqrt(wz² + p²)); 0 at grazing.
inline double ggx_g1(const Vec3& w, double alpha_x, double alpha_y) {
    const double p2 = projected_roughness2_sin2(w, alpha_x, alpha_y);
    const double cos_abs = std::abs(w.z);
    return 2.0 * cos_abs / (cos_abs + std::sqrt(cos_abs * cos_abs + p2));
}

// G1(w) / |wz| = 2 / (|wz| + sqrt(wz² + p²)): finite at grazing (it is 2 S(w) of README "The model").
inline double ggx_g1_over_cos(const Vec3& w, double alpha_x, double alpha_y) {
    const double p2 = projected_roughness2_sin2(w, alpha_x, alpha_y);
    const double cos_abs = std::abs(w.z);
    return 2.0 / (cos_abs + std::sqrt(cos_abs * cos_abs + p2));
}

// Separable Smith G2 = G1(wi) G1(wo) (what the model uses).
inline double ggx_g2_separable(const Vec3& wi, const Vec3& wo, double alpha_x, double alpha_y) {
    return ggx_g1(wi, alpha_x, alpha_y) * ggx_g1(wo, alpha_x, alpha_y);
}

// Height-correlated Smith G2 = 1 / (1 + Λ(wi) + Λ(wo)), with Λ = (r - |z|) / (2|z|),
// r = sqrt(z² + p²):  G2 = 2 |zi| |zo| / (|zi| ro + |zo| ri)  (cf. Heitz 2014, the height-correlated form).
inline double ggx_g2_height_correlated(const Vec3& wi, const Vec3& wo, double alpha_x, double alpha_y) {
    const double zi = std::abs(wi.z);
    const double zo = std::abs(wo.z);
    const double ri = std::sqrt(zi * zi + projected_roughness2_sin2(wi, alpha_x, alpha_y));
    const double ro = std::sqrt(zo * zo + projected_roughness2_sin2(wo, alpha_x, alpha_y));
    const double denom = zi * ro + zo * ri;
    return denom > 0.0 ? 2.0 * zi * zo / denom : 0.0;
}

// Visible normals (Heitz 2018, "Sampling the GGX Distribution of Visible
// Normals"): stretch wo to the isotropic α = 1 configuration, sample the
// projected hemisphere as a disk warped towards the visible half, lift the
// point onto the hemisphere and unstretch. φ = 2π u1 and disk radius sqrt(u2).
// A wo below the horizon is mirrored (wo -> -wo), so the sampler is two-sided.
inline Vec3 ggx_sample_visible_h(const Vec3& wo, double u1, double u2, double alpha_x, double alpha_y) {
    alpha_x = clamp_alpha(alpha_x);
    alpha_y = clamp_alpha(alpha_y);
    const Vec3 view = wo.z < 0.0 ? scale(wo, -1.0) : wo;
    const Vec3 view_std = normalize({alpha_x * view.x, alpha_y * view.y, view.z});
    // An orthonormal basis (t1, t2, view_std).
    const double len2 = view_std.x * view_std.x + view_std.y * view_std.y;
    const Vec3 t1 = len2 > 0.0 ? scale(Vec3{-view_std.y, view_std.x, 0.0}, 1.0 / std::sqrt(len2)) : Vec3{1.0, 0.0, 0.0};
    const Vec3 t2 = cross(view_std, t1);
    // A uniform point on the unit disk, its second coordinate squeezed into the visible part.
    const double radius = std::sqrt(u2);
    const double phi = 2.0 * kPi * u1;
    const double d1 = radius * std::cos(phi);
    const double d2_disk = radius * std::sin(phi);
    const double s = 0.5 * (1.0 + view_std.z);
    const double d2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - d1 * d1)) + s * d2_disk;
    const double lift = std::sqrt(std::max(0.0, 1.0 - d1 * d1 - d2 * d2));
    const Vec3 h_std = add(add(scale(t1, d1), scale(t2, d2)), scale(view_std, lift));
    return normalize({alpha_x * h_std.x, alpha_y * h_std.y, std::max(0.0, h_std.z)});
}

// Density of visible normals, D_wo(h) = G1(wo) max(0, wo·h) D(h) / |wo_z|
// (Heitz 2014/2018), with G1/|wo_z| taken in its grazing-safe form; wo mirrored as above.
inline double ggx_pdf_visible_h(const Vec3& h, const Vec3& wo, double alpha_x, double alpha_y) {
    const Vec3 view = wo.z < 0.0 ? scale(wo, -1.0) : wo;
    const double cos_view_h = dot(view, h);
    if (cos_view_h <= 0.0 || h.z <= 0.0) return 0.0;
    return ggx_g1_over_cos(view, alpha_x, alpha_y) * cos_view_h * ggx_d(h, alpha_x, alpha_y);
}

// ---------------------------------------------------------------------------
// Anisotropic Beckmann (Walter et al. 2007, Heitz 2014 §5.2): slope density P22 = exp(-(x²/αx² + y²/αy²)) / (π αx αy).

// D = exp(-((h·x/αx)² + (h·y/αy)²) / (h·n)²) / (π αx αy (h·n)⁴): the model's
// distribution (model/distributions.hpp) with the toolkit's clamps.
inline double beckmann_d(const Vec3& h, double alpha_x, double alpha_y) {
    if (h.z <= 0.0) return 0.0;
    const f64::HalfVector<double> half{h.x * h.x, h.y * h.y, h.z, h.z * h.z, dot(h, h)};
    return f64::Beckmann<double>::from_alphas(clamp_alpha(alpha_x), clamp_alpha(alpha_y)).d(half);
}

inline double beckmann_pdf_h(const Vec3& h, double alpha_x, double alpha_y) {
    return h.z <= 0.0 ? 0.0 : beckmann_d(h, alpha_x, alpha_y) * h.z;
}

// Stretched slope radius ρ = sqrt(-ln(1 - u2)), φ = 2π u1, h ∝ (ρ αx cos φ, ρ αy sin φ, 1):
// the same projected-half-vector construction as eq. (14)-(15), for P22 above.
inline Vec3 beckmann_sample_h(double u1, double u2, double alpha_x, double alpha_y) {
    alpha_x = clamp_alpha(alpha_x);
    alpha_y = clamp_alpha(alpha_y);
    const double phi = 2.0 * kPi * u1;
    const Vec3 tangent{alpha_x * std::cos(phi), alpha_y * std::sin(phi), 0.0};
    if (u2 >= 1.0) return normalize(tangent);
    const double radius = std::sqrt(-std::log1p(-u2));
    if (radius <= 1.0) return normalize({radius * tangent.x, radius * tangent.y, 1.0});
    return normalize({tangent.x, tangent.y, 1.0 / radius});
}

// Eq. (3-30): Λ = (erf(a) - 1)/2 + exp(-a²) / (2 a sqrt(π)), a = 1 / (α_o tanθ) by
// eq. (3-25), i.e. a = |wz| / sqrt(αx² wx² + αy² wy²). Λ = 0 at the normal, +inf at grazing.
inline double beckmann_lambda(const Vec3& w, double alpha_x, double alpha_y) {
    const double p2 = projected_roughness2_sin2(w, alpha_x, alpha_y);
    if (p2 <= 0.0) return 0.0;
    const double a = std::abs(w.z) / std::sqrt(p2);
    return -0.5 * std::erfc(a) + std::exp(-a * a) / (2.0 * a * kSqrtPi);
}

inline double beckmann_g1(const Vec3& w, double alpha_x, double alpha_y) {
    return 1.0 / (1.0 + beckmann_lambda(w, alpha_x, alpha_y));
}

}  // namespace principled_brdf::microfacet
