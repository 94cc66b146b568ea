// Part of the model (docs/model.md): the microfacet distributions the
// principled BRDF uses, over a number type F. Both work on the unnormalised
// half vector H = wi + wo through the squares of its components, so that
// cos²θh = Hz²/|H|² and sin²θh = (Hx² + Hy²)/|H|² keep full relative precision
// at narrow peaks, where 1 - cos²θh would cancel.
#pragma once  // once per translation unit: included only by model.hpp, which allows one namespace

// The squares of the half vector's components that the distributions read.
template <class F>
struct HalfVector {
    F hx2, hy2, hz, hz2;
    F h_len2;  // |H|²
};

// Log-derivatives in the two roughnesses as their half-sum and half-difference:
//   sum = ax ∂/∂ax + ay ∂/∂ay (scaling both),  difference = ax ∂/∂ax - ay ∂/∂ay (changing their ratio).
// Roughness scales both alphas and anisotropic changes their ratio, so each
// parameter's derivative is one of the two (unless a clamp holds one alpha):
// taken apart per axis, they cancel to a few digits in float32.
template <class F>
struct LogAlphaPartials {
    F sum, difference;
};

// ∂ln(cos θ + sqrt(q))/∂q = 1 / (2 sqrt(q) (cos θ + sqrt(q))): the log-derivative of a
// Smith denominator in its stretched squared length q
template <class F>
PB_MODEL_INLINE F log_smith_denominator_partial(F cos_theta, F q) {
    F root = square_root_nonnegative(q);
    return reciprocal(F(2.0) * root * (cos_theta + root));
}

// Anisotropic GGX (GTR2, Burley 2012 eq. 13) with Smith masking (Heitz 2014):
//   D(h)  = 1 / (π ax ay ((h·x / ax)² + (h·y / ay)² + (h·n)²)²)
//   G1(w) = 2 n·w / (n·w + sqrt((w·x ax)² + (w·y ay)² + (n·w)²))
// and the density of its visible normals, G1(wo) D(h) / (4 cos θv) in wi.
template <class F>
struct Ggx {
    F alpha_x, alpha_y;
    F alpha_x2, alpha_y2;          // ax², ay²
    F inv_alpha_x2, inv_alpha_y2;  // 1/ax², 1/ay²
    F norm;                        // 1/(π ax ay)

    static PB_MODEL_INLINE Ggx from_alphas(F ax, F ay) {
        Ggx d;
        d.alpha_x = ax;
        d.alpha_y = ay;
        d.alpha_x2 = ax * ax;
        d.alpha_y2 = ay * ay;
        // one division for the three (a per-batch cost for per-element materials):
        // 1/ax² = (ay / (ax ay))², 1/ay² = (ax / (ax ay))²
        F inv_product = reciprocal(ax * ay);
        F inv_alpha_x = ay * inv_product, inv_alpha_y = ax * inv_product;
        d.inv_alpha_x2 = inv_alpha_x * inv_alpha_x;
        d.inv_alpha_y2 = inv_alpha_y * inv_alpha_y;
        d.norm = F(kInvPi) * inv_product;
        return d;
    }

    // D(h), h = H/|H|, read from the unnormalised H: with
    // (h·x / ax)² + (h·y / ay)² + (h·n)² = (Hx²/ax² + Hy²/ay² + Hz²) / |H|²,
    // D = norm (|H|² / (Hx²/ax² + Hy²/ay² + Hz²))². H is never normalised (no
    // square root or division per component), and its squares keep full
    // precision at narrow peaks, where 1 - (h·n)² would cancel.
    PB_MODEL_INLINE F d(const HalfVector<F>& h) const {
        F stretched_h_len2 = mul_add(h.hx2, inv_alpha_x2, mul_add(h.hy2, inv_alpha_y2, h.hz2));  // Hx²/ax² + Hy²/ay² + Hz²
        F inv_stretched_unit = h.h_len2 / stretched_h_len2;  // 1 / ((h·x / ax)² + (h·y / ay)² + (h·n)²)
        return norm * inv_stretched_unit * inv_stretched_unit;
    }

