// The float64 reference's derivatives of f in the directions (docs/gradients.md,
// "Derivatives in the directions"): the model's forward mode
// (model/direction_gradient.hpp) for double, one pair at a time.
#pragma once

#include <Eigen/Core>

#include "reference.hpp"

namespace principled_brdf::reference {

using DirectionShading = Shading<DirectionDual<double>>;
using DirectionShadingCache = RowCache<DirectionShading, &direction_shading_of<double>>;

// f (times cos θl if asked) and ∂f_c/∂(wi_x, wi_y, wi_z, wo_x, wo_y, wo_z); both
// zero unless wi and wo lie strictly above the surface.
struct DirectionGradient {
    Vector3d value = Vector3d::Zero();
    Eigen::Matrix<double, 3, kDirectionSlots, Eigen::RowMajor> jacobian =
            Eigen::Matrix<double, 3, kDirectionSlots, Eigen::RowMajor>::Zero();
};

template <Model model>
DirectionGradient direction_gradient_of(const DirectionShading& s, const Vec3<double>& wi, const Vec3<double>& wo,
                                        bool cosine) {
    DirectionGradient out;
    out.value = vector3d(f64::eval_direction_gradient<model>(
            wi, wo, s, cosine, [&](int c, int k, double value) { out.jacobian(c, k) = value; }));
    return out;
}

inline DirectionGradient eval_direction_grad(const DirectionShading& s, const Vector3d& wi, const Vector3d& wo,
                                             Model model = Model::kDisney2014, bool cosine = false) {
    return model == Model::kDisney2012 ? direction_gradient_of<Model::kDisney2012>(s, vec3(wi), vec3(wo), cosine)
                                       : direction_gradient_of<Model::kDisney2014>(s, vec3(wi), vec3(wo), cosine);
}

// The 2015 models' (model/bsdf2015_gradient.hpp): over the whole sphere, in `mode`.
template <Model model, bool compensated>
using DirectionShading2015Cache = RowCache<Shading2015<model, PassDual<double>>,
                                           &constant_shading2015_of_row<Shading2015<model, PassDual<double>>, double, compensated>>;

template <class S, If2015<S, PassDual<double>> = 0>
inline DirectionGradient eval_direction_grad(const S& s, const Vector3d& wi, const Vector3d& wo,
                                             bool cosine, TransportMode mode) {
    DirectionGradient out;
    out.value = vector3d(f64::eval_direction_gradient2015(
            vec3(wi), vec3(wo), s, mode, cosine, [&](int c, int k, double value) { out.jacobian(c, k) = value; }));
    return out;
}

}  // namespace principled_brdf::reference
