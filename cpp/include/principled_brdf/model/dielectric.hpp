// Part of the model (docs/model.md): the geometry and Fresnel factor of a
// smooth or rough dielectric interface, over a number type F. The interface
// lies in the tangent plane with normal n = (0, 0, 1); η is the relative index
// of refraction, the index of the far side over that of the near side.
#pragma once  // once per translation unit: included only by model.hpp, which allows one namespace

// The unpolarised Fresnel reflectance of a dielectric interface (Walter et
// al. 2007 eq. 22 in the amplitude form): light arriving at |cos θi| = c from
// the near side, with cos²θt = 1 - sin²θi / η²,
//   rs = (c - η cos θt) / (c + η cos θt),  rp = (η c - cos θt) / (η c + cos θt),
//   F = (rs² + rp²) / 2,
// and F = 1 under total internal reflection (cos²θt <= 0). cos²θt is formed as
// (c² + (η - 1)(η + 1)) / η², which keeps its digits where 1 - sin²θi/η² would
// cancel (grazing light with η near 1; near the critical angle).
template <class F>
PB_MODEL_INLINE F cos2_theta_transmitted(F c, F eta) {
    return mul_add(c, c, (eta - F(1.0)) * (eta + F(1.0))) / (eta * eta);
}

// Both factors at once from g = η cos θt (the form of Cook and Torrance 1982),
// one square root and one division. With e = (η - 1)(η + 1),
// sin²θi = (1 - c)(1 + c), b = c + g and q = η² c + g:
//   rs = (c - g) / b = -e / b²,   rp = (η² c - g) / q = e (η² c² - sin²θi) / q²,
//   F = (rs² + rp²) / 2,
// and, from 1 - rs² = 4 c g / b² and 1 - rp² = 4 η² c g / q², the transmitted
// fraction without the cancellation of 1 - F where F nears 1 (grazing light,
// the critical angle):
//   T = 2 c g (q² + η² b²) / (b² q²);
// F = 1 and T = 0 under total internal reflection (g² <= 0) and at grazing
// incidence (c = 0, where rs = rp = -1 up to the rounding of g). The differences
// c - g and η² c - g are formed from their products, where they keep their
// digits as η nears 1; g² = c² + e where c < η, else η² - sin²θi (η well below
// 1 near normal incidence): each form rounds the smaller square.
template <class F>
struct FresnelDielectric {
    F reflectance, transmittance;
};

template <class F>
PB_MODEL_INLINE FresnelDielectric<F> fresnel_dielectric_both(F cos_theta_i, F eta) {
    F one(1.0), zero(0.0);
    F c = min(max(cos_theta_i, -cos_theta_i), one);  // |cos θi|
    F eta2 = eta * eta, e = (eta - one) * (eta + one), sin2 = (one - c) * (one + c);
    F g2 = select(c < eta, mul_add(c, c, e), eta2 - sin2);
    MaskOf<F> reflects_all = (g2 <= zero) | (c == zero);
    F g = square_root_nonnegative(g2);
    F b = c + g, q = mul_add(eta2, c, g);
    F b2 = b * b, q2 = q * q;
    F inv_b2_q2 = one / (b2 * q2);
    F rs = -e * q2 * inv_b2_q2;
    F rp = e * mul_sub(eta2 * c, c, sin2) * b2 * inv_b2_q2;
    F reflectance = F(0.5) * mul_add(rs, rs, rp * rp);
    F transmittance = F(2.0) * c * g * mul_add(eta2, b2, q2) * inv_b2_q2;
    return {select(reflects_all, one, reflectance), select(reflects_all, zero, transmittance)};
}

template <class F>
PB_MODEL_INLINE F fresnel_dielectric(F cos_theta_i, F eta) {
    return fresnel_dielectric_both(cos_theta_i, eta).reflectance;
}

template <class F>
PB_MODEL_INLINE F fresnel_dielectric_transmittance(F cos_theta_i, F eta) {
    return fresnel_dielectric_both(cos_theta_i, eta).transmittance;
}

// The direction refracted from w through a surface of unit normal m (Snell's
// law), on the far side: with c = |w·m| and cos θt = sqrt(1 - (1 - c²)/η²),
//   wt = -w / η + (c / η - cos θt) sign(w·m) m;
// zero under total internal reflection (no refracted direction). m is n for
// the interface itself, a microfacet's normal for a rough one.
template <class F>
PB_MODEL_INLINE Vec3<F> refract(const Vec3<F>& w, const Vec3<F>& m, F eta) {
    F one(1.0), zero(0.0);
    F signed_c = dot(w, m);
    F c = min(max(signed_c, -signed_c), one);
    F inv_eta = one / eta;
    F cos2_t = cos2_theta_transmitted(c, eta);
    F normal_part = mul_sub(c, inv_eta, square_root_nonnegative(cos2_t));
    F along = select(signed_c < zero, -normal_part, normal_part);
    Vec3<F> wt{mul_sub(along, m.x, w.x * inv_eta), mul_sub(along, m.y, w.y * inv_eta), mul_sub(along, m.z, w.z * inv_eta)};
    Vec3<F> none{zero, zero, zero};
    return select(cos2_t > zero, wt, none);
}

template <class F>
PB_MODEL_INLINE Vec3<F> refract(const Vec3<F>& w, F eta) {
    return refract(w, Vec3<F>{F(0.0), F(0.0), F(1.0)}, eta);
}

// The generalised half vector of a pair (Walter et al. 2007 eq. 16), each
// direction weighted by the index of its own side: H = wo + η wi with η the
// index on wi's side over that on wo's (1 for reflection, where H = wi + wo),
// unnormalised and turned to the side of n (H·n >= 0). Given η - 1 and formed
// as (wo + wi) + (η - 1) wi: where η nears 1 the light passes nearly straight
// through, wi nears -wo, and wo + wi is exact where wo + η wi would lose the
// digits of its rounded product.
template <class F>
PB_MODEL_INLINE Vec3<F> generalized_half_vector(const Vec3<F>& wi, const Vec3<F>& wo, F eta_minus_one) {
    F k = eta_minus_one;
    Vec3<F> h{mul_add(k, wi.x, wo.x + wi.x), mul_add(k, wi.y, wo.y + wi.y), mul_add(k, wi.z, wo.z + wi.z)};
    MaskOf<F> below = h.z < F(0.0);
    Vec3<F> flipped{-h.x, -h.y, -h.z};
    return select(below, flipped, h);
}
