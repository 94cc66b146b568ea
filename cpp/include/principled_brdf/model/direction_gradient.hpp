// Part of the model (docs/model.md): the derivatives of f in the directions,
// ∂f_c/∂wi and ∂f_c/∂wo, by forward mode: the model's own eval instantiated
// for Dual<F, 6> (model/dual.hpp), whose tangents are those of the six
// components wi_x, wi_y, wi_z, wo_x, wo_y, wo_z. They are the derivatives of
// f as a function of the two 3-vectors as given, not renormalised
// (docs/gradients.md, "Derivatives in the directions").
#pragma once  // once per translation unit: included only by model.hpp, which allows one namespace

inline constexpr int kDirectionSlots = 6;  // wi_x, wi_y, wi_z, wo_x, wo_y, wo_z

template <class F>
using DirectionDual = Dual<F, kDirectionSlots>;

// The material's constants for the forward pass: shading_of over constants
// (tangents 0), so that every constant a lobe prepares is carried as the
// model computes it.
template <class F>
PB_MODEL_INLINE Shading<DirectionDual<F>> direction_shading_of(const F* p) {
    DirectionDual<F> slots[kParamSlots];
    for (int k = 0; k < kParamSlots; ++k) slots[k] = DirectionDual<F>(p[k]);
    return shading_of(slots);
}

// f (times cos θl if `cosine`), returned, and its 18 derivatives, given to
// `jacobian(c, k, value)` for every channel c and direction component k
// (wi_x ... wo_z); all 0 unless both directions lie strictly above the
// surface (and, checks off, H is finite), as f is.
template <Model model, class F, class Sink>
PB_MODEL_INLINE Rgb<F> eval_direction_gradient(const Vec3<F>& wi, const Vec3<F>& wo, const Shading<DirectionDual<F>>& s,
                                               bool cosine, Sink&& jacobian) {
    using D = DirectionDual<F>;
    Vec3<D> dwi{D::variable(wi.x, 0), D::variable(wi.y, 1), D::variable(wi.z, 2)};
    Vec3<D> dwo{D::variable(wo.x, 3), D::variable(wo.y, 4), D::variable(wo.z, 5)};
    Geometry<D> g = geometry_of(dwi, dwo);
    MaskOf<F> above = above_surface(g);
    Rgb<D> f = eval_lobes<model>(g, s, view_of<model>(dwo, s)).total(s);
    if (cosine) f = dwi.z * f;
    F zero(0.0);
    auto put = [&](int c, const D& channel) {
        for (int k = 0; k < kDirectionSlots; ++k) jacobian(c, k, select(above, channel.d[k], zero));
        return select(above, channel.v, zero);
    };
    return {put(0, f.r), put(1, f.g), put(2, f.b)};
}
