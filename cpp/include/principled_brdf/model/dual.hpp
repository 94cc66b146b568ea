// Part of the model (docs/model.md): a forward-mode number over a number type
// F, its value and N tangents, with the operations the model's parts use on F
// (model/scalar_ops.hpp for double, the kernels' for their batches). The model
// instantiated for Dual<F, N> computes f together with N directional
// derivatives (docs/gradients.md, "Derivatives in the directions"); the value
// is computed by the same operations of F as the model's own, so it has the
// same bits.
//
// Comparisons give F's masks, of the values: a select or a clamp picks a
// branch and its tangents with it (the derivative of the active branch).
// Included after the model, inside the same namespace (argument-dependent
// lookup finds these overloads from the model's templates).
#pragma once  // once per translation unit: included only by model.hpp, which allows one namespace

template <class F, int N>
struct Dual {
    F v;
    F d[N];

    Dual() = default;
    // a constant: its tangents 0
    Dual(F value) : v(value) {
        for (int k = 0; k < N; ++k) d[k] = F(0.0);
    }
    Dual(double value) : Dual(F(value)) {}

    // the k-th of N independent variables
    static PB_MODEL_INLINE Dual variable(F value, int k) {
        Dual x(value);
        x.d[k] = F(1.0);
        return x;
    }
};

// Dual(double) and Dual(F) are one constructor for F = double
template <int N>
struct Dual<double, N> {
    double v;
    double d[N];

    Dual() = default;
    Dual(double value) : v(value) {
        for (int k = 0; k < N; ++k) d[k] = 0.0;
    }

    static PB_MODEL_INLINE Dual variable(double value, int k) {
        Dual x(value);
        x.d[k] = 1.0;
        return x;
    }
};

// its value, without the tangents (a table's node is found from it, model/dielectric_energy.hpp)
template <class F, int N>
PB_MODEL_INLINE F real_part(const Dual<F, N>& x) {
    return x.v;
}

// The same tangent map applied to each of x's tangents.
template <class F, int N, class Tangent>
PB_MODEL_INLINE Dual<F, N> with_tangents(F value, Tangent tangent) {
    Dual<F, N> r;
    r.v = value;
    for (int k = 0; k < N; ++k) r.d[k] = tangent(k);
    return r;
}

template <class F, int N>
PB_MODEL_INLINE Dual<F, N> operator+(const Dual<F, N>& a, const Dual<F, N>& b) {
    return with_tangents<F, N>(a.v + b.v, [&](int k) { return a.d[k] + b.d[k]; });
}
template <class F, int N>
PB_MODEL_INLINE Dual<F, N> operator-(const Dual<F, N>& a, const Dual<F, N>& b) {
    return with_tangents<F, N>(a.v - b.v, [&](int k) { return a.d[k] - b.d[k]; });
}
template <class F, int N>
PB_MODEL_INLINE Dual<F, N> operator-(const Dual<F, N>& a) {
    return with_tangents<F, N>(-a.v, [&](int k) { return -a.d[k]; });
}
template <class F, int N>
PB_MODEL_INLINE Dual<F, N> operator*(const Dual<F, N>& a, const Dual<F, N>& b) {
    return with_tangents<F, N>(a.v * b.v, [&](int k) { return mul_add(a.d[k], b.v, a.v * b.d[k]); });
}
// (a' - (a/b) b') / b
template <class F, int N>
PB_MODEL_INLINE Dual<F, N> operator/(const Dual<F, N>& a, const Dual<F, N>& b) {
    F q = a.v / b.v;
    F inv = reciprocal(b.v);
    return with_tangents<F, N>(q, [&](int k) { return neg_mul_add(q, b.d[k], a.d[k]) * inv; });
}

template <class F, int N>
PB_MODEL_INLINE Dual<F, N> mul_add(const Dual<F, N>& a, const Dual<F, N>& b, const Dual<F, N>& c) {
    return with_tangents<F, N>(mul_add(a.v, b.v, c.v), [&](int k) { return mul_add(a.d[k], b.v, mul_add(a.v, b.d[k], c.d[k])); });
}
template <class F, int N>
PB_MODEL_INLINE Dual<F, N> mul_sub(const Dual<F, N>& a, const Dual<F, N>& b, const Dual<F, N>& c) {
    return with_tangents<F, N>(mul_sub(a.v, b.v, c.v), [&](int k) { return mul_add(a.d[k], b.v, mul_sub(a.v, b.d[k], c.d[k])); });
}
template <class F, int N>
PB_MODEL_INLINE Dual<F, N> neg_mul_add(const Dual<F, N>& a, const Dual<F, N>& b, const Dual<F, N>& c) {
    return with_tangents<F, N>(neg_mul_add(a.v, b.v, c.v),
                               [&](int k) { return neg_mul_add(a.d[k], b.v, neg_mul_add(a.v, b.d[k], c.d[k])); });
}