    // (w·x ax)² + (w·y ay)² + (n·w)²: the squared length of w stretched to alpha 1
    PB_MODEL_INLINE F stretched_length2(const Vec3<F>& w) const {
        return mul_add(alpha_x2, w.x * w.x, mul_add(alpha_y2, w.y * w.y, w.z * w.z));
    }

    // n·w + sqrt(stretched_length2(w)) = 2 n·w / G1(w)
    PB_MODEL_INLINE F smith_denominator(const Vec3<F>& w) const {
        return smith_denominator_of(w.z, stretched_length2(w));
    }

    // G1(wo) D(h) / (4 cos θv) = D(h) / (2 smith_denominator(wo))
    PB_MODEL_INLINE F visible_pdf(F d_h, F smith_denominator_wo) const { return d_h / (F(2.0) * smith_denominator_wo); }

    // D(h) cos θh / (4 cos θd) = D(h) Hz / (2 |H|²): the density in wi of h drawn from D cos θh
    PB_MODEL_INLINE F distribution_pdf(F d_h, const HalfVector<F>& h) const { return d_h * h.hz / (F(2.0) * h.h_len2); }

    // cos θ + sqrt(q): the Smith denominator given q (the stretched squared length)
    static PB_MODEL_INLINE F smith_denominator_of(F cos_theta, F q) { return square_root_nonnegative(q) + cos_theta; }

    // log-derivatives of D: with tx = Hx²/ax², ty = Hy²/ay², s = tx + ty + Hz² and
    // D ∝ (|H|²/s)² / (ax ay):  ax ∂ln D/∂ax = 4 tx / s - 1, ay ∂ln D/∂ay = 4 ty / s - 1
    PB_MODEL_INLINE LogAlphaPartials<F> log_d_partials(const HalfVector<F>& h) const {
        F tx = h.hx2 * inv_alpha_x2, ty = h.hy2 * inv_alpha_y2;
        // s as d() forms it, so that the two share one reciprocal
        F inv_s = reciprocal(mul_add(h.hx2, inv_alpha_x2, mul_add(h.hy2, inv_alpha_y2, h.hz2)));
        return {F(2.0) * (tx + ty - h.hz2) * inv_s, F(4.0) * (tx - ty) * inv_s};
    }

    // log-derivatives of smith_denominator(w): ax ∂/∂ax = 2 (w·x ax)² ∂ln/∂q, the same in y
    PB_MODEL_INLINE LogAlphaPartials<F> log_smith_partials(const Vec3<F>& w) const {
        F by_q = F(2.0) * log_smith_denominator_partial(w.z, stretched_length2(w));
        F px = alpha_x2 * (w.x * w.x), py = alpha_y2 * (w.y * w.y);
        return {(px + py) * by_q, (px - py) * by_q};
    }

    // p² = (w·x ax)² + (w·y ay)², the projected roughness times sin θ, squared (Heitz 2014 eq. 80)
    PB_MODEL_INLINE F projected_length2(const Vec3<F>& w) const { return mul_add(alpha_x2, w.x * w.x, alpha_y2 * (w.y * w.y)); }

    // Λ(w), n·w > 0 (Heitz 2014 eq. 72): (-1 + sqrt(1 + p²/cos²θ)) / 2 written as
    // p² / (2 cos θ (cos θ + sqrt(cos²θ + p²))), which does not cancel as p -> 0
    // and is +inf at cos θ = 0, its value there
    PB_MODEL_INLINE F lambda(const Vec3<F>& w) const {
        F p2 = projected_length2(w);
        return p2 / (F(2.0) * w.z * (w.z + square_root_nonnegative(mul_add(w.z, w.z, p2))));
    }

