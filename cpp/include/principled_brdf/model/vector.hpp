// Part of the model (docs/model.md): included inside a namespace that defines
// the operations of its number types. Vectors, colors and the small helpers
// every part uses, over a number type F: double (the reference) or
// xsimd::batch<float, Arch> (the kernels).
#pragma once  // once per translation unit: included only by model.hpp, which allows one namespace

// What a comparison of two F gives: bool for double, a batch_bool for a batch.
template <class F>
using MaskOf = decltype(F() < F());

// Whether x is nonzero in some lane: the test by which a part skips a term
// that is 0 in every lane. Dual numbers (model/dual.hpp) overload it to count
// their tangents too, so that a term whose weight is 0 keeps its derivative.
template <class F>
PB_MODEL_INLINE bool nonzero_anywhere(const F& x) { return any(x != F(0.0)); }

template <class F>
struct Vec3 {
    F x, y, z;
};

template <class F>
struct Rgb {
    F r, g, b;
};

template <class F>
PB_MODEL_INLINE Rgb<F> operator*(F s, const Rgb<F>& c) { return {s * c.r, s * c.g, s * c.b}; }
template <class F>
PB_MODEL_INLINE Rgb<F> operator+(const Rgb<F>& a, const Rgb<F>& b) { return {a.r + b.r, a.g + b.g, a.b + b.b}; }

template <class F>
PB_MODEL_INLINE Vec3<F> select(const MaskOf<F>& m, const Vec3<F>& a, const Vec3<F>& b) {
    return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)};
}

template <class F>
PB_MODEL_INLINE Rgb<F> select(const MaskOf<F>& m, const Rgb<F>& a, const Rgb<F>& b) {
    return {select(m, a.r, b.r), select(m, a.g, b.g), select(m, a.b, b.b)};
}

// x² + y² + z², one rounding per fused step
template <class F>
PB_MODEL_INLINE F squared_length(const Vec3<F>& w) { return mul_add(w.x, w.x, mul_add(w.y, w.y, w.z * w.z)); }

template <class F>
PB_MODEL_INLINE F dot(const Vec3<F>& a, const Vec3<F>& b) { return mul_add(a.x, b.x, mul_add(a.y, b.y, a.z * b.z)); }

// mix(a, b, t) = a (1 - t) + b t: for a, b >= 0 nothing cancels (a + (b - a) t
// loses b's digits when b << a and t -> 1, e.g. Csheen of a saturated color).
template <class F>
PB_MODEL_INLINE F mix(F a, F b, F t) { return mul_add(b, t, a * (F(1.0) - t)); }
template <class F>
PB_MODEL_INLINE Rgb<F> mix(const Rgb<F>& a, const Rgb<F>& b, F t) { return {mix(a.r, b.r, t), mix(a.g, b.g, t), mix(a.b, b.b, t)}; }

// Schlick(u) = clamp(1 - u, 0, 1)^5, given 1 - u
template <class F>
PB_MODEL_INLINE F schlick_weight_of_complement(F one_minus_u) {
    F m = min(max(one_minus_u, F(0.0)), F(1.0));
    F m2 = m * m;
    return m2 * m2 * m;
}

template <class F>
PB_MODEL_INLINE F schlick_weight(F u) { return schlick_weight_of_complement(F(1.0) - u); }

// lum(c) = 0.3 R + 0.6 G + 0.1 B, the shader's luminance (Cdlum)
template <class F>
PB_MODEL_INLINE F luminance_of(const Rgb<F>& c) { return mul_add(F(0.3), c.r, mul_add(F(0.6), c.g, F(0.1) * c.b)); }

// Ctint = base_color / Cdlum, the color's hue and saturation at unit
// luminance; 1 where Cdlum is below float32's smallest normal number 2^-126
// (1/Cdlum would overflow float32 there, and a subnormal color is black to
// any renderer). The float64 instantiation applies the same threshold, so
// the two agree (docs/model.md, "The model").
inline constexpr double kSmallestTintedLuminance = 0x1p-126;

template <class F>
struct Tint {
    Rgb<F> color;             // Ctint
    MaskOf<F> defined;        // Cdlum >= 2^-126
    F inverse_luminance;      // 1/Cdlum where defined, else 1
};

template <class F>
PB_MODEL_INLINE Tint<F> tint_of(const Rgb<F>& base, F luminance) {
    F one(1.0);
    Tint<F> t;
    t.defined = luminance >= F(kSmallestTintedLuminance);
    t.inverse_luminance = reciprocal(select(t.defined, luminance, one));
    t.color = {select(t.defined, base.r * t.inverse_luminance, one), select(t.defined, base.g * t.inverse_luminance, one),
               select(t.defined, base.b * t.inverse_luminance, one)};
    return t;
}

inline constexpr double kInvPi = 0.318309886183790671538;
inline constexpr double kSqrtPi = 1.772453850905516027298;
