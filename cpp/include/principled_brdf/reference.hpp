// The float64 reference: the model (docs/model.md) instantiated for double,
// with exact arithmetic where the kernels approximate (model/scalar_ops.hpp),
// one pair at a time. It is the yardstick the SIMD kernels are measured
// against; tests/numpy_model.py, an independent transcription of
// docs/model.md, "The model", and tests/numpy_model_2015.py, of
// docs/model-2015.md, are its own.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "model/f64.hpp"
#include "model_table.hpp"

namespace principled_brdf::reference {

using namespace principled_brdf::f64;  // the model's parts for double
using Eigen::Vector3d;

// The parameters of docs/model.md, "The model", with their defaults.
struct Material {
    Vector3d base_color{default_of(kBaseColorR), default_of(kBaseColorG), default_of(kBaseColorB)};
    double metallic = default_of(kMetallic);
    double subsurface = default_of(kSubsurface);
    double specular = default_of(kSpecular);
    double specular_tint = default_of(kSpecularTint);
    double roughness = default_of(kRoughness);
    double anisotropic = default_of(kAnisotropic);
    double sheen = default_of(kSheen);
    double sheen_tint = default_of(kSheenTint);
    double clearcoat = default_of(kClearcoat);
    double clearcoat_gloss = default_of(kClearcoatGloss);
    double spec_trans = default_of(kSpecTrans);
    double flatness = default_of(kFlatness);
    double diff_trans = default_of(kDiffTrans);

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
        m.spec_trans = row[kSpecTrans];
        m.flatness = row[kFlatness];
        m.diff_trans = row[kDiffTrans];
        return m;
    }

    std::array<double, kParamSlots> slots() const {
        return {base_color.x(), base_color.y(), base_color.z(), metallic, subsurface, specular, specular_tint,
                roughness, anisotropic, sheen, sheen_tint, clearcoat, clearcoat_gloss, spec_trans, flatness, diff_trans};
    }

    Shading<double> shading() const { return shading_of(slots().data()); }
};

// What a run of packed material rows (slot order of params.hpp) prepares,
// prepared again only when a row differs from the one before: a uniform
// material is prepared once per call, as the kernels hoist it.
template <class Prepared, Prepared (*prepare)(const double*)>
class RowCache {
public:
    // `row` is read only when it is not the row of the last call (one shared row is prepared once)
    const Prepared& of(const double* row) {
        if (prepared_ && row == last_) return value_;
        last_ = row;
        if (!prepared_ || !std::equal(row, row + kParamSlots, row_.begin())) {
            std::copy(row, row + kParamSlots, row_.begin());
            value_ = prepare(row_.data());
            prepared_ = true;
        }
        return value_;
    }

private:
    const double* last_ = nullptr;
    std::array<double, kParamSlots> row_{};
    Prepared value_{};
    bool prepared_ = false;
};

// A material's shading with the partials of its constants, for eval_grad.
struct GradientShading {
    Shading<double> shading;
    MaterialPartials<double> partials;
};

inline GradientShading gradient_shading_of(const double* row) { return {shading_of(row), material_partials_of(row)}; }

// A material's shading with its multiple-scattering lobe (energy compensation,
// Kulla & Conty 2017; model/energy.hpp), for one model's tables.
struct Compensated {
    Shading<double> shading;
    MultipleScatteringLobe<double> ms;
};

template <Model model>
Compensated compensated_of(const double* row) {
    const Shading<double> s = shading_of(row);
    return {s, multiple_scattering_of(row, s, model)};
}

using ShadingCache = RowCache<Shading<double>, &shading_of<double>>;
template <Model model>
using CompensatedCache = RowCache<Compensated, &compensated_of<model>>;
using GradientShadingCache = RowCache<GradientShading, &gradient_shading_of>;
template <Model model, bool compensated>
using Shading2015Cache = RowCache<Shading2015<model, double>, &shading2015_of_row<Shading2015<model, double>, double, compensated>>;

