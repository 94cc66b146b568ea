// Float64 reference of the Disney principled BRDF (README "The model"), one function per
// lobe, then their sum. Plain on purpose: this is the yardstick the SIMD kernel
// is measured against, so it reads like the spec. Two liberties keep it
// accurate to the last digits where the literal form cancels, both exact for
// unit vectors: sin²θh from the components of H = wi + wo instead of
// 1 - cos²θh (the GTR1 peak, alpha down to 0.001), and cos θd = |H| / 2 with
// 1 - cos θd = |wi - wo|² / (4 (1 + cos θd)) (Schlick's (1 - cos θd)^5 as
// wi -> wo). The latter also makes f exactly reciprocal.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "params.hpp"

namespace principled_brdf::reference {

using Eigen::Vector3d;

inline constexpr double kPi = 3.14159265358979323846;

struct Material {
    Vector3d base_color{0.82, 0.67, 0.16};
    double metallic = 0.0;
    double subsurface = 0.0;
    double specular = 0.5;
    double specular_tint = 0.0;
    double roughness = 0.5;
    double anisotropic = 0.0;
    double sheen = 0.0;
    double sheen_tint = 0.5;
    double clearcoat = 0.0;
    double clearcoat_gloss = 1.0;

    // A packed row in the slot order of params.hpp.
    static Material from_slots(const double* row) {
        Material m;
        m.base_color = Vector3d(row[kBaseColorR], row[kBaseColorG], row[kBaseColorB]);
        m.metallic = row[kMetallic];
        m.subsurface = row[kSubsurface];
        m.specular = row[kSpecular];
        m.specular_tint = row[kSpecularTint];
        m.roughness = row[kRoughness];
        m.anisotropic = row[kAnisotropic];
        m.sheen = row[kSheen];
        m.sheen_tint = row[kSheenTint];
        m.clearcoat = row[kClearcoat];
        m.clearcoat_gloss = row[kClearcoatGloss];
        return m;
    }
};

// The four lobes of README "The model", each already weighted as it enters the sum.
struct Lobes {
    Vector3d diffuse = Vector3d::Zero();    // diffuse + subsurface, times (1 - metallic)
    Vector3d sheen = Vector3d::Zero();      // times (1 - metallic)
    Vector3d specular = Vector3d::Zero();   // primary GTR2 lobe
    Vector3d clearcoat = Vector3d::Zero();  // 0.25 clearcoat Gr Fr Dr, grey
    Vector3d total() const { return diffuse + sheen + specular + clearcoat; }
};

// The angles every lobe needs, computed once from a pair of directions.
struct Geometry {
    double cos_theta_l;   // n·wi
    double cos_theta_v;   // n·wo
    Vector3d h;           // normalize(wi + wo)
    double cos2_theta_h;  // (n·h)²
    double sin2_theta_h;  // 1 - (n·h)², from the tangential part of H
    double cos_theta_d;   // wi·h = wo·h = |H| / 2
    double one_minus_cos_theta_d;

