// Part of the model layer (docs/model.md "The microfacet family"): the
// shape-invariant distributions beyond GGX and Beckmann, over a number type F,
// each anisotropic by stretching (Heitz 2014 §5.1): with stretched slopes
// (x/ax, y/ay) of radius r the slope density is f(r) / (ax ay), so
//   D(h) = f(r) / (ax ay cos⁴θh),  r² = ((h·x/ax)² + (h·y/ay)²) / (h·n)²,
// and Λ depends on w only through a = cos θ / sqrt((w·x ax)² + (w·y ay)²).
// Blinn-Phong is the exception: not shape-invariant, it is parameterised by
// Beckmann's alphas and borrows Beckmann's Λ (Walter et al. 2007 §5.2).
// Λ and the exponential-power draw are double-only operations
// (student_t_lambda_of, exponential_power_lambda_of, inverse_regularized_gamma_of,
// log_gamma), like Beckmann's erfc: no kernel instantiates these types.
// Included, inside a namespace that defines the model's operations, after
// distributions.hpp (model/f64_family.hpp does so for double).
// Once a translation unit, like the model (model.hpp says why): a second
// inclusion, under any namespace, is a compile error.
#ifdef PRINCIPLED_BRDF_DISTRIBUTION_FAMILY_INCLUDED
#error "principled_brdf: model/distribution_family.hpp is already included in this translation unit (include model/f64_family.hpp instead)"
#endif
#define PRINCIPLED_BRDF_DISTRIBUTION_FAMILY_INCLUDED

// The stretch shared by the family: the per-direction a, the stretched tan²θh of a half vector.
template <class F>
struct Stretch {
    F alpha_x, alpha_y, inv_alpha_x2, inv_alpha_y2;

    static PB_MODEL_INLINE Stretch from_alphas(F ax, F ay) {
        return {ax, ay, reciprocal(ax * ax), reciprocal(ay * ay)};
    }

    // r² = ((h·x/ax)² + (h·y/ay)²) / (h·n)²
    PB_MODEL_INLINE F tan2(const HalfVector<F>& h) const {
        return mul_add(h.hx2, inv_alpha_x2, h.hy2 * inv_alpha_y2) * reciprocal(h.hz2);
    }

    // ln cos⁴θh, from Hz itself (finite where Hz² underflows)
    PB_MODEL_INLINE F log_cos4(const HalfVector<F>& h) const { return F(4.0) * log(h.hz * reciprocal_sqrt(h.h_len2)); }

    // a = n·w / sqrt((w·x ax)² + (w·y ay)²) (Heitz 2014 eq. 80 gives the projected roughness), n·w >= 0; +inf at the normal
    PB_MODEL_INLINE F cot_projected(const Vec3<F>& w) const {
        F p2 = mul_add(alpha_x * alpha_x, w.x * w.x, (alpha_y * alpha_y) * (w.y * w.y));
        return w.z * reciprocal_sqrt(p2);
    }

    // the unnormalised half vector of stretched slope radius ρ at azimuth φ, ρ = +inf the horizon
    PB_MODEL_INLINE Vec3<F> slope_direction(F sin_phi, F cos_phi, F radius) const {
        MaskOf<F> steep = radius > F(1.0);
        F scale = select(steep, F(1.0), radius);
        F height = select(steep, reciprocal(radius), F(1.0));
        return {scale * (alpha_x * cos_phi), scale * (alpha_y * sin_phi), height};
    }
};

// Walter et al. 2007 eq. 27's rational fit of Beckmann's G1, written as Λ
// (G1 = 1/(1 + Λ)): Λ ≈ (1 - 1.259 a + 0.396 a²) / (3.535 a + 2.181 a²)
// for a < 1.6, else 0.
template <class F>
PB_MODEL_INLINE F beckmann_lambda_walter(F a) {
    F value = mul_add(a, mul_add(F(0.396), a, F(-1.259)), F(1.0)) * reciprocal(a * mul_add(F(2.181), a, F(3.535)));
    return select(a < F(1.6), value, F(0.0));
}

// Student-t slopes (Ribardière et al. 2017), shape γ > 3/2, ν = γ - 1:
//   f(r) = (1 + r²/ν)^-γ / π,
// so that γ = 2 is GGX and γ -> ∞ Beckmann ((1 + r²/ν)^-γ -> exp(-r²)).
template <class F>
struct StudentT {
    Stretch<F> stretch;
    F gamma, nu;
    F log_norm;  // ln(1/(π ax ay))

    static PB_MODEL_INLINE StudentT from(F ax, F ay, F gamma) {
        return {Stretch<F>::from_alphas(ax, ay), gamma, gamma - F(1.0), log(F(kInvPi) * reciprocal(ax * ay))};
    }

    // D = exp(ln norm - γ ln(1 + r²/ν) - ln cos⁴θh)
    PB_MODEL_INLINE F d(const HalfVector<F>& h) const {
        return exp(log_norm - gamma * log_one_plus(stretch.tan2(h) * reciprocal(nu)) - stretch.log_cos4(h));
    }