// f(cache) with the row cache Cache<model, compensated> of a 2015 model
// (Shading2015Cache, GradientShading2015Cache, DirectionShading2015Cache), with
// the energy compensation where `compensated` and the model offers it; nothing for the others.
template <template <Model, bool> class Cache, class Function>
void with_cache2015(Model model, bool compensated, Function&& f) {
    with_model(model, [&](auto constant) {
        if constexpr (is_bsdf(constant())) {
            if constexpr (row_of(constant()).energy_compensation) {
                if (compensated) {
                    Cache<constant(), true> cache;
                    f(cache);
                    return 0;
                }
            }
            Cache<constant(), false> cache;
            f(cache);
        }
        return 0;
    });
}

// The lobes of kLobeNames (params.hpp), in its order, each already weighted as it enters the sum.
struct Lobes {
    Vector3d diffuse = Vector3d::Zero();    // diffuse + subsurface, times (1 - metallic)
    Vector3d sheen = Vector3d::Zero();      // times (1 - metallic)
    Vector3d specular = Vector3d::Zero();   // primary GGX lobe
    Vector3d clearcoat = Vector3d::Zero();  // grey
    Vector3d multiple_scattering = Vector3d::Zero();  // energy compensation (model/energy.hpp); 0 when off
    Vector3d transmission = Vector3d::Zero();         // the 2015 models' (model/bsdf2015.hpp)
    Vector3d diffuse_transmission = Vector3d::Zero();  // the thin sheet's
    Vector3d total() const {
        return diffuse + sheen + specular + clearcoat + multiple_scattering + transmission + diffuse_transmission;
    }
};

inline Vec3<double> vec3(const Vector3d& w) { return {w.x(), w.y(), w.z()}; }
inline Vector3d vector3d(const Vec3<double>& w) { return {w.x, w.y, w.z}; }
inline Vector3d vector3d(const Rgb<double>& c) { return {c.r, c.g, c.b}; }

template <Model model>
Lobes lobes_of(const Shading<double>& s, const Vec3<double>& wi, const Vec3<double>& wo) {
    const Geometry<double> g = geometry_of(wi, wo);
    if (!above_surface(g)) return {};
    const LobeValues<double> v = f64::eval_lobes<model>(g, s, view_of<model>(wo, s));
    return {vector3d(v.diffuse_rgb(s)), vector3d(v.sheen_rgb(s)), vector3d(v.specular_rgb(s)), vector3d(v.clearcoat_rgb())};
}

// Every lobe at (wi, wo); all zero unless both lie strictly above the surface.
// Each function below takes the material or its prepared Shading.
inline Lobes eval_lobes(const Shading<double>& s, const Vector3d& wi, const Vector3d& wo,
                        Model model = Model::kDisney2014) {
    return model == Model::kDisney2012 ? lobes_of<Model::kDisney2012>(s, vec3(wi), vec3(wo))
                                       : lobes_of<Model::kDisney2014>(s, vec3(wi), vec3(wo));
}

inline Lobes eval_lobes(const Material& m, const Vector3d& wi, const Vector3d& wo, Model model = Model::kDisney2014) {
    return eval_lobes(m.shading(), wi, wo, model);
}

template <Model model>
Vector3d eval_of(const Shading<double>& s, const Vec3<double>& wi, const Vec3<double>& wo) {
    const Geometry<double> g = geometry_of(wi, wo);
    if (!above_surface(g)) return Vector3d::Zero();
    return vector3d(f64::eval_lobes<model>(g, s, view_of<model>(wo, s)).total(s));
}

// f(wi, wo) in 1/sr, without the cosine factor.
inline Vector3d eval(const Shading<double>& s, const Vector3d& wi, const Vector3d& wo, Model model = Model::kDisney2014) {
    return model == Model::kDisney2012 ? eval_of<Model::kDisney2012>(s, vec3(wi), vec3(wo))
                                       : eval_of<Model::kDisney2014>(s, vec3(wi), vec3(wo));
}

inline Vector3d eval(const Material& m, const Vector3d& wi, const Vector3d& wo, Model model = Model::kDisney2014) {
    return eval(m.shading(), wi, wo, model);
}

// f and its Jacobian ∂f_c/∂p over the 13 parameter slots (docs/gradients.md); both zero
// unless wi and wo lie strictly above the surface.
struct Gradient {
    Vector3d value = Vector3d::Zero();
    Eigen::Matrix<double, 3, kGradientSlots, Eigen::RowMajor> jacobian =
            Eigen::Matrix<double, 3, kGradientSlots, Eigen::RowMajor>::Zero();
};

