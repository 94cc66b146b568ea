// Float64 reference of importance sampling and its pdf (README "Sampling and pdf"), exactly as
// the README section "Sampling and pdf" defines them: a mixture of three lobes
// (0 cosine, 1 primary specular, 2 clearcoat), the lobe chosen by u0, the
// direction drawn from u1, u2. The SIMD kernel implements the same definition
// on its own, so for the same u both return the same sample; keep every
// formula here literal and say which equation it is.
//
// Conventions of reference.hpp: local frame n = z, wi towards the light, wo
// towards the viewer. A density is in solid angle of wi. Everything is 0 (pdf,
// weight) unless cos θl > 0 and cos θv > 0, and nothing returns NaN: the only
// divisions are by quantities that are positive above the horizon, and the
// samplers guard their own 0/0 (see sample_visible_normal).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>

#include "params.hpp"
#include "reference.hpp"

namespace principled_brdf::reference {

// How the primary specular lobe draws its half vector (README "Sampling and pdf").
enum class SpecularSampler : int {
    kVisibleNormals = 0,  // Dupuy & Benyoub 2023 spherical caps (default)
    kDistribution = 1,    // Burley 2012 eq. 14-15, the paper's own
};

// One drawn direction with its mixture pdf and weight f cos θl / pdf.
struct Sample {
    Vector3d wi = Vector3d::Zero();
    double pdf = 0.0;
    Vector3d weight = Vector3d::Zero();
    int lobe = 0;  // 0 cosine, 1 primary specular, 2 clearcoat
};

// lum(c) = 0.3 R + 0.6 G + 0.1 B (the shader's luminance, Cdlum of README "The model").
inline double luminance(const Vector3d& c) { return 0.3 * c.x() + 0.6 * c.y() + 0.1 * c.z(); }

// Clearcoat GTR1 alpha, ac = mix(0.1, 0.001, clearcoat_gloss) (README "The model").
inline double clearcoat_alpha(const Material& m) { return mix(0.1, 0.001, m.clearcoat_gloss); }

// ---------------------------------------------------------------------------
// lobe selection

// P_k = w_k / (w0 + w1 + w2), the cheap albedo estimates of README "Lobe probabilities":
//   w0 = (1 - metallic) (Cdlum + 0.1 sheen lum(Csheen))
//   w1 = max(lum(mix(Cspec0, 1, FV)), 0.02)
//   w2 = 0.25 clearcoat mix(0.04, 1, FV)
// w1 >= 0.02, so the sum is never 0. FV = Schlick(cos θv) is 1 below the horizon.
inline std::array<double, 3> lobe_probabilities(const Material& m, const Vector3d& wo) {
    const double fv = schlick_weight(wo.z());
    const Vector3d sheen_color = mix(Vector3d::Ones(), tint(m.base_color), m.sheen_tint);
    const double w0 = (1.0 - m.metallic) * (luminance(m.base_color) + 0.1 * m.sheen * luminance(sheen_color));
    const double w1 = std::max(luminance(mix(specular_f0(m), Vector3d::Ones(), fv)), 0.02);
    const double w2 = 0.25 * m.clearcoat * mix(0.04, 1.0, fv);
    const double total = w0 + w1 + w2;
    return {w0 / total, w1 / total, w2 / total};
}

// Lobe 0 if u0 < P0, else lobe 1 if u0 < P0 + P1, else lobe 2 -- but never a lobe of
// probability 0: when P2 = 0, P0 + P1 may round to just below 1 (and u0 = 1 is
// accepted), and those u0 fall to lobe 1.
inline int choose_lobe(const std::array<double, 3>& probability, double u0) {
    if (u0 < probability[0]) return 0;
    if (u0 < probability[0] + probability[1] || probability[2] <= 0.0) return 1;
    return 2;
}

// ---------------------------------------------------------------------------
// directions and half vectors drawn from (u1, u2)

// Mirror of wo about the microfacet normal h: wi = 2 (wo·h) h - wo.
inline Vector3d reflect(const Vector3d& wo, const Vector3d& h) { return 2.0 * wo.dot(h) * h - wo; }

// Lobe 0, cosine-weighted hemisphere (Malley): φ = 2π u1 as for the other
// lobes, r = sqrt(u2), wi = (r cos φ, r sin φ, sqrt(1 - u2)).
inline Vector3d sample_cosine(double u1, double u2) {
    const double r = std::sqrt(u2);
    const double phi = 2.0 * kPi * u1;
    return Vector3d(r * std::cos(phi), r * std::sin(phi), std::sqrt(1.0 - u2));
}

// Lobe 1, visible normals of anisotropic GGX by spherical caps (Dupuy & Benyoub 2023):
// stretch wo to the alpha = 1 configuration, draw a point on the unit sphere's cap
// z >= -v.z, add v, unstretch. The half vector is a zero vector only at u2 = 1
// with φ opposite the stretched view (or wo = -n); there h = 0 is returned, so
// wi = -wo: below the horizon like every other u2 = 1 sample (there m.z = 0, h is
// horizontal and wi.z = -wo.z).
inline Vector3d sample_visible_normal(const Vector3d& wo, double alpha_x, double alpha_y, double u1, double u2) {
    const Vector3d v = Vector3d(alpha_x * wo.x(), alpha_y * wo.y(), wo.z()).normalized();
    const double phi = 2.0 * kPi * u1;
    const double z = (1.0 - u2) * (1.0 + v.z()) - v.z();
    const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Vector3d m = Vector3d(s * std::cos(phi), s * std::sin(phi), z) + v;
    const Vector3d h_unnormalised(alpha_x * m.x(), alpha_y * m.y(), m.z());
    const double length2 = h_unnormalised.squaredNorm();
    return length2 > 0.0 ? Vector3d(h_unnormalised / std::sqrt(length2)) : Vector3d::Zero();
}

// Lobe 1 option, the paper's distribution sampling (Burley 2012 eq. 14-15, multiplied
// through by sqrt(1 - u2)): h ∝ (sqrt(u2) ax cos 2πu1, sqrt(u2) ay sin 2πu1, sqrt(1 - u2)).
// Never the zero vector (ax, ay >= 0.001); u2 = 1 gives a horizontal h.
inline Vector3d sample_distribution_normal(double alpha_x, double alpha_y, double u1, double u2) {
    const double phi = 2.0 * kPi * u1;
    const double radius = std::sqrt(u2);
    return Vector3d(radius * alpha_x * std::cos(phi), radius * alpha_y * std::sin(phi), std::sqrt(1.0 - u2))
        .normalized();
}

// Lobe 2, GTR1 (gamma = 1, Burley 2012 appendix B eq. 5) with a = ac, φ = 2π u1:
//   cos²θh = (1 - a^(2(1 - u2))) / (1 - a²),   sin²θh = a² (a^(-2 u2) - 1) / (1 - a²),
// each written as a ratio of expm1 (a^x = exp(x ln a)) so that neither cancels,
// not even as a -> 1; a >= 1 is the uniform limit cos²θh = 1 - u2, sin²θh = u2
// (gtr1_d gives D = 1/π there).
inline Vector3d sample_gtr1_normal(double alpha, double u1, double u2) {
    double cos2_theta_h, sin2_theta_h;
    if (alpha >= 1.0) {
        cos2_theta_h = 1.0 - u2;
        sin2_theta_h = u2;
    } else {
        const double log_alpha = std::log(alpha);
        const double minus_one_minus_a2 = std::expm1(2.0 * log_alpha);  // a² - 1 < 0
        cos2_theta_h = std::expm1(2.0 * (1.0 - u2) * log_alpha) / minus_one_minus_a2;
        sin2_theta_h = -alpha * alpha * std::expm1(-2.0 * u2 * log_alpha) / minus_one_minus_a2;
    }
    const double phi = 2.0 * kPi * u1;
    const double sin_theta_h = std::sqrt(std::max(0.0, sin2_theta_h));
    return Vector3d(sin_theta_h * std::cos(phi), sin_theta_h * std::sin(phi), std::sqrt(std::max(0.0, cos2_theta_h)));
}

// ---------------------------------------------------------------------------
// per-lobe densities of wi, for cos θl > 0 and cos θv > 0 (g from Geometry::from(wi, wo))

// Lobe 0: cos θl / π.
inline double pdf_cosine(const Geometry& g) { return g.cos_theta_l / kPi; }

// Lobe 1, visible normals: G1(wo) Ds(h) / (4 cos θv) with anisotropic Smith G1 (Heitz 2014),
// = Ds(h) / (2 (cos θv + sqrt((wo·x ax)² + (wo·y ay)² + cos²θv))) = Ds S(wo) / 2.
inline double pdf_specular_visible(const Geometry& g, const Vector3d& wo, double alpha_x, double alpha_y) {
    return 0.5 * gtr2_aniso_d(g, alpha_x, alpha_y) * smith_ggx_aniso_s(wo, alpha_x, alpha_y);
}

// Lobe 1, distribution sampling: Ds(h) cos θh / (4 cos θd) (the Jacobian of the
// reflection is 1 / (4 cos θd)).
inline double pdf_specular_distribution(const Geometry& g, double alpha_x, double alpha_y) {
    return gtr2_aniso_d(g, alpha_x, alpha_y) * g.h.z() / (4.0 * g.cos_theta_d);
}

// Lobe 2: Dr(h) cos θh / (4 cos θd).
inline double pdf_clearcoat(const Geometry& g, double alpha) {
    return gtr1_d(g, alpha) * g.h.z() / (4.0 * g.cos_theta_d);
}

inline double pdf_specular(const Material& m, const Geometry& g, const Vector3d& wo, SpecularSampler sampler) {
    double alpha_x, alpha_y;
    specular_alphas(m, alpha_x, alpha_y);
    return sampler == SpecularSampler::kDistribution ? pdf_specular_distribution(g, alpha_x, alpha_y)
                                                     : pdf_specular_visible(g, wo, alpha_x, alpha_y);
}

// ---------------------------------------------------------------------------
// the mixture

// P0 pdf0 + P1 pdf1 + P2 pdf2; 0 unless cos θl > 0 and cos θv > 0 (then wi + wo != 0
// and cos θd > 0, so nothing divides by 0, and every pdf_k is finite).
inline double pdf(const Material& m, const Vector3d& wi, const Vector3d& wo,
                  SpecularSampler sampler = SpecularSampler::kVisibleNormals) {
    if (wi.z() <= 0.0 || wo.z() <= 0.0) return 0.0;
    const Geometry g = Geometry::from(wi, wo);
    const std::array<double, 3> probability = lobe_probabilities(m, wo);
    return probability[0] * pdf_cosine(g) + probability[1] * pdf_specular(m, g, wo, sampler) +
           probability[2] * pdf_clearcoat(g, clearcoat_alpha(m));
}

// wi drawn from the lobe that u0 chooses, with (u1, u2) as README "Sampling and pdf" says.
inline Vector3d sample_direction(const Material& m, const Vector3d& wo, int lobe, double u1, double u2,
                                 SpecularSampler sampler) {
    if (lobe == 0) return sample_cosine(u1, u2);
    if (lobe == 2) return reflect(wo, sample_gtr1_normal(clearcoat_alpha(m), u1, u2));
    double alpha_x, alpha_y;
    specular_alphas(m, alpha_x, alpha_y);
    const Vector3d h = sampler == SpecularSampler::kDistribution
                           ? sample_distribution_normal(alpha_x, alpha_y, u1, u2)
                           : sample_visible_normal(wo, alpha_x, alpha_y, u1, u2);
    return reflect(wo, h);
}

// The whole sample: wi, its mixture pdf (the number pdf() gives for the pair) and
// weight = f(wi, wo) cos θl / pdf; pdf and weight are 0 when wi or wo is at or below
// the horizon (wi is still the finite direction drawn).
inline Sample sample(const Material& m, const Vector3d& wo, double u0, double u1, double u2,
                     Model model = Model::kDisney2014,
                     SpecularSampler sampler = SpecularSampler::kVisibleNormals) {
    Sample s;
    s.lobe = choose_lobe(lobe_probabilities(m, wo), u0);
    s.wi = sample_direction(m, wo, s.lobe, u1, u2, sampler);
    s.pdf = pdf(m, s.wi, wo, sampler);
    if (s.pdf > 0.0) s.weight = eval(m, s.wi, wo, model) * (s.wi.z() / s.pdf);
    return s;
}

}  // namespace principled_brdf::reference
