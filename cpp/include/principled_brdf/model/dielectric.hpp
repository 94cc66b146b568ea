// Part of the model (docs/model.md): the geometry and Fresnel factor of a
// smooth or rough dielectric interface, over a number type F. The interface
// lies in the tangent plane with normal n = (0, 0, 1); η is the relative index
// of refraction, the index of the far side over that of the near side.
#pragma once  // once per translation unit: included only by model.hpp, which allows one namespace

// The unpolarised Fresnel reflectance of a dielectric interface (Walter et
// al. 2007 eq. 22 in the amplitude form): light arriving at |cos θi| from the
// near side, with cos²θt = 1 - sin²θi / η²,
//   rs = (cos θi - η cos θt) / (cos θi + η cos θt),  rp = (η cos θi - cos θt) / (η cos θi + cos θt),
//   F = (rs² + rp²) / 2,
// and F = 1 under total internal reflection (cos²θt <= 0). cos²θt is formed as
// (c² + (η - 1)(η + 1)) / η², which keeps its digits where 1 - sin²θi/η² would
// cancel (grazing light with η near 1; near the critical angle).
template <class F>
PB_MODEL_INLINE F cos2_theta_transmitted(F c, F eta) {
    return mul_add(c, c, (eta - F(1.0)) * (eta + F(1.0))) / (eta * eta);
}

template <class F>
PB_MODEL_INLINE F fresnel_dielectric(F cos_theta_i, F eta) {
    F one(1.0);
    F c = min(max(cos_theta_i, -cos_theta_i), one);  // |cos θi|
    F cos2_t = cos2_theta_transmitted(c, eta);
    MaskOf<F> total_internal_reflection = cos2_t <= F(0.0);
    F cos_t = square_root(cos2_t);
    F eta_cos_t = eta * cos_t, eta_cos_i = eta * c;
    F rs = (c - eta_cos_t) / (c + eta_cos_t);
    F rp = (eta_cos_i - cos_t) / (eta_cos_i + cos_t);
    return select(total_internal_reflection, one, F(0.5) * mul_add(rs, rs, rp * rp));
}

// Its complement, the transmitted fraction 1 - F, without the cancellation of
// 1 - F where F nears 1 (grazing light, the critical angle): with
// 1 - rs² = 4 c η cos θt / (c + η cos θt)² and 1 - rp² = 4 η c cos θt / (η c + cos θt)²,
//   1 - F = 2 η c cos θt (1 / (c + η cos θt)² + 1 / (η c + cos θt)²),
// 0 under total internal reflection.
template <class F>
PB_MODEL_INLINE F fresnel_dielectric_transmittance(F cos_theta_i, F eta) {
    F c = min(max(cos_theta_i, -cos_theta_i), F(1.0));
    F cos2_t = cos2_theta_transmitted(c, eta);
    F cos_t = square_root_nonnegative(cos2_t);
    F s = c + eta * cos_t, p = mul_add(eta, c, cos_t);
    F t = F(2.0) * eta * c * cos_t * (F(1.0) / (s * s) + F(1.0) / (p * p));
    return select(cos2_t <= F(0.0), F(0.0), t);
}

// The direction refracted from w through the interface (Snell's law), on the
// far side: with c = |cos θ| and cos θt = sqrt(1 - (1 - c²)/η²),
//   wt = -w / η + (c / η - cos θt) sign(w·n) n.
// Zero under total internal reflection (no refracted direction).
template <class F>
PB_MODEL_INLINE Vec3<F> refract(const Vec3<F>& w, F eta) {
    F one(1.0), zero(0.0);
    F c = min(max(w.z, -w.z), one);
    F inv_eta = one / eta;
    F cos2_t = cos2_theta_transmitted(c, eta);
    MaskOf<F> transmits = cos2_t > zero;
    F cos_t = square_root(cos2_t);
    F normal_part = mul_sub(c, inv_eta, cos_t);
    F z = select(w.z < zero, -normal_part, normal_part) - w.z * inv_eta;
    Vec3<F> wt{-w.x * inv_eta, -w.y * inv_eta, z};
    Vec3<F> none{zero, zero, zero};
    return select(transmits, wt, none);
}

// The generalised half vector of a pair (Walter et al. 2007 eq. 16), each
// direction weighted by the index of its own side: H = wo + η wi with η the
// index on wi's side over that on wo's (1 for reflection, where H = wi + wo),
// unnormalised and turned to the side of n (H·n >= 0).
template <class F>
PB_MODEL_INLINE Vec3<F> generalized_half_vector(const Vec3<F>& wi, const Vec3<F>& wo, F eta) {
    Vec3<F> h{mul_add(eta, wi.x, wo.x), mul_add(eta, wi.y, wo.y), mul_add(eta, wi.z, wo.z)};
    MaskOf<F> below = h.z < F(0.0);
    Vec3<F> flipped{-h.x, -h.y, -h.z};
    return select(below, flipped, h);
}

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