template <Model model>
Gradient gradient_of(const GradientShading& prepared, const Vec3<double>& wi, const Vec3<double>& wo) {
    const Shading<double>& s = prepared.shading;
    const Geometry<double> g = geometry_of(wi, wo);
    Gradient out;
    if (!above_surface(g)) return out;
    out.value = vector3d(f64::eval_gradient<model>(g, s, view_of<model>(wo, s), prepared.partials,
                                                   [](double x) { return x; },
                                                   [&](int c, int p, double value) { out.jacobian(c, p) = value; }));
    return out;
}

inline Gradient eval_grad(const GradientShading& prepared, const Vector3d& wi, const Vector3d& wo,
                          Model model = Model::kDisney2014) {
    return model == Model::kDisney2012 ? gradient_of<Model::kDisney2012>(prepared, vec3(wi), vec3(wo))
                                       : gradient_of<Model::kDisney2014>(prepared, vec3(wi), vec3(wo));
}

inline Gradient eval_grad(const Material& m, const Vector3d& wi, const Vector3d& wo, Model model = Model::kDisney2014) {
    return eval_grad(gradient_shading_of(m.slots().data()), wi, wo, model);
}

// ---------------------------------------------------------------- sampling (docs/sampling.md)

// P_k = w_k / (w0 + w1 + w2) at wo: the chances of the cosine, specular and clearcoat lobes.
inline std::array<double, 3> lobe_probabilities(const Shading<double>& s, const Vector3d& wo) {
    const LobeWeights<double> w = lobe_weights(schlick_weight(wo.z()), s);
    return {s.diffuse.cosine_lobe_weight * w.inv_total, w.specular * w.inv_total, w.clearcoat * w.inv_total};
}

inline std::array<double, 3> lobe_probabilities(const Material& m, const Vector3d& wo) {
    return lobe_probabilities(m.shading(), wo);
}

// The mixture density Σ P_k pdf_k(wi) of wi given wo; 0 unless both lie strictly above the surface.
inline double pdf(const Shading<double>& s, const Vector3d& wi, const Vector3d& wo,
                  SpecularSampler sampler = SpecularSampler::kVisibleNormals) {
    const Geometry<double> g = geometry_of(vec3(wi), vec3(wo));
    if (!above_surface(g)) return 0.0;
    const View<double> view = view_of<Model::kDisney2014>(vec3(wo), s);  // the pdf does not depend on the model
    return mixture_pdf(g, s, view, lobe_weights(view.fv, s), sampler);
}

inline double pdf(const Material& m, const Vector3d& wi, const Vector3d& wo,
                  SpecularSampler sampler = SpecularSampler::kVisibleNormals) {
    return pdf(m.shading(), wi, wo, sampler);
}

// One drawn direction with its mixture pdf and weight f cos θl / pdf.
struct Sample {
    Vector3d wi = Vector3d::Zero();
    double pdf = 0.0;
    Vector3d weight = Vector3d::Zero();
    int lobe = 0;  // 0 cosine, 1 primary specular, 2 clearcoat
};

template <Model model>
Sample sample_of(const Shading<double>& s, const Vec3<double>& wo, const Uniforms<double>& u, SpecularSampler sampler) {
    const double fv = schlick_weight(wo.z);
    const LobeWeights<double> weights = lobe_weights(fv, s);
    const LobeChoice<double> choice = choose_lobe(u.u0, s, weights);
    const Weighed<double> w = weigh<model>(wo, fv, weights, sample_direction(wo, u, choice, s, sampler), s, sampler);
    return {vector3d(w.wi), w.pdf, vector3d(w.weight), choice.cosine ? 0 : choice.specular ? 1 : 2};
}

// The whole sample for (u0, u1, u2): wi, its mixture pdf (the number pdf()
// gives for the pair) and weight = f(wi, wo) cos θl / pdf; pdf and weight are
// 0 when wi or wo is at or below the horizon (wi is still the direction drawn).
inline Sample sample(const Shading<double>& s, const Vector3d& wo, double u0, double u1, double u2,
                     Model model = Model::kDisney2014, SpecularSampler sampler = SpecularSampler::kVisibleNormals) {
    const Uniforms<double> u{u0, u1, u2};
    return model == Model::kDisney2012 ? sample_of<Model::kDisney2012>(s, vec3(wo), u, sampler)
                                       : sample_of<Model::kDisney2014>(s, vec3(wo), u, sampler);
}