// (1/x)' = -x' / x²
template <class F, int N>
PB_MODEL_INLINE Dual<F, N> reciprocal(const Dual<F, N>& x) {
    F r = reciprocal(x.v);
    F minus_r2 = -(r * r);
    return with_tangents<F, N>(r, [&](int k) { return minus_r2 * x.d[k]; });
}
// (x^-1/2)' = -x' / (2 x^3/2)
template <class F, int N>
PB_MODEL_INLINE Dual<F, N> reciprocal_sqrt(const Dual<F, N>& x) {
    F r = reciprocal_sqrt(x.v);
    F slope = F(-0.5) * r * r * r;
    return with_tangents<F, N>(r, [&](int k) { return slope * x.d[k]; });
}
// (√x)' = x' / (2 √x); x = 0 gives infinite or NaN tangents, which the model's
// callers select away (the half vector of wi = -wo, below the surface)
template <class F, int N>
PB_MODEL_INLINE Dual<F, N> square_root_nonnegative(const Dual<F, N>& x) {
    F root = square_root_nonnegative(x.v);
    F slope = F(0.5) / root;
    return with_tangents<F, N>(root, [&](int k) { return slope * x.d[k]; });
}
// √max(x, 0): tangents 0 where x <= 0
template <class F, int N>
PB_MODEL_INLINE Dual<F, N> square_root(const Dual<F, N>& x) {
    F root = square_root(x.v);
    auto positive = x.v > F(0.0);
    F slope = select(positive, F(0.5) / select(positive, root, F(1.0)), F(0.0));
    return with_tangents<F, N>(root, [&](int k) { return slope * x.d[k]; });
}
template <class F, int N>
PB_MODEL_INLINE Dual<F, N> log(const Dual<F, N>& x) {
    F inv = reciprocal(x.v);
    return with_tangents<F, N>(log(x.v), [&](int k) { return x.d[k] * inv; });
}
template <class F, int N>
PB_MODEL_INLINE Dual<F, N> exp(const Dual<F, N>& x) {
    F e = exp(x.v);
    return with_tangents<F, N>(e, [&](int k) { return e * x.d[k]; });
}
template <class F, int N>
PB_MODEL_INLINE Dual<F, N> exp_minus_one(const Dual<F, N>& x) {
    F e = exp(x.v);
    return with_tangents<F, N>(exp_minus_one(x.v), [&](int k) { return e * x.d[k]; });
}

template <class F, int N>
PB_MODEL_INLINE Dual<F, N> select(const MaskOf<F>& m, const Dual<F, N>& a, const Dual<F, N>& b) {
    return with_tangents<F, N>(select(m, a.v, b.v), [&](int k) { return select(m, a.d[k], b.d[k]); });
}
// as F's min and max: the second operand where either value is NaN
template <class F, int N>
PB_MODEL_INLINE Dual<F, N> min(const Dual<F, N>& a, const Dual<F, N>& b) {
    auto first = a.v < b.v;
    return with_tangents<F, N>(min(a.v, b.v), [&](int k) { return select(first, a.d[k], b.d[k]); });
}
template <class F, int N>
PB_MODEL_INLINE Dual<F, N> max(const Dual<F, N>& a, const Dual<F, N>& b) {
    auto first = a.v > b.v;
    return with_tangents<F, N>(max(a.v, b.v), [&](int k) { return select(first, a.d[k], b.d[k]); });
}

template <class F, int N>
PB_MODEL_INLINE auto operator<(const Dual<F, N>& a, const Dual<F, N>& b) { return a.v < b.v; }
template <class F, int N>
PB_MODEL_INLINE auto operator<=(const Dual<F, N>& a, const Dual<F, N>& b) { return a.v <= b.v; }
template <class F, int N>
PB_MODEL_INLINE auto operator>(const Dual<F, N>& a, const Dual<F, N>& b) { return a.v > b.v; }
template <class F, int N>
PB_MODEL_INLINE auto operator>=(const Dual<F, N>& a, const Dual<F, N>& b) { return a.v >= b.v; }
template <class F, int N>
PB_MODEL_INLINE auto operator==(const Dual<F, N>& a, const Dual<F, N>& b) { return a.v == b.v; }
template <class F, int N>
PB_MODEL_INLINE auto operator!=(const Dual<F, N>& a, const Dual<F, N>& b) { return a.v != b.v; }

// A term skipped where its weight is 0 in every lane has a derivative where the
// weight's tangents are not 0 (the one-sided derivative at a parameter's bound,
// e.g. clearcoat 0): the test counts them.
template <class F, int N>
PB_MODEL_INLINE bool nonzero_anywhere(const Dual<F, N>& x) {
    bool nonzero = nonzero_anywhere(x.v);
    for (int k = 0; k < N; ++k) nonzero = nonzero || nonzero_anywhere(x.d[k]);
    return nonzero;
}