    // G1(w) = 1 / (1 + Λ(w)) = 2 n·w / smith_denominator(w), n·w >= 0
    PB_MODEL_INLINE F g1(const Vec3<F>& w) const { return F(2.0) * w.z / smith_denominator(w); }

    // ---- sampling: each draw gives an unnormalised half vector d (h = d / |d|)
    // from φ = 2π u1 as (sin φ, cos φ) and u2

    // V = (ax w.x, ay w.y, w.z): w in the configuration stretched to alpha 1,
    // where the distribution is the uniform one of unit normals (Heitz 2018)
    PB_MODEL_INLINE Vec3<F> stretch(const Vec3<F>& w) const { return {alpha_x * w.x, alpha_y * w.y, w.z}; }

    // L cos θ = (1 - u2)(L + V.z) - V.z: the height of a point drawn uniformly
    // on the spherical cap of normals visible from V / L (Dupuy & Benyoub 2023),
    // scaled by L = |V| so that V need not be normalised
    static PB_MODEL_INLINE F cap_scaled_cos(F u2, F length, F stretched_z) {
        return mul_sub(F(1.0) - u2, length + stretched_z, stretched_z);
    }

    // visible normals of wo, n·wo > 0: the cap point about V / L, offset by it,
    // scaled by L and unstretched: d = (ax (L sin θ cos φ + V.x), ay (L sin θ sin φ + V.y), L cos θ + V.z)
    PB_MODEL_INLINE Vec3<F> sample_visible(const Vec3<F>& wo, F sin_phi, F cos_phi, F u2) const {
        Vec3<F> v = stretch(wo);
        F length2 = squared_length(v);
        F scaled_cos = cap_scaled_cos(u2, square_root_nonnegative(length2), v.z);
        F scaled_sin = square_root(neg_mul_add(scaled_cos, scaled_cos, length2));
        return {alpha_x * mul_add(scaled_sin, cos_phi, v.x), alpha_y * mul_add(scaled_sin, sin_phi, v.y),
                max(scaled_cos + v.z, F(0.0))};
    }

    // the distribution, D cos θh (Burley 2012 eq. 14-15): d = (ax sqrt(u2) cos φ, ay sqrt(u2) sin φ, sqrt(1 - u2))
    PB_MODEL_INLINE Vec3<F> sample_distribution(F sin_phi, F cos_phi, F u2) const {
        F radius = square_root(u2);
        return {alpha_x * radius * cos_phi, alpha_y * radius * sin_phi, square_root(F(1.0) - u2)};
    }
};

// Isotropic Smith GGX denominator n·w + sqrt(a2 (1 - (n·w)²) + (n·w)²) for
// alpha² = a2 < 1, as a2 + cos²(1 - a2) (both terms >= 0): the clearcoat's.
template <class F>
PB_MODEL_INLINE F smith_denominator_iso_small(F cos_theta, F a2) {
    return Ggx<F>::smith_denominator_of(cos_theta, mul_add(cos_theta * cos_theta, F(1.0) - a2, a2));
}

// The same for any a2 (the 2012 model's alpha_g² reaches 10^15 at roughness
// 10^4), from the components: a2 ((w·x)² + (w·y)²) + (n·w)², where the form
// above cancels to 0.
template <class F>
PB_MODEL_INLINE F smith_denominator_iso(const Vec3<F>& w, F a2) {
    return Ggx<F>::smith_denominator_of(w.z, mul_add(a2, mul_add(w.x, w.x, w.y * w.y), w.z * w.z));
}

// (e^x - 1) / x given e^x - 1, 1 at x = 0
template <class F>
PB_MODEL_INLINE F ratio_exp_minus_one(F x, F exp_minus_one_of_x) {
    MaskOf<F> zero = x == F(0.0);
    return select(zero, F(1.0), exp_minus_one_of_x / select(zero, F(1.0), x));
}

template <class F>
PB_MODEL_INLINE F exp_minus_one_over_x(F x) { return ratio_exp_minus_one(x, exp_minus_one(x)); }