inline Sample sample(const Material& m, const Vector3d& wo, double u0, double u1, double u2,
                     Model model = Model::kDisney2014, SpecularSampler sampler = SpecularSampler::kVisibleNormals) {
    return sample(m.shading(), wo, u0, u1, u2, model, sampler);
}

// ---------------------------------------------------------------- energy compensation (model/energy.hpp)
// The same functions for a Compensated material: f gains the multiple-scattering
// lobe, the cosine lobe's mixture weight gains w3 = its albedo at wo. `model`
// must be the one c was prepared for (its tables).

inline double missing_energy_of_view(const Compensated& c, const Vector3d& wo) { return c.ms.missing_energy(wo.z()); }

inline Vector3d multiple_scattering_of(const Compensated& c, const Vector3d& wi, const Vector3d& wo) {
    const Geometry<double> g = geometry_of(vec3(wi), vec3(wo));
    if (!above_surface(g)) return Vector3d::Zero();
    return vector3d(c.ms.rgb(c.ms.value(g, c.ms.missing_energy(wo.z()))));
}

inline Lobes eval_lobes(const Compensated& c, const Vector3d& wi, const Vector3d& wo, Model model = Model::kDisney2014) {
    Lobes out = eval_lobes(c.shading, wi, wo, model);
    out.multiple_scattering = multiple_scattering_of(c, wi, wo);
    return out;
}

inline Vector3d eval(const Compensated& c, const Vector3d& wi, const Vector3d& wo, Model model = Model::kDisney2014) {
    return eval(c.shading, wi, wo, model) + multiple_scattering_of(c, wi, wo);
}

inline Shading<double> compensated_mixture(const Compensated& c, const Vector3d& wo) {
    return with_multiple_scattering_weight(c.shading, c.ms.weight(c.ms.missing_energy(wo.z())));
}

// (P0, P1, P2): the cosine lobe's chance includes the multiple-scattering lobe's
inline std::array<double, 3> lobe_probabilities(const Compensated& c, const Vector3d& wo) {
    return lobe_probabilities(compensated_mixture(c, wo), wo);
}

inline double pdf(const Compensated& c, const Vector3d& wi, const Vector3d& wo,
                  SpecularSampler sampler = SpecularSampler::kVisibleNormals) {
    return pdf(compensated_mixture(c, wo), wi, wo, sampler);
}

template <Model model>
Sample compensated_sample_of(const Compensated& c, const Vec3<double>& wo, const Uniforms<double>& u,
                             SpecularSampler sampler) {
    const double missing_wo = c.ms.missing_energy(wo.z);
    const Shading<double> s = with_multiple_scattering_weight(c.shading, c.ms.weight(missing_wo));
    const double fv = schlick_weight(wo.z);
    const LobeWeights<double> weights = lobe_weights(fv, s);
    const LobeChoice<double> choice = choose_lobe(u.u0, s, weights);
    const CompensatedWeighed<double> cw =
            weigh_compensated<model>(wo, fv, weights, sample_direction(wo, u, choice, s, sampler), s, c.ms, missing_wo, sampler);
    const Weighed<double>& w = cw.weighed;
    return {vector3d(w.wi), w.pdf, vector3d(w.weight), choice.cosine ? 0 : choice.specular ? 1 : 2};
}

inline Sample sample(const Compensated& c, const Vector3d& wo, double u0, double u1, double u2,
                     Model model = Model::kDisney2014, SpecularSampler sampler = SpecularSampler::kVisibleNormals) {
    const Uniforms<double> u{u0, u1, u2};
    return model == Model::kDisney2012 ? compensated_sample_of<Model::kDisney2012>(c, vec3(wo), u, sampler)
                                       : compensated_sample_of<Model::kDisney2014>(c, vec3(wo), u, sampler);
}

// ---------------------------------------------------------------- the 2015 models (model/bsdf2015.hpp)
// Directions anywhere on the sphere; f = 0 where either lies in the tangent plane.
// The functions below take either model's constants, Solid2015 or ThinSheet2015 (over F).
template <class S, class F = double>
using If2015 = std::enable_if_t<std::is_base_of_v<Interface2015<F>, S>, int>;

