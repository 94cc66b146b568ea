// Part of the model's double instantiation only (model/f64.hpp includes it
// after model.hpp): what the toolkit (pb.microfacet, microfacet.hpp) offers
// beside the distributions the models use, and no kernel instantiates: the
// height-correlated Smith term of GGX, anisotropic Beckmann and the GTR
// family, and the Jacobian of refraction. They read erfc, log1p, pow and the
// other operations only the double set defines.
#pragma once  // once per translation unit, as model.hpp

// GGX's height-correlated G2 = 1 / (1 + Λ(wi) + Λ(wo)) (Heitz 2014 eq. 99) =
// 2 cos θi cos θo / (cos θi |Vo| + cos θo |Vi|), V the stretched direction
template <class F>
PB_MODEL_INLINE F g2_height_correlated(const Ggx<F>& ggx, const Vec3<F>& wi, const Vec3<F>& wo) {
    F length_i = square_root_nonnegative(ggx.stretched_length2(wi));
    F length_o = square_root_nonnegative(ggx.stretched_length2(wo));
    F denominator = mul_add(wi.z, length_o, wo.z * length_i);
    // a quotient, not a reciprocal: the denominator may be subnormal
    return select(denominator > F(0.0), F(2.0) * wi.z * wo.z / denominator, F(0.0));
}

// Anisotropic Beckmann (Walter et al. 2007), slope density
// P22 = exp(-(x²/ax² + y²/ay²)) / (π ax ay):
//   D(h) = exp(-((h·x/ax)² + (h·y/ay)²) / (h·n)²) / (π ax ay (h·n)⁴),
// with (h·n)⁴ taken into the exponent (one exp: no 0 · inf at the horizon).
// Λ and the draw use erfc and log1p, which only the double operations define:
// no kernel instantiates them.
template <class F>
struct Beckmann {
    F alpha_x, alpha_y;
    F alpha_x2, alpha_y2;          // ax², ay²
    F inv_alpha_x2, inv_alpha_y2;  // 1/ax², 1/ay²
    F norm;                        // 1/(π ax ay)

    static PB_MODEL_INLINE Beckmann from_alphas(F ax, F ay) {
        Beckmann d;
        d.alpha_x = ax;
        d.alpha_y = ay;
        d.alpha_x2 = ax * ax;
        d.alpha_y2 = ay * ay;
        d.inv_alpha_x2 = reciprocal(d.alpha_x2);
        d.inv_alpha_y2 = reciprocal(d.alpha_y2);
        d.norm = F(kInvPi) * reciprocal(ax * ay);
        return d;
    }

    // D(h) for h = H/|H|, h·n > 0; ln cos θh from Hz itself, which stays
    // finite where Hz² underflows (the stretched tan² is then +inf, D 0)
    PB_MODEL_INLINE F d(const HalfVector<F>& h) const {
        F tan2_stretched = mul_add(h.hx2, inv_alpha_x2, h.hy2 * inv_alpha_y2) * reciprocal(h.hz2);
        F log_cos = log(h.hz * reciprocal_sqrt(h.h_len2));
        return norm * exp(neg_mul_add(F(4.0), log_cos, -tan2_stretched));
    }

    // Λ(w), n·w >= 0 (Walter et al. 2007; Heitz 2014 eq. 83):
    //   Λ = (erf(a) - 1)/2 + exp(-a²) / (2 a sqrt(π)),  a = cos θ / sqrt((w·x ax)² + (w·y ay)²),
    // with erf(a) - 1 = -erfc(a); 0 at the normal (p = 0), +inf at grazing
    PB_MODEL_INLINE F lambda(const Vec3<F>& w) const {
        F p2 = mul_add(alpha_x2, w.x * w.x, alpha_y2 * (w.y * w.y));
        F a = w.z * reciprocal_sqrt(p2);
        F value = mul_add(F(-0.5), erfc(a), exp(-a * a) * reciprocal(F(2.0 * kSqrtPi) * a));
        return select(p2 > F(0.0), value, F(0.0));
    }

    PB_MODEL_INLINE F g1(const Vec3<F>& w) const { return reciprocal(F(1.0) + lambda(w)); }

    // D cos θh: the stretched slope radius ρ = sqrt(-ln(1 - u2)) at azimuth φ,
    // d = (ρ ax cos φ, ρ ay sin φ, 1), divided by ρ where ρ > 1 (it is only a
    // direction) and the tangent itself at u2 = 1
    PB_MODEL_INLINE Vec3<F> sample_distribution(F sin_phi, F cos_phi, F u2) const {
        F radius = square_root(-log_one_plus(-u2));
        MaskOf<F> steep = radius > F(1.0);
        F tangent_scale = select(steep, F(1.0), radius);
        F height = select(u2 < F(1.0), select(steep, reciprocal(radius), F(1.0)), F(0.0));
        return {tangent_scale * (alpha_x * cos_phi), tangent_scale * (alpha_y * sin_phi), height};
    }
};

