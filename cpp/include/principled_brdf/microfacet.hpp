// Microfacet toolkit in float64 (docs/microfacet.md): the GTR family of
// Burley 2012 (appendix B), anisotropic GGX with Smith masking, and anisotropic
// Beckmann (Walter et al. 2007; its Smith Λ as in Heitz 2014). The
// distributions are the model's types (model/distributions.hpp: Ggx, Gtr1,
// Gtr, Beckmann) instantiated for double; this file adds the toolkit's
// clamps, its two-sided conventions and the GTR closed forms at γ = 3/2 and 2.
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
#include <complex>

#include "model/f64.hpp"

namespace principled_brdf::microfacet {

inline constexpr double kPi = 3.14159265358979323846;
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

using f64::Beckmann;
using f64::Ggx;
using f64::Gtr;
using f64::Gtr1;
using ModelVec3 = f64::Vec3<double>;

inline ModelVec3 model_vec(const Vec3& w) { return {w.x, w.y, w.z}; }
inline Vec3 toolkit_vec(const ModelVec3& w) { return {w.x, w.y, w.z}; }
// w with its z made |z|: the toolkit's masking functions are two-sided
inline ModelVec3 upper(const Vec3& w) { return {w.x, w.y, std::abs(w.z)}; }
// the half vector's squares of a unit h, |h|² taken as 1
inline f64::HalfVector<double> half_of(const Vec3& h) { return {h.x * h.x, h.y * h.y, h.z, h.z * h.z, dot(h, h)}; }
inline f64::HalfVector<double> half_of(const Cos2Sin2& h) { return {h.sin2, 0.0, std::sqrt(h.cos2), h.cos2, 1.0}; }

// h = d / |d| for a model draw's unnormalised d
inline Vec3 normalized_draw(const ModelVec3& d) { return normalize(toolkit_vec(d)); }

// ---------------------------------------------------------------------------
// GTR, isotropic (appendix B.2). With a2 = α² and c = cosθh, every D below has
// the shape  norm / t^γ,  t = 1 + (a2 - 1) c², written as t = a2 cos²θh + sin²θh.

inline double gtr_t(const Cos2Sin2& h, double a2) { return a2 * h.cos2 + h.sin2; }

// Eq. (1), any γ > 0: the model's Gtr (its normaliser stays accurate at γ = 1 and α = 1).
inline double gtr_d_general(const Cos2Sin2& h, double alpha, double gamma) {
    if (h.cos2 <= 0.0) return 0.0;
    return Gtr<double>::from(clamp_gtr_alpha(alpha), clamp_gamma(gamma)).d(h.cos2, h.sin2);
}

// Eq. (4), γ = 1 (Berry; the clearcoat lobe): D = (a2-1) / (π ln a2) / t, the model's Gtr1.
inline double gtr1_d(const Cos2Sin2& h, double alpha) {
    if (h.cos2 <= 0.0) return 0.0;
    return Gtr1<double>::from_alpha(clamp_gtr_alpha(alpha)).d(half_of(h));
}

// Eq. (6), γ = 3/2: D = (a2 + α) / (2π) / t^(3/2).
inline double gtr3_2_d(const Cos2Sin2& h, double alpha) {
    if (h.cos2 <= 0.0) return 0.0;
    alpha = clamp_gtr_alpha(alpha);
    const double a2 = alpha * alpha;
    const double t = gtr_t(h, a2);
    return (a2 + alpha) / (2.0 * kPi * t * std::sqrt(t));
}

// Eq. (8), γ = 2 (isotropic GGX / Trowbridge-Reitz): D = a2 / (π t²), the model's Ggx.
inline double gtr2_d(const Cos2Sin2& h, double alpha) {
    if (h.cos2 <= 0.0) return 0.0;
    alpha = clamp_gtr_alpha(alpha);
    return Ggx<double>::from_alphas(alpha, alpha).d(half_of(h));
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

// Eq. (3), any γ > 0, as the pair (cos²θh, sin²θh): the model's Gtr draw.
inline Cos2Sin2 gtr_sample_cos2_general(double u2, double alpha, double gamma) {
    const auto [cos2, sin2] = Gtr<double>::from(clamp_gtr_alpha(alpha), clamp_gamma(gamma)).draw_cos2_sin2(u2);
    return {cos2, sin2};
}

// Eq. (5), γ = 1: the model's Gtr1 draw; cos²θh uniform at α = 1, its limit.
inline Cos2Sin2 gtr1_sample_cos2(double u2, double alpha) {
    alpha = clamp_gtr_alpha(alpha);
    if (alpha == 1.0) return {1.0 - u2, u2};
    const Gtr1<double> gtr1 = Gtr1<double>::from_alpha(alpha);
    return {gtr1.draw_cos2(u2), gtr1.draw_sin2(u2)};
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
// Anisotropic GGX (GTR2 aniso) and its Smith masking: the model's Ggx with the
// toolkit's clamps; Λ, G1 and G2 two-sided (they read |w·n|).

inline Ggx<double> ggx_of(double alpha_x, double alpha_y) {
    return Ggx<double>::from_alphas(clamp_alpha(alpha_x), clamp_alpha(alpha_y));
}

// Eq. (13): D = 1 / (π αx αy ((h·x/αx)² + (h·y/αy)² + (h·n)²)²).
inline double ggx_d(const Vec3& h, double alpha_x, double alpha_y) {
    if (h.z <= 0.0) return 0.0;
    return ggx_of(alpha_x, alpha_y).d(half_of(h));
}

inline double ggx_pdf_h(const Vec3& h, double alpha_x, double alpha_y) {
    return h.z <= 0.0 ? 0.0 : ggx_d(h, alpha_x, alpha_y) * h.z;
}

// Eq. (14)-(15): h ∝ (αx sqrt(u2) cos 2πu1, αy sqrt(u2) sin 2πu1, sqrt(1-u2)); u2 = 1 is the horizon.
inline Vec3 ggx_sample_h(double u1, double u2, double alpha_x, double alpha_y) {
    const auto [sin_phi, cos_phi] = f64::sincos_turns(u1);
    return normalized_draw(ggx_of(alpha_x, alpha_y).sample_distribution(sin_phi, cos_phi, u2));
}

// Λ(w) = (-1 + sqrt(1 + (αx² wx² + αy² wy²) / wz²)) / 2, in a form that neither
// cancels nor overflows as wz -> 0 (it is +inf at wz = 0).
inline double ggx_lambda(const Vec3& w, double alpha_x, double alpha_y) {
    return ggx_of(alpha_x, alpha_y).lambda(upper(w));
}

// G1 = 1 / (1 + Λ) = 2 |wz| / (|wz| + sqrt(wz² + p²)); 0 at grazing.
inline double ggx_g1(const Vec3& w, double alpha_x, double alpha_y) { return ggx_of(alpha_x, alpha_y).g1(upper(w)); }

// G1(w) / |wz| = 2 / (|wz| + sqrt(wz² + p²)): finite at grazing (it is 2 S(w) of docs/model.md, "The model").
inline double ggx_g1_over_cos(const Vec3& w, double alpha_x, double alpha_y) {
    return 2.0 / ggx_of(alpha_x, alpha_y).smith_denominator(upper(w));
}

// Separable Smith G2 = G1(wi) G1(wo) (what the model uses).
inline double ggx_g2_separable(const Vec3& wi, const Vec3& wo, double alpha_x, double alpha_y) {
    const Ggx<double> ggx = ggx_of(alpha_x, alpha_y);
    return ggx.g1(upper(wi)) * ggx.g1(upper(wo));
}

// Height-correlated Smith G2 = 1 / (1 + Λ(wi) + Λ(wo)) (Heitz 2014 eq. 99).
inline double ggx_g2_height_correlated(const Vec3& wi, const Vec3& wo, double alpha_x, double alpha_y) {
    return f64::g2_height_correlated(ggx_of(alpha_x, alpha_y), upper(wi), upper(wo));
}

// A wo below the horizon is mirrored (wo -> -wo), so the visible-normal sampler is two-sided.
inline Vec3 mirrored_above(const Vec3& wo) { return wo.z < 0.0 ? scale(wo, -1.0) : wo; }

// Visible normals by spherical caps (Dupuy & Benyoub 2023), the model's
// sampler: the density D_wo(h) of ggx_pdf_visible_h.
inline Vec3 ggx_sample_visible_h(const Vec3& wo, double u1, double u2, double alpha_x, double alpha_y) {
    const auto [sin_phi, cos_phi] = f64::sincos_turns(u1);
    const ModelVec3 d = ggx_of(alpha_x, alpha_y).sample_visible(model_vec(mirrored_above(wo)), sin_phi, cos_phi, u2);
    const double length2 = d.x * d.x + d.y * d.y + d.z * d.z;
    // u2 = 1 at a view along the normal: d = 0, any horizon normal is right
    return length2 > 0.0 ? normalized_draw(d) : Vec3{1.0, 0.0, 0.0};
}

// Density of visible normals, D_wo(h) = G1(wo) max(0, wo·h) D(h) / |wo_z|
// (Heitz 2014 eq. 38), with G1/|wo_z| taken in its grazing-safe form; wo mirrored as above.
inline double ggx_pdf_visible_h(const Vec3& h, const Vec3& wo, double alpha_x, double alpha_y) {
    const Vec3 view = mirrored_above(wo);
    const double cos_view_h = dot(view, h);
    if (cos_view_h <= 0.0 || h.z <= 0.0) return 0.0;
    return ggx_g1_over_cos(view, alpha_x, alpha_y) * cos_view_h * ggx_d(h, alpha_x, alpha_y);
}

// ---------------------------------------------------------------------------
// Anisotropic Beckmann (Walter et al. 2007, Heitz 2014 §5.2): the model's
// Beckmann with the toolkit's clamps; Λ and G1 two-sided.

inline Beckmann<double> beckmann_of(double alpha_x, double alpha_y) {
    return Beckmann<double>::from_alphas(clamp_alpha(alpha_x), clamp_alpha(alpha_y));
}

// D = exp(-((h·x/αx)² + (h·y/αy)²) / (h·n)²) / (π αx αy (h·n)⁴).
inline double beckmann_d(const Vec3& h, double alpha_x, double alpha_y) {
    if (h.z <= 0.0) return 0.0;
    return beckmann_of(alpha_x, alpha_y).d(half_of(h));
}

inline double beckmann_pdf_h(const Vec3& h, double alpha_x, double alpha_y) {
    return h.z <= 0.0 ? 0.0 : beckmann_d(h, alpha_x, alpha_y) * h.z;
}

// Stretched slope radius ρ = sqrt(-ln(1 - u2)), φ = 2π u1, h ∝ (ρ αx cos φ, ρ αy sin φ, 1).
inline Vec3 beckmann_sample_h(double u1, double u2, double alpha_x, double alpha_y) {
    const auto [sin_phi, cos_phi] = f64::sincos_turns(u1);
    return normalized_draw(beckmann_of(alpha_x, alpha_y).sample_distribution(sin_phi, cos_phi, u2));
}

// Λ = (erf(a) - 1)/2 + exp(-a²) / (2 a sqrt(π)), a = |wz| / sqrt(αx² wx² + αy² wy²):
// 0 at the normal, +inf at grazing.
inline double beckmann_lambda(const Vec3& w, double alpha_x, double alpha_y) {
    return beckmann_of(alpha_x, alpha_y).lambda(upper(w));
}

inline double beckmann_g1(const Vec3& w, double alpha_x, double alpha_y) {
    return beckmann_of(alpha_x, alpha_y).g1(upper(w));
}

// ---------------------------------------------------------------- interfaces
// Dielectric interfaces are the model's (model/dielectric.hpp): η is the
// index of the far side over that of the near side.

inline ModelVec3 to_model(const Vec3& w) { return {w.x, w.y, w.z}; }
inline Vec3 from_model(const ModelVec3& w) { return {w.x, w.y, w.z}; }

// Unpolarised Fresnel reflectance at |cos θi|, 1 under total internal reflection.
inline double fresnel_dielectric(double cos_theta_i, double eta) { return f64::fresnel_dielectric(cos_theta_i, eta); }

// The same for a conductor of complex index n = η + ik (relative to the near side):
// with cos θt = sqrt((c² + (n - 1)(n + 1)) / n²) complex,
//   rs = (cos θi - n cos θt) / (cos θi + n cos θt),  rp = (n cos θi - cos θt) / (n cos θi + cos θt),
//   F = (|rs|² + |rp|²) / 2;  at k = 0 it is fresnel_dielectric.
inline double fresnel_conductor(double cos_theta_i, double eta, double k) {
    const double c = std::min(std::abs(cos_theta_i), 1.0);
    const std::complex<double> n(eta, k);
    const std::complex<double> cos_t = std::sqrt((c * c + (n - 1.0) * (n + 1.0)) / (n * n));
    const std::complex<double> rs = (c - n * cos_t) / (c + n * cos_t);
    const std::complex<double> rp = (n * c - cos_t) / (n * c + cos_t);
    return 0.5 * (std::norm(rs) + std::norm(rp));
}

// Snell's law through the tangent plane; (0, 0, 0) under total internal reflection.
inline Vec3 refract(const Vec3& w, double eta) { return from_model(f64::refract(to_model(w), eta)); }

// h = normalize(wo + η wi) turned to the side of n: η the index on wi's side
// over that on wo's (1: the usual half vector). (0, 0, 0) where wo + η wi = 0.
inline Vec3 generalized_half_vector(const Vec3& wi, const Vec3& wo, double eta) {
    const Vec3 h = from_model(f64::generalized_half_vector(to_model(wi), to_model(wo), eta - 1.0));
    const double length2 = dot(h, h);
    return length2 > 0.0 ? scale(h, 1.0 / std::sqrt(length2)) : Vec3{0.0, 0.0, 0.0};
}

// dωh/dωi of refraction at h = generalized_half_vector(wi, wo, η): η² |wi·h| / (wo·h + η wi·h)².
inline double refraction_jacobian(const Vec3& wi, const Vec3& wo, double eta) {
    const Vec3 h = generalized_half_vector(wi, wo, eta);
    return f64::refraction_jacobian(to_model(wi), to_model(wo), to_model(h), eta);
}

}  // namespace principled_brdf::microfacet