template <class S, If2015<S> = 0>
inline Lobes eval_lobes(const S& s, const Vector3d& wi, const Vector3d& wo,
                        TransportMode mode = TransportMode::kRadiance) {
    const Lobes2015<double> v = eval_lobes2015(vec3(wi), vec3(wo), s, mode);
    Lobes out;
    out.diffuse = vector3d(v.diffuse);
    out.sheen = vector3d(v.sheen);
    out.specular = vector3d(v.specular);
    out.clearcoat = vector3d(v.clearcoat);
    out.transmission = vector3d(v.transmission);
    out.diffuse_transmission = vector3d(v.diffuse_transmission);
    out.multiple_scattering = vector3d(v.multiple_scattering);
    return out;
}

template <class S, If2015<S> = 0>
inline Vector3d eval(const S& s, const Vector3d& wi, const Vector3d& wo,
                     TransportMode mode = TransportMode::kRadiance) {
    return vector3d(eval2015(vec3(wi), vec3(wo), s, mode));
}

// P_k at wo of the sampled lobes (kSampledLobeNames); a solid's interface counted as its split at h = n.
template <class S, If2015<S> = 0>
inline std::array<double, kSampledLobeNames.size()> lobe_probabilities(const S& s, const Vector3d& wo) {
    const LobeWeights2015<double> w = lobe_weights2015(side_of(vec3(wo), vec3(wo), s), s);
    const double reflected = w.interface_reflection;
    return {w.cosine * w.inv_total, (w.specular + reflected) * w.inv_total, w.clearcoat * w.inv_total,
            (w.transmission - reflected) * w.inv_total, w.diffuse_transmission * w.inv_total};
}

// The mixture density of wi given wo over the whole sphere.
template <class S, If2015<S> = 0>
inline double pdf(const S& s, const Vector3d& wi, const Vector3d& wo,
                  SpecularSampler sampler = SpecularSampler::kVisibleNormals) {
    return pdf2015(vec3(wi), vec3(wo), s, sampler);
}

// As sample() of the BRDFs; lobe 3 is the transmission, 4 the thin sheet's diffuse transmission. wi = 0 where the
// transmission's microfacet reflects totally (no refracted direction).
template <class S, If2015<S> = 0>
inline Sample sample(const S& s, const Vector3d& wo, double u0, double u1, double u2,
                     SpecularSampler sampler = SpecularSampler::kVisibleNormals,
                     TransportMode mode = TransportMode::kRadiance) {
    const Sample2015<double> drawn = sample2015(vec3(wo), Uniforms<double>{u0, u1, u2}, s, sampler, mode);
    const LobeChoice2015<double>& c = drawn.choice;
    const int lobe = c.transmission ? 3 : c.diffuse_transmission ? 4 : c.reflected.cosine ? 0 : c.reflected.specular ? 1 : 2;
    return {vector3d(drawn.wi), drawn.pdf, vector3d(drawn.weight), lobe};
}

// f and its Jacobian ∂f_c/∂p over every parameter slot (model/bsdf2015_gradient.hpp).
struct Gradient2015 {
    Vector3d value = Vector3d::Zero();
    Eigen::Matrix<double, 3, kParamSlots, Eigen::RowMajor> jacobian =
            Eigen::Matrix<double, 3, kParamSlots, Eigen::RowMajor>::Zero();
};

template <Model model, bool compensated>
using GradientShading2015Cache =
        RowCache<GradientShading2015<Shading2015<model, PassDual<double>>>,
                 &gradient_shading2015_of_row<Shading2015<model, PassDual<double>>, double, compensated>>;

template <class S>
inline Gradient2015 eval_grad(const GradientShading2015<S>& s, const Vector3d& wi, const Vector3d& wo,
                              TransportMode mode = TransportMode::kRadiance) {
    struct Sink {
        Gradient2015& out;
        bool wants(int) const { return true; }
        void operator()(int c, int p, double value) { out.jacobian(c, p) = value; }
    };
    Gradient2015 out;
    out.value = vector3d(eval_gradient2015(vec3(wi), vec3(wo), s, mode, false, Sink{out}));
    return out;
}

}  // namespace principled_brdf::reference