    static Geometry from(const Vector3d& wi, const Vector3d& wo) {
        Geometry g;
        g.cos_theta_l = wi.z();
        g.cos_theta_v = wo.z();
        const Vector3d half_sum = wi + wo;
        const double inv_len2 = 1.0 / half_sum.squaredNorm();
        g.h = half_sum * std::sqrt(inv_len2);
        g.cos2_theta_h = half_sum.z() * half_sum.z() * inv_len2;
        g.sin2_theta_h = (half_sum.x() * half_sum.x() + half_sum.y() * half_sum.y()) * inv_len2;
        g.cos_theta_d = 0.5 * std::sqrt(half_sum.squaredNorm());
        g.one_minus_cos_theta_d = (wi - wo).squaredNorm() / (4.0 * (1.0 + g.cos_theta_d));
        return g;
    }
};

inline double mix(double a, double b, double t) { return a + (b - a) * t; }
inline Vector3d mix(const Vector3d& a, const Vector3d& b, double t) { return a + (b - a) * t; }

// Schlick(u) = clamp(1 - u, 0, 1)^5, given 1 - u
inline double schlick_weight_of_complement(double one_minus_u) {
    const double m = std::clamp(one_minus_u, 0.0, 1.0);
    return m * m * m * m * m;
}

inline double schlick_weight(double u) { return schlick_weight_of_complement(1.0 - u); }

// Hue and saturation of the base colour at unit luminance (Ctint).
inline Vector3d tint(const Vector3d& base_color) {
    const double luminance = 0.3 * base_color.x() + 0.6 * base_color.y() + 0.1 * base_color.z();
    return luminance > 0.0 ? Vector3d(base_color / luminance) : Vector3d::Ones();
}

// Cspec0: specular colour at normal incidence.
inline Vector3d specular_f0(const Material& m) {
    const Vector3d dielectric = m.specular * 0.08 * mix(Vector3d::Ones(), tint(m.base_color), m.specular_tint);
    return mix(dielectric, m.base_color, m.metallic);
}

// alpha_x, alpha_y from roughness and anisotropic (2014 addenda).
inline void specular_alphas(const Material& m, double& alpha_x, double& alpha_y) {
    const double aspect = std::sqrt(1.0 - 0.9 * m.anisotropic);
    const double alpha = m.roughness * m.roughness;
    alpha_x = std::max(0.001, alpha / aspect);
    alpha_y = std::max(0.001, alpha * aspect);
}

// Diffuse and its subsurface blend, (1/π) mix(Fd, ss, subsurface) Cd (1 - metallic).
inline Vector3d diffuse_lobe(const Material& m, const Geometry& g) {
    const double fl = schlick_weight(g.cos_theta_l);
    const double fv = schlick_weight(g.cos_theta_v);
    const double cos2_theta_d = g.cos_theta_d * g.cos_theta_d;

    const double fd90 = 0.5 + 2.0 * m.roughness * cos2_theta_d;
    const double fd = mix(1.0, fd90, fl) * mix(1.0, fd90, fv);

    const double fss90 = m.roughness * cos2_theta_d;
    const double fss = mix(1.0, fss90, fl) * mix(1.0, fss90, fv);
    const double ss = 1.25 * (fss * (1.0 / (g.cos_theta_l + g.cos_theta_v) - 0.5) + 0.5);

    return (1.0 / kPi) * mix(fd, ss, m.subsurface) * m.base_color * (1.0 - m.metallic);
}

// Sheen: FH sheen Csheen (1 - metallic).
inline Vector3d sheen_lobe(const Material& m, const Geometry& g) {
    const Vector3d sheen_color = mix(Vector3d::Ones(), tint(m.base_color), m.sheen_tint);
    return schlick_weight_of_complement(g.one_minus_cos_theta_d) * m.sheen * sheen_color * (1.0 - m.metallic);
}

// Anisotropic GTR2 (GGX), Burley 2012 eq. 13.
inline double gtr2_aniso_d(const Geometry& g, double alpha_x, double alpha_y) {
    const double hx = g.h.x() / alpha_x;
    const double hy = g.h.y() / alpha_y;
    const double denom = hx * hx + hy * hy + g.cos2_theta_h;
    return 1.0 / (kPi * alpha_x * alpha_y * denom * denom);
}

// S(w) = G1(w) / (2 n·w) for anisotropic Smith GGX.
inline double smith_ggx_aniso_s(const Vector3d& w, double alpha_x, double alpha_y) {
    const double sx = w.x() * alpha_x;
    const double sy = w.y() * alpha_y;
    return 1.0 / (w.z() + std::sqrt(sx * sx + sy * sy + w.z() * w.z()));
}

// Siso(w, g) = 1 / (n·w + sqrt(g² + (n·w)² - g² (n·w)²)) = G1(w) / (2 n·w) for
// isotropic Smith GGX with alpha g. For a unit w, g² (1 - (n·w)²) is
// g² ((w·x)² + (w·y)²): written so, nothing cancels when g is large.
inline double smith_ggx_iso_s(const Vector3d& w, double alpha) {
    const double a2 = alpha * alpha;
    return 1.0 / (w.z() + std::sqrt(a2 * (w.x() * w.x() + w.y() * w.y()) + w.z() * w.z()));
}

// Primary specular Gs Fs Ds; the model chooses Gs (README "The model").
inline Vector3d specular_lobe(const Material& m, const Vector3d& wi, const Vector3d& wo, const Geometry& g,
                              Model model) {
    double alpha_x, alpha_y;
    specular_alphas(m, alpha_x, alpha_y);
    const double ds = gtr2_aniso_d(g, alpha_x, alpha_y);
    const Vector3d fs = mix(specular_f0(m), Vector3d::Ones(), schlick_weight_of_complement(g.one_minus_cos_theta_d));
    double gs;
    if (model == Model::kDisney2012) {
        const double alpha_g = (0.5 + 0.5 * m.roughness) * (0.5 + 0.5 * m.roughness);
        gs = smith_ggx_iso_s(wi, alpha_g) * smith_ggx_iso_s(wo, alpha_g);
    } else {
        gs = smith_ggx_aniso_s(wi, alpha_x, alpha_y) * smith_ggx_aniso_s(wo, alpha_x, alpha_y);
    }
    return gs * ds * fs;
}

// GTR1 (Berry), gamma = 1, with 1 + (a²-1)cos²θh written as a² cos²θh + sin²θh.
inline double gtr1_d(const Geometry& g, double alpha) {
    if (alpha >= 1.0) return 1.0 / kPi;
    const double a2 = alpha * alpha;
    return (a2 - 1.0) / (kPi * std::log(a2) * (a2 * g.cos2_theta_h + g.sin2_theta_h));
}

// Clearcoat 0.25 clearcoat Gr Fr Dr, alpha = mix(0.1, 0.001, clearcoat_gloss).
inline Vector3d clearcoat_lobe(const Material& m, const Vector3d& wi, const Vector3d& wo, const Geometry& g) {
    const double dr = gtr1_d(g, mix(0.1, 0.001, m.clearcoat_gloss));
    const double fr = mix(0.04, 1.0, schlick_weight_of_complement(g.one_minus_cos_theta_d));
    const double gr = smith_ggx_iso_s(wi, 0.25) * smith_ggx_iso_s(wo, 0.25);
    return Vector3d::Constant(0.25 * m.clearcoat * gr * fr * dr);
}

// Every lobe at (wi, wo); all zero unless both lie strictly above the surface.
inline Lobes eval_lobes(const Material& m, const Vector3d& wi, const Vector3d& wo,
                        Model model = Model::kDisney2014) {
    Lobes lobes;
    if (wi.z() <= 0.0 || wo.z() <= 0.0) return lobes;
    const Geometry g = Geometry::from(wi, wo);
    lobes.diffuse = diffuse_lobe(m, g);
    lobes.sheen = sheen_lobe(m, g);
    lobes.specular = specular_lobe(m, wi, wo, g, model);
    lobes.clearcoat = clearcoat_lobe(m, wi, wo, g);
    return lobes;
}

// f(wi, wo) in 1/sr, without the cosine factor.
inline Vector3d eval(const Material& m, const Vector3d& wi, const Vector3d& wo,
                     Model model = Model::kDisney2014) {
    return eval_lobes(m, wi, wo, model).total();
}

}  // namespace principled_brdf::reference