    PB_MODEL_INLINE F lambda(const Vec3<F>& w) const { return student_t_lambda_of(nu, stretch.cot_projected(w)); }

    // D cos θh: P(ρ <= r) = 1 - (1 + r²/ν)^(1-γ), inverted in closed form,
    // ρ² = ν expm1(-ln(1 - u2) / ν)
    PB_MODEL_INLINE Vec3<F> sample_distribution(F sin_phi, F cos_phi, F u2) const {
        F radius2 = nu * exp_minus_one(-log_one_plus(-u2) * reciprocal(nu));
        return stretch.slope_direction(sin_phi, cos_phi, square_root(radius2));
    }
};

// Exponential-power slopes (Holzschuch & Pacanowski 2017), shape p > 0:
//   f(r) = p exp(-r^(2p)) / (π Γ(1/p)),
// p = 1 is Beckmann. ρ^(2p) of a draw is Gamma(1/p)-distributed.
template <class F>
struct ExponentialPower {
    Stretch<F> stretch;
    F p;
    F log_norm;  // ln(p / (π Γ(1/p) ax ay))

    static PB_MODEL_INLINE ExponentialPower from(F ax, F ay, F p) {
        return {Stretch<F>::from_alphas(ax, ay), p, log(p * F(kInvPi) * reciprocal(ax * ay)) - log_gamma(reciprocal(p))};
    }

    PB_MODEL_INLINE F d(const HalfVector<F>& h) const {
        return exp(log_norm - pow(stretch.tan2(h), p) - stretch.log_cos4(h));
    }

    PB_MODEL_INLINE F lambda(const Vec3<F>& w) const { return exponential_power_lambda_of(p, stretch.cot_projected(w)); }

    // D cos θh: ρ^(2p) = P^-1(1/p, u2), the inverse regularised incomplete gamma function
    PB_MODEL_INLINE Vec3<F> sample_distribution(F sin_phi, F cos_phi, F u2) const {
        F s = reciprocal(p);
        F radius = pow(inverse_regularized_gamma_of(s, u2, F(1.0) - u2), F(0.5) * s);
        return stretch.slope_direction(sin_phi, cos_phi, radius);
    }
};

// Blinn-Phong (Blinn 1977) with Walter et al. 2007's exponent α_p = 2/α² - 2 (Walter §5.2), made anisotropic as Ashikhmin & Shirley 2000 do:
//   D = cos^e θh / (π ax ay),  e = ex cos²φh + ey sin²φh,  ex = 2/ax² - 2, ey = 2/ay² - 2,
// exactly normalised for every (ax, ay) in (0, 1] ((e + 2)/(2π) = 1/(π α²) isotropically).
// Its Λ is Beckmann's at the same alphas (an approximation: Blinn-Phong is not shape-invariant).
template <class F>
struct BlinnPhong {
    F exponent_x, exponent_y;  // ex, ey
    F norm;                    // 1/(π ax ay)
    Beckmann<F> beckmann;

    static PB_MODEL_INLINE BlinnPhong from_alphas(F ax, F ay) {
        return {F(2.0) * reciprocal(ax * ax) - F(2.0), F(2.0) * reciprocal(ay * ay) - F(2.0),
                F(kInvPi) * reciprocal(ax * ay), Beckmann<F>::from_alphas(ax, ay)};
    }

    // cos^e θh = exp(-e ln(1 + tan²θh) / 2), e from the squares of the half vector
    PB_MODEL_INLINE F d(const HalfVector<F>& h) const {
        F sin2 = h.hx2 + h.hy2;
        MaskOf<F> off_normal = sin2 > F(0.0);
        F e = mul_add(exponent_x, h.hx2, exponent_y * h.hy2) * reciprocal(select(off_normal, sin2, F(1.0)));
        F log_cos = F(-0.5) * log_one_plus(sin2 * reciprocal(h.hz2));
        // e = 0 (alpha 1) is cos⁰ = 1 even where ln cos θh = -inf
        return norm * exp(select(off_normal & (e > F(0.0)), e * log_cos, F(0.0)));
    }

    PB_MODEL_INLINE F lambda(const Vec3<F>& w) const { return beckmann.lambda(w); }

    // D cos θh (Ashikhmin & Shirley 2000): the azimuth of (ax cos 2πu1, ay sin 2πu1),
    // then cos θh = u2^(1/(e + 2)), sin²θh = -expm1(2 ln u2 / (e + 2))
    PB_MODEL_INLINE Vec3<F> sample_distribution(F sin_phi, F cos_phi, F u2) const {
        F x = beckmann.alpha_x * cos_phi, y = beckmann.alpha_y * sin_phi;
        F length2 = mul_add(x, x, y * y);
        F inv_length = reciprocal_sqrt(length2);
        F e = mul_add(exponent_x, x * x, exponent_y * (y * y)) * reciprocal(length2);
        F log_cos = log(u2) * reciprocal(e + F(2.0));
        F sin_theta = square_root(-exp_minus_one(F(2.0) * log_cos));
        return {sin_theta * x * inv_length, sin_theta * y * inv_length, exp(log_cos)};
    }
};