// ∂ln smith_denominator_iso(w, a2)/∂a2 = ((w·x)² + (w·y)²) ∂ln/∂q
template <class F>
PB_MODEL_INLINE F log_smith_denominator_iso_partial(const Vec3<F>& w, F a2) {
    F sin2 = mul_add(w.x, w.x, w.y * w.y);
    return sin2 * log_smith_denominator_partial(w.z, mul_add(a2, sin2, w.z * w.z));
}

// GTR1 (Berry; GTR at γ = 1, Burley 2012 appendix B eq. 4), alpha in (0, 1):
//   D(h) = (a² - 1) / (π ln a² (a² cos²θh + sin²θh))
// drawn by eq. 5 as sin²θh = a² (a^(-2 u) - 1) / (1 - a²), cos²θh = (1 - a^(2 (1 - u))) / (1 - a²).
// Near a = 1, a² - 1 is taken as e^L - 1 with L = ln a², which keeps its
// digits; D's normaliser is 1/π at a = 1, the draw needs a < 1.
template <class F>
struct Gtr1 {
    F alpha2;                // a²
    F log_alpha2;            // L = ln a²
    F inv_one_minus_alpha2;  // 1 / (1 - a²) = -1 / (e^L - 1)
    F norm;                  // (a² - 1) / (π ln a²)
    F sin2_scale;            // a² / (1 - a²)

    static PB_MODEL_INLINE Gtr1 from_alpha(F alpha) {
        Gtr1 d;
        d.alpha2 = alpha * alpha;
        d.log_alpha2 = log(d.alpha2);
        // a² - 1 itself keeps its digits while a² is small (the clearcoat's a <= 0.1, so
        // the kernels never take e^L - 1); e^L - 1 keeps them as a -> 1
        F alpha2_minus_1 = all(d.alpha2 <= F(0.25)) ? d.alpha2 - F(1.0) : exp_minus_one(d.log_alpha2);
        d.inv_one_minus_alpha2 = -reciprocal(alpha2_minus_1);
        d.norm = F(kInvPi) * ratio_exp_minus_one(d.log_alpha2, alpha2_minus_1);
        d.sin2_scale = d.alpha2 * d.inv_one_minus_alpha2;
        return d;
    }

    // |H|² (a² cos²θh + sin²θh) = a² Hz² + Hx² + Hy²: D(h) is norm |H|² over this
    PB_MODEL_INLINE F denominator(const HalfVector<F>& h) const { return mul_add(alpha2, h.hz2, h.hx2 + h.hy2); }

    PB_MODEL_INLINE F d(const HalfVector<F>& h) const { return norm * h.h_len2 / denominator(h); }

    // D(h) cos θh / (4 cos θd) = norm Hz / (2 denominator), the density in wi
    PB_MODEL_INLINE F pdf(const HalfVector<F>& h) const { return norm * h.hz / (F(2.0) * denominator(h)); }

    // ∂ln D/∂a² = 1/(a² - 1) - 1/(a² ln a²) - Hz² / denominator
    PB_MODEL_INLINE F log_d_partial_alpha2(const HalfVector<F>& h) const {
        F log_norm = -inv_one_minus_alpha2 - reciprocal(alpha2 * log_alpha2);
        return neg_mul_add(h.hz2, reciprocal(denominator(h)), log_norm);
    }

    // sin²θh of the draw at u (eq. 5, through e^x - 1 with x = -u ln a² in [0, -L])
    PB_MODEL_INLINE F draw_sin2(F u) const { return min(sin2_scale * exp_minus_one(-u * log_alpha2), F(1.0)); }

    // cos²θh of the same draw, without 1 - sin²θh: -(e^((1-u) L) - 1) / (1 - a²)
    PB_MODEL_INLINE F draw_cos2(F u) const {
        return min(-exp_minus_one((F(1.0) - u) * log_alpha2) * inv_one_minus_alpha2, F(1.0));
    }
};
