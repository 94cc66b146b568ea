// Part of the model (docs/model.md): the microfacet distributions the
// principled BRDF uses, over a number type F. Both work on the unnormalised
// half vector H = wi + wo through the squares of its components, so that
// cos²θh = Hz²/|H|² and sin²θh = (Hx² + Hy²)/|H|² keep full relative precision
// at narrow peaks, where 1 - cos²θh would cancel.
#pragma once  // (per namespace that includes the model)

// The squares of the half vector's components that the distributions read.
template <class F>
struct HalfVector {
    F hx2, hy2, hz, hz2;
    F h_len2;  // |H|²
};

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
        d.inv_alpha_x2 = reciprocal(d.alpha_x2);
        d.inv_alpha_y2 = reciprocal(d.alpha_y2);
        d.norm = F(kInvPi) * reciprocal(ax * ay);
        return d;
    }

    // D(h), h = H/|H|: norm |H|⁴ / (Hx²/ax² + Hy²/ay² + Hz²)²
    PB_MODEL_INLINE F d(const HalfVector<F>& h) const {
        const F stretched = mul_add(h.hx2, inv_alpha_x2, mul_add(h.hy2, inv_alpha_y2, h.hz2));
        const F root = h.h_len2 * reciprocal(stretched);
        return norm * root * root;
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
    PB_MODEL_INLINE F visible_pdf(F d_h, F smith_denominator_wo) const { return d_h * reciprocal(F(2.0) * smith_denominator_wo); }

    // D(h) cos θh / (4 cos θd) = D(h) Hz / (2 |H|²): the density in wi of h drawn from D cos θh
    PB_MODEL_INLINE F distribution_pdf(F d_h, const HalfVector<F>& h) const { return d_h * h.hz * reciprocal(F(2.0) * h.h_len2); }

    // cos θ + sqrt(q): the Smith denominator given q (the stretched squared length)
    static PB_MODEL_INLINE F smith_denominator_of(F cos_theta, F q) { return mul_add(q, reciprocal_sqrt(q), cos_theta); }
};

// Anisotropic Beckmann (Walter et al. 2007), slope density
// P22 = exp(-(x²/ax² + y²/ay²)) / (π ax ay):
//   D(h) = exp(-((h·x/ax)² + (h·y/ay)²) / (h·n)²) / (π ax ay (h·n)⁴),
// with (h·n)⁴ taken into the exponent (one exp: no 0 · inf at the horizon).
template <class F>
struct Beckmann {
    F inv_alpha_x2, inv_alpha_y2;  // 1/ax², 1/ay²
    F norm;                        // 1/(π ax ay)

    static PB_MODEL_INLINE Beckmann from_alphas(F ax, F ay) {
        Beckmann d;
        d.inv_alpha_x2 = reciprocal(ax * ax);
        d.inv_alpha_y2 = reciprocal(ay * ay);
        d.norm = F(kInvPi) * reciprocal(ax * ay);
        return d;
    }

    // D(h) for h = H/|H|, h·n > 0; ln cos θh from Hz itself, which stays
    // finite where Hz² underflows (the stretched tan² is then +inf, D 0)
    PB_MODEL_INLINE F d(const HalfVector<F>& h) const {
        const F tan2_stretched = mul_add(h.hx2, inv_alpha_x2, h.hy2 * inv_alpha_y2) * reciprocal(h.hz2);
        const F log_cos = log(h.hz * reciprocal_sqrt(h.h_len2));
        return norm * exp(neg_mul_add(F(4.0), log_cos, -tan2_stretched));
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

// GTR1 (Berry; GTR at γ = 1, Burley 2012 appendix B eq. 4), alpha < 1:
//   D(h) = (a² - 1) / (π ln a² (a² cos²θh + sin²θh))
// drawn by eq. 5 as sin²θh = a² (a^(-2 u) - 1) / (1 - a²).
template <class F>
struct Gtr1 {
    F alpha2;      // a²
    F log_alpha2;  // ln a²
    F norm;        // (a² - 1) / (π ln a²)
    F sin2_scale;  // a² / (1 - a²)

    static PB_MODEL_INLINE Gtr1 from_alpha(F alpha) {
        Gtr1 d;
        d.alpha2 = alpha * alpha;
        d.log_alpha2 = log(d.alpha2);
        d.norm = F(kInvPi) * (d.alpha2 - F(1.0)) * reciprocal(d.log_alpha2);
        d.sin2_scale = d.alpha2 * reciprocal(F(1.0) - d.alpha2);
        return d;
    }

    // |H|² (a² cos²θh + sin²θh) = a² Hz² + Hx² + Hy²: D(h) is norm |H|² over this
    PB_MODEL_INLINE F denominator(const HalfVector<F>& h) const { return mul_add(alpha2, h.hz2, h.hx2 + h.hy2); }

    // D(h) cos θh / (4 cos θd) = norm Hz / (2 denominator), the density in wi
    PB_MODEL_INLINE F pdf(const HalfVector<F>& h) const { return norm * h.hz * reciprocal(F(2.0) * denominator(h)); }

    // sin²θh of the draw at u (eq. 5, through e^x - 1 with x = -u ln a² in [0, 14])
    PB_MODEL_INLINE F draw_sin2(F u) const { return min(sin2_scale * exp_minus_one(-u * log_alpha2), F(1.0)); }
};