// ln((1 - w) + w e^z) = ln(1 + w (e^z - 1)) for a weight w in [0, 1] given
// with its complement: log1p where w (e^z - 1) is small, else the log of a sum
// of two positive terms (e^z taken out when z > 0), so that it neither
// cancels nor overflows.
template <class F>
PB_MODEL_INLINE F log_mix_exp(F weight, F weight_complement, F z) {
    F y = weight * exp_minus_one(min(z, F(700.0)));
    MaskOf<F> small = (z < F(700.0)) & (y <= F(0.5)) & (y >= F(-0.5));
    F large = select(z > F(0.0), z + log(mul_add(weight_complement, exp(-z), weight)),
                           log(mul_add(weight, exp(min(z, F(0.0))), weight_complement)));
    return select(small, log_one_plus(y), large);
}

// The GTR family (Burley 2012 appendix B eq. 1-3), isotropic, any γ > 0, alpha in (0, 1]:
//   D(h) = c / t^γ,  t = a² cos²θh + sin²θh,  c = (γ - 1)(a² - 1) / (π (1 - (a²)^(1-γ))).
// With L = ln a² and x = (1 - γ) L the normaliser is c = (expm1(L)/L) / (π expm1(x)/x),
// which tends smoothly to GTR1's as γ -> 1 and to 1/π as a -> 1. For x > 0
// the factor e^(-x) = (a²)^(γ-1) moves onto t^-γ, giving (a²/t)^γ / a² with
// a²/t in (0, 1], so nothing overflows for small alpha and large γ.
// The draw (eq. 3) as the pair (cos²θh, sin²θh): with k = 1 - γ,
//   M = ln((1-u) (a²)^k + u) / k,  cos²θh = expm1(M) / expm1(L),
//   q = ln(u (a²)^-k + (1-u)) / k,  sin²θh = e^M expm1(-q) / expm1(L)
// needs no 1 - cos²θh; both logarithms tend to eq. 5's as k -> 0 (M -> (1-u) L,
// q -> -u L). Λ has no closed form for general γ: none is offered.
// Uses pow and log1p, which only the double operations define.
template <class F>
struct Gtr {
    F alpha2, log_alpha2, gamma;
    F k;                 // 1 - γ
    MaskOf<F> ratio_form;  // x > 0: D = norm (a²/t)^γ, else norm t^-γ
    F norm;              // c (a²)^(γ-1) / a² where ratio_form, else c

    static PB_MODEL_INLINE Gtr from(F alpha, F gamma) {
        Gtr d;
        d.alpha2 = alpha * alpha;
        d.log_alpha2 = F(2.0) * log(alpha);
        d.gamma = gamma;
        d.k = F(1.0) - gamma;
        F x = d.k * d.log_alpha2;
        d.ratio_form = x > F(0.0);
        F normaliser_l = exp_minus_one_over_x(d.log_alpha2) * F(kInvPi);
        d.norm = select(d.ratio_form, normaliser_l * reciprocal(exp_minus_one_over_x(-x)) * reciprocal(d.alpha2),
                        normaliser_l * reciprocal(exp_minus_one_over_x(x)));
        return d;
    }

    // D for cos²θh > 0
    PB_MODEL_INLINE F d(F cos2, F sin2) const {
        F t = mul_add(alpha2, cos2, sin2);
        return norm * select(ratio_form, pow(alpha2 * reciprocal(t), gamma), pow(t, -gamma));
    }

    // (cos²θh, sin²θh) of the draw at u2 < 1 (u2 = 1: the horizon, (0, 1))
    PB_MODEL_INLINE std::pair<F, F> draw_cos2_sin2(F u2) const {
        F one(1.0), zero(0.0);
        F u_complement = one - u2;
        MaskOf<F> exponential = k == zero;  // γ = 1: eq. 5
        F safe_k = select(exponential, one, k);
        F m = select(exponential, u_complement * log_alpha2,
                           log_mix_exp(u_complement, u2, k * log_alpha2) * reciprocal(safe_k));
        F q = select(exponential, -u2 * log_alpha2, log_mix_exp(u2, u_complement, -k * log_alpha2) * reciprocal(safe_k));
        F inv_expm1_l = reciprocal(exp_minus_one(log_alpha2));
        F cos2 = exp_minus_one(m) * inv_expm1_l;
        F sin2 = exp(m) * exp_minus_one(-q) * inv_expm1_l;
        MaskOf<F> uniform = log_alpha2 == zero;  // a = 1: cos²θh uniform
        MaskOf<F> horizon = u2 >= one;
        F cos2_drawn = select(horizon, zero, select(uniform, u_complement, min(max(cos2, zero), one)));
        F sin2_drawn = select(horizon, one, select(uniform, u2, min(max(sin2, zero), one)));
        return {cos2_drawn, sin2_drawn};
    }
};

// dωh/dωi of refraction (Walter et al. 2007 eq. 17), h the unit generalised
// half vector and η as for generalized_half_vector:
//   η² |wi·h| / (wo·h + η wi·h)²,
// +inf where the denominator vanishes (wi and wo on one side along h).
template <class F>
PB_MODEL_INLINE F refraction_jacobian(const Vec3<F>& wi, const Vec3<F>& wo, const Vec3<F>& h, F eta) {
    F wi_h = dot(wi, h);
    F denominator = mul_add(eta, wi_h, dot(wo, h));
    return eta * eta * max(wi_h, -wi_h) / (denominator * denominator);
}
