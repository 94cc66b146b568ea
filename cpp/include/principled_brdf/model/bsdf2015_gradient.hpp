// Part of the model (docs/gradients.md, "The 2015 BSDF"): the 2015 models'
// derivatives (the solid's and the thin sheet's) in their parameter slots and
// in the directions, by forward mode: eval2015
// instantiated for dual numbers (model/dual.hpp), so that every path of the
// model (its sides, η from specular through the exact Fresnel factor and the
// refraction, the clamps) is differentiated as it is evaluated. Where the
// model clamps (η >= 1.001, the alphas >= 0.001) the derivative is the
// active branch's.
//
// The 16 slots are taken kSlotsAPass at a time, one evaluation a pass: one
// instantiation of the model over Dual<F, kSlotsAPass> serves every pass, which
// keeps the kernels' code (and their compile time) a fraction of one over all
// 16 tangents, and a pass whose slots no column wants is skipped.
#pragma once  // once per translation unit: included only by model.hpp, which allows one namespace

inline constexpr int kSlotsAPass = 4;
inline constexpr int kGradientPasses = kParamSlots / kSlotsAPass;
static_assert(kGradientPasses * kSlotsAPass == kParamSlots, "the passes cover the slots");

template <class F>
using PassDual = Dual<F, kSlotsAPass>;

// The material's constants S (Solid2015 or ThinSheet2015 over PassDual<F>),
// pass by pass: pass q's tangents are those of slots q kSlotsAPass ... (q + 1) kSlotsAPass - 1.
template <class S>
struct GradientShading2015 {
    S pass[kGradientPasses];
};

template <class S, class F>
PB_MODEL_INLINE GradientShading2015<S> gradient_shading2015_of(const F* p, bool compensated = false) {
    GradientShading2015<S> g;
    for (int q = 0; q < kGradientPasses; ++q) {
        PassDual<F> slots[kParamSlots];
        for (int k = 0; k < kParamSlots; ++k) {
            const int tangent = k - q * kSlotsAPass;
            slots[k] = tangent >= 0 && tangent < kSlotsAPass ? PassDual<F>::variable(p[k], tangent) : PassDual<F>(p[k]);
        }
        g.pass[q] = shading2015_of<S>(slots, compensated);
    }
    return g;
}

// f (times |cos θl| if `cosine`), returned, and ∂f_c/∂p given to
// `jacobian(c, p, value)` for every channel c and every slot p the sink
// wants (jacobian.wants(p)).
template <class F, class S, class Sink>
PB_MODEL_INLINE Rgb<F> eval_gradient2015(const Vec3<F>& wi, const Vec3<F>& wo, const GradientShading2015<S>& s,
                                         TransportMode mode, bool cosine, Sink&& jacobian) {
    using D = PassDual<F>;
    Vec3<D> dwi{D(wi.x), D(wi.y), D(wi.z)}, dwo{D(wo.x), D(wo.y), D(wo.z)};
    D cosine_factor(cosine ? max(wi.z, -wi.z) : F(1.0));
    Rgb<F> value;
    for (int q = 0; q < kGradientPasses; ++q) {
        bool wanted = q == 0;  // (the first pass gives the value)
        for (int t = 0; t < kSlotsAPass; ++t) wanted = wanted || jacobian.wants(q * kSlotsAPass + t);
        if (!wanted) continue;
        Rgb<D> f = cosine_factor * eval2015(dwi, dwo, s.pass[q], mode);
        auto put = [&](int c, const D& channel) {
            for (int t = 0; t < kSlotsAPass; ++t)
                if (jacobian.wants(q * kSlotsAPass + t)) jacobian(c, q * kSlotsAPass + t, channel.d[t]);
            return channel.v;
        };
        Rgb<F> channels{put(0, f.r), put(1, f.g), put(2, f.b)};
        if (q == 0) value = channels;
    }
    return value;
}

// ---------------------------------------------------------------- in the directions (docs/gradients.md)
// The derivatives of f in wi and wo, as the 2014 model's (direction_gradient.hpp),
// by the same dual numbers: the material's constants carry no tangents, and the
// kDirectionSlots components wi_x ... wo_z take the tangents kSlotsAPass at a time, in
// kDirectionPasses2015 evaluations.
inline constexpr int kDirectionPasses2015 = (kDirectionSlots + kSlotsAPass - 1) / kSlotsAPass;

// S over PassDual<F>, its tangents 0
template <class S, class F>
PB_MODEL_INLINE S constant_shading2015_of(const F* p, bool compensated = false) {
    PassDual<F> slots[kParamSlots];
    for (int k = 0; k < kParamSlots; ++k) slots[k] = PassDual<F>(p[k]);
    return shading2015_of<S>(slots, compensated);
}

// the reference's row caches take a function of the row alone
template <class S, class F, bool compensated>
PB_MODEL_INLINE GradientShading2015<S> gradient_shading2015_of_row(const F* p) {
    return gradient_shading2015_of<S>(p, compensated);
}
template <class S, class F, bool compensated>
PB_MODEL_INLINE S constant_shading2015_of_row(const F* p) {
    return constant_shading2015_of<S>(p, compensated);
}

// f (times |cos θl| if `cosine`), returned, and ∂f_c/∂w_k given to
// `jacobian(c, k, value)` for every channel c and component k (wi_x ... wo_z);
// 0 wherever f is (a direction in the tangent plane, or not finite).
template <class F, class S, class Sink>
PB_MODEL_INLINE Rgb<F> eval_direction_gradient2015(const Vec3<F>& wi, const Vec3<F>& wo, const S& s,
                                                   TransportMode mode, bool cosine, Sink&& jacobian) {
    using D = PassDual<F>;
    const F components[kDirectionSlots] = {wi.x, wi.y, wi.z, wo.x, wo.y, wo.z};
    Rgb<F> value;
    for (int q = 0; q < kDirectionPasses2015; ++q) {
        D w[kDirectionSlots];
        for (int k = 0; k < kDirectionSlots; ++k) {
            const int tangent = k - q * kSlotsAPass;
            w[k] = tangent >= 0 && tangent < kSlotsAPass ? D::variable(components[k], tangent) : D(components[k]);
        }
        Vec3<D> dwi{w[0], w[1], w[2]}, dwo{w[3], w[4], w[5]};
        Rgb<D> f = eval2015(dwi, dwo, s, mode);
        if (cosine) f = max(dwi.z, -dwi.z) * f;
        auto put = [&](int c, const D& channel) {
            for (int t = 0; t < kSlotsAPass && q * kSlotsAPass + t < kDirectionSlots; ++t)
                jacobian(c, q * kSlotsAPass + t, channel.d[t]);
            return channel.v;
        };
        Rgb<F> channels{put(0, f.r), put(1, f.g), put(2, f.b)};
        if (q == 0) value = channels;
    }
    return value;
}
