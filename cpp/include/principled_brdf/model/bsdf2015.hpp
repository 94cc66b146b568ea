// Part of the model (docs/model-2015.md): the 2015 BSDF of a solid over a
// number type F, over the whole sphere: the 2014 lobes outside with the exact
// dielectric Fresnel factor, and a rough dielectric interface (Walter et al.
// 2007) that reflects and transmits from either side.
//
// Sides. Every function takes the pair as the viewer sees it: when wo lies
// below the tangent plane (wo.z < 0) both directions are mirrored through it
// first (Side), so that the viewer is above and the light above (reflection)
// or below (transmission); η_t is then the light side's index over the
// viewer's, η outside and 1/η inside.
//
// The thin sheet (disney2015_thin, Burley 2015) shares the solid's lobes
// above the sheet and replaces the refraction: both interfaces lie at one
// point, so light passes without bending, through a microfacet lobe mirrored
// below the sheet (roughness r_t) and a diffuse one; the sheet has no inside,
// both of its faces see the lobes outside.
#pragma once  // once per translation unit: included only by model.hpp, which allows one namespace

// η - 1 from specular: ((η - 1)/(η + 1))² = 0.08 specular gives
// η = 2 / (1 - r) - 1, r = sqrt(0.08 specular), so η - 1 = 2 r / (1 - r),
// at least 0.001 (the callers keep specular below 12.5, where η is finite).
// Kept apart from η: near 1 it carries the digits the half vector needs.
template <class F>
PB_MODEL_INLINE F eta_minus_one_of_specular(F specular) {
    F root = square_root(F(0.08) * specular);
    return max(F(2.0) * root / (F(1.0) - root), F(0.001));
}

// Everything the 2015 solid needs of a material, independent of the directions.
template <class F>
struct Shading2015 {
    // the 2014 lobes' constants, the diffuse and sheen colors and the cosine
    // lobe's weight times w_D = (1 - metallic)(1 - spec_trans)
    Shading<F> brdf;
    F flatness;
    // the specular's Fresnel factor F_s = dielectric F_D(cos θd; η) + schlick_f0 (1 - FH) + schlick_grazing FH:
    // dielectric = (1 - m)(1 - specular_tint), schlick_f0 = (1 - m) specular_tint 0.08 specular Ctint + m base_color,
    // schlick_grazing = (1 - m) specular_tint + m
    F dielectric;
    Rgb<F> schlick_f0;
    F schlick_grazing;
    F transmission_weight;     // w_T = (1 - metallic) spec_trans
    Rgb<F> transmission_color;  // sqrt(base_color)
    F transmission_luminance;   // lum(sqrt(base_color))
    F eta, inv_eta;
    F eta_minus_one, inv_eta_minus_one;  // η - 1 and 1/η - 1 = -(η - 1)/η
    // the thin sheet's: the transmission's GGX, alphas of r_t = clamp((0.65 η - 0.35) r, 0, 1) with
    // roughness's anisotropy, and the diffuse transmission w_D dt c / π, its sampling weight w_D dt lum(c)
    bool thin = false;
    Ggx<F> thin_ggx;
    Rgb<F> diffuse_transmission;
    F diffuse_transmission_luminance;

    PB_MODEL_INLINE bool opaque() const { return !nonzero_anywhere(transmission_weight); }
};

// Both GGX alphas of a roughness, with the 2014 anisotropy (principled.hpp's shading_of).
template <class F>
PB_MODEL_INLINE Ggx<F> ggx_of_roughness(F roughness, F anisotropic) {
    F aspect2 = neg_mul_add(F(0.9), anisotropic, F(1.0));
    F inv_aspect = reciprocal_sqrt(aspect2);
    F alpha = roughness * roughness;
    return Ggx<F>::from_alphas(max(F(0.001), alpha * inv_aspect), max(F(0.001), alpha * (aspect2 * inv_aspect)));
}

template <class F>
PB_MODEL_INLINE Shading2015<F> shading2015_of(const F* p, bool thin = false) {
    F one(1.0);
    Shading2015<F> s;
    s.brdf = shading_of(p);
    F metallic = p[kMetallic], dielectric = one - metallic;
    F opaque_fraction = one - p[kSpecTrans];
    s.brdf.diffuse.color = opaque_fraction * s.brdf.diffuse.color;
    s.brdf.diffuse.subsurface = F(0.0);
    s.brdf.sheen.color = opaque_fraction * s.brdf.sheen.color;
    s.brdf.diffuse.cosine_lobe_weight = opaque_fraction * s.brdf.diffuse.cosine_lobe_weight;
    s.flatness = p[kFlatness];

    Rgb<F> base{p[kBaseColorR], p[kBaseColorG], p[kBaseColorB]};
    Rgb<F> tint = tint_of(base, luminance_of(base)).color;
    F specular_tint = p[kSpecularTint];
    s.dielectric = dielectric * (one - specular_tint);
    s.schlick_f0 = (dielectric * specular_tint * F(0.08) * p[kSpecular]) * tint + metallic * base;
    s.schlick_grazing = mul_add(dielectric, specular_tint, metallic);
    s.transmission_weight = dielectric * p[kSpecTrans];
    s.transmission_color = {square_root(base.r), square_root(base.g), square_root(base.b)};
    s.transmission_luminance = luminance_of(s.transmission_color);
    s.eta_minus_one = eta_minus_one_of_specular(p[kSpecular]);
    s.eta = s.eta_minus_one + one;
    s.inv_eta = one / s.eta;
    s.inv_eta_minus_one = -s.eta_minus_one * s.inv_eta;
    s.thin = thin;
    if (thin) {
        // dt = diff_trans / 2 of the diffuse goes through the sheet; transmitted light keeps c, not sqrt(c)
        F kept = neg_mul_add(F(0.5), p[kDiffTrans], one);
        F through = F(0.5) * p[kDiffTrans];
        s.brdf.diffuse.color = kept * s.brdf.diffuse.color;
        s.brdf.sheen.color = kept * s.brdf.sheen.color;
        s.brdf.diffuse.cosine_lobe_weight = kept * s.brdf.diffuse.cosine_lobe_weight;
        s.transmission_color = base;
        s.transmission_luminance = luminance_of(base);
        F diffuse_weight = dielectric * opaque_fraction * through;
        s.diffuse_transmission = (diffuse_weight * F(kInvPi)) * base;
        s.diffuse_transmission_luminance = diffuse_weight * s.transmission_luminance;
        F thin_roughness = min(max(mul_add(F(0.65), s.eta, F(-0.35)) * p[kRoughness], F(0.0)), one);
        s.thin_ggx = ggx_of_roughness(thin_roughness, p[kAnisotropic]);
    }
    return s;
}

// (one model's each, for a function pointer)
template <class F>
PB_MODEL_INLINE Shading2015<F> solid_shading2015_of(const F* p) { return shading2015_of(p, false); }
template <class F>
PB_MODEL_INLINE Shading2015<F> thin_shading2015_of(const F* p) { return shading2015_of(p, true); }

// The pair as the viewer sees it (the file's comment).
template <class F>
struct Side {
    Vec3<F> wi, wo;     // mirrored when wo.z < 0: wo.z >= 0
    MaskOf<F> flipped;  // mirrored
    MaskOf<F> inside;   // the viewer is inside the solid (flipped; never on a thin sheet)
    F eta_t;            // η_t: η outside, 1/η inside
    F eta_t_minus_one;  // η_t - 1
};

template <class F>
PB_MODEL_INLINE Vec3<F> mirrored(const Vec3<F>& w) { return {w.x, w.y, -w.z}; }

template <class F>
PB_MODEL_INLINE Side<F> side_of(const Vec3<F>& wi, const Vec3<F>& wo, const Shading2015<F>& s) {
    Side<F> side;
    side.flipped = wo.z < F(0.0);
    side.inside = s.thin ? MaskOf<F>(false) : side.flipped;
    side.wi = select(side.flipped, mirrored(wi), wi);
    side.wo = select(side.flipped, mirrored(wo), wo);
    side.eta_t = select(side.inside, s.inv_eta, s.eta);
    side.eta_t_minus_one = select(side.inside, s.inv_eta_minus_one, s.eta_minus_one);
    return side;
}

// The lobes of f at a pair, per channel.
template <class F>
struct Lobes2015 {
    Rgb<F> diffuse, sheen, specular, clearcoat, transmission, diffuse_transmission;

    Rgb<F> total() const { return diffuse + sheen + specular + clearcoat + transmission + diffuse_transmission; }
};

// The reflection, both directions on the viewer's side (wi.z, wo.z > 0 after
// the Side's mirror): outside, the 2014 lobes with F_s; inside, only the
// interface, w_T F_D(cos θd; 1/η) Ds Gs.
template <class F>
PB_MODEL_INLINE Lobes2015<F> reflection2015(const Side<F>& side, const Geometry<F>& g, const Shading2015<F>& s) {
    const Shading<F>& b = s.brdf;
    F zero(0.0);
    Rgb<F> none{zero, zero, zero};
    F fh = schlick_weight_of_complement(g.one_minus_cos_theta_d);
    Fresnel<F> schlick{schlick_weight(side.wi.z), schlick_weight(side.wo.z), fh};
    MaskOf<F> outside = !side.inside;

    // Fd + flatness (ss - f_L), f_L = (1 - FL/2)(1 - FV/2): (1 - flatness) f_L + flatness ss + f_R with f_L + f_R = Fd
    F diffuse = b.diffuse.template value<false>(g, schlick);
    if (nonzero_anywhere(s.flatness)) {
        F lambert = neg_mul_add(F(0.5), schlick.fl, F(1.0)) * neg_mul_add(F(0.5), schlick.fv, F(1.0));
        diffuse = mul_add(s.flatness, b.diffuse.subsurface_shape(g, schlick) - lambert, diffuse);
    }
    Lobes2015<F> out;
    out.diffuse = select(outside, diffuse * b.diffuse.color, none);
    out.sheen = select(outside, fh * b.sheen.color, none);

    F ds_gs = b.specular.template value<Model::kDisney2014>(g, b.specular.ggx.smith_denominator(side.wo));
    F exact = fresnel_dielectric(g.cos_theta_d, side.eta_t);
    F one_minus_fh = F(1.0) - fh;
    F grey = mul_add(s.dielectric, exact, s.schlick_grazing * fh);
    Rgb<F> outside_fresnel{mul_add(s.schlick_f0.r, one_minus_fh, grey), mul_add(s.schlick_f0.g, one_minus_fh, grey),
                           mul_add(s.schlick_f0.b, one_minus_fh, grey)};
    F inside_fresnel = s.transmission_weight * exact;
    out.specular = ds_gs * select(side.inside, Rgb<F>{inside_fresnel, inside_fresnel, inside_fresnel}, outside_fresnel);

    F clearcoat = select(outside, b.clearcoat.value(g, fh, b.clearcoat.smith_wo(side.wo)), zero);
    out.clearcoat = {clearcoat, clearcoat, clearcoat};
    out.transmission = none;
    out.diffuse_transmission = none;
    return out;
}

// The generalised half vector of a transmitted pair and what both the value
// and the density read of it: H = wo + η_t wi turned to H.z >= 0 (Walter et
// al. 2007 eq. 16), valid where each direction sees the microfacet from its
// own side (wo·H > 0 > wi·H). H is formed as (wo + wi) + (η_t - 1) wi: where
// η_t nears 1 the light passes nearly straight through, wi nears -wo, and
// wo + wi is exact where wo + η_t wi would lose the digits of its rounded
// product.
template <class F>
struct Refraction {
    HalfVector<F> h;
    F wo_h, wi_h;      // wo·H, wi·H (unnormalised)
    F stretched_h2;    // Q = Hx²/ax² + Hy²/ay² + Hz²
    MaskOf<F> valid;
};

template <class F>
PB_MODEL_INLINE Refraction<F> refraction_of(const Side<F>& side, const Ggx<F>& ggx) {
    const Vec3<F>& wi = side.wi;
    F k = side.eta_t_minus_one;
    Vec3<F> sum{mul_add(k, wi.x, side.wo.x + wi.x), mul_add(k, wi.y, side.wo.y + wi.y), mul_add(k, wi.z, side.wo.z + wi.z)};
    Vec3<F> h = select(sum.z < F(0.0), Vec3<F>{-sum.x, -sum.y, -sum.z}, sum);
    Refraction<F> r;
    r.h.hx2 = h.x * h.x;
    r.h.hy2 = h.y * h.y;
    r.h.hz = h.z;
    r.h.hz2 = h.z * h.z;
    r.h.h_len2 = r.h.hx2 + r.h.hy2 + r.h.hz2;
    r.wo_h = dot(side.wo, h);
    r.wi_h = dot(side.wi, h);
    r.stretched_h2 = mul_add(r.h.hx2, ggx.inv_alpha_x2, mul_add(r.h.hy2, ggx.inv_alpha_y2, r.h.hz2));
    r.valid = (side.wi.z < F(0.0)) & (r.wo_h > F(0.0)) & (r.wi_h < F(0.0)) & (r.h.h_len2 > F(0.0));
    return r;
}

// The transmission (Walter et al. 2007 eq. 21), viewer above, light below:
//   w_T sqrt(c) (1 - F_D(wo·h; η_t)) D(h) G1(wo) G1(wi) |wo·h| |wi·h| / (|cos θv| |cos θl| (wo·h + η_t wi·h)²),
// times η_t² in importance mode. With H unnormalised, wo·H + η_t wi·H = |H|²,
// D(h) = norm |H|⁴ / Q² and G1(w) / |cos θ| = 2 / smith_denominator(|w|), so
//   D G1 G1 |wo·h| |wi·h| / (...) = 4 norm |wo·H| |wi·H| / (Q² S(wo) S(wi)):
// no normalisation, and no cancellation in the denominator.
template <class F>
PB_MODEL_INLINE F transmission_value(const Side<F>& side, const Refraction<F>& r, const Shading2015<F>& s,
                                     TransportMode mode) {
    const Ggx<F>& ggx = s.brdf.specular.ggx;
    F cos_h = r.wo_h * reciprocal_sqrt(r.h.h_len2);
    F transmitted = fresnel_dielectric_transmittance(cos_h, side.eta_t);
    F smith = ggx.smith_denominator(side.wo) * ggx.smith_denominator(mirrored(side.wi));
    F value = F(4.0) * s.transmission_weight * transmitted * ggx.norm * (r.wo_h * -r.wi_h) /
              (r.stretched_h2 * r.stretched_h2 * smith);
    if (mode == TransportMode::kImportance) value = value * (side.eta_t * side.eta_t);
    return select(r.valid, value, F(0.0));
}

// The thin sheet's microfacet transmission, viewer above, light below
// (Burley 2015): the light's direction mirrored, wi' = mirror(wi), h' the half
// vector of (wi', wo),
//   w_T c (1 - F_D(wo·h'; η)) D_t(h') G1_t(wo) G1_t(wi') / (4 |cos θl| |cos θv|),
// formed as the specular's Ds Gs (SpecularLobe::value) with the sheet's GGX; c applied by the caller.
template <class F>
PB_MODEL_INLINE F thin_transmission_value(const Side<F>& side, const Shading2015<F>& s) {
    Vec3<F> through = mirrored(side.wi);
    Geometry<F> g = geometry_of(through, side.wo);
    F ds_gs = s.thin_ggx.d(g) / (s.thin_ggx.smith_denominator(through) * s.thin_ggx.smith_denominator(side.wo));
    F value = s.transmission_weight * fresnel_dielectric_transmittance(g.cos_theta_d, s.eta) * ds_gs;
    return select((side.wi.z < F(0.0)) & g.finite, value, F(0.0));
}

// The thin sheet's density of transmitted wi: the mirrored direction's, drawn
// as a reflection about a half vector of the sheet's GGX (SpecularLobe::pdf).
template <class F>
PB_MODEL_INLINE F thin_transmission_pdf(const Side<F>& side, const Ggx<F>& ggx, SpecularSampler sampler) {
    Vec3<F> through = mirrored(side.wi);
    Geometry<F> g = geometry_of(through, side.wo);
    F d_h = ggx.d(g);
    F pdf = sampler == SpecularSampler::kDistribution ? ggx.distribution_pdf(d_h, g)
                                                     : ggx.visible_pdf(d_h, ggx.smith_denominator(side.wo));
    return select((side.wi.z < F(0.0)) & g.finite, pdf, F(0.0));
}

// Every lobe at (wi, wo), 0 where the pair is not one the model scatters
// (a direction in the tangent plane, or not finite: see geometry_of).
template <class F>
PB_MODEL_INLINE MaskOf<F> scattered2015(const Side<F>& side, const Geometry<F>& g) {
    return (side.wo.z > F(0.0)) & (side.wi.z != F(0.0)) & g.finite;
}

template <class F>
PB_MODEL_INLINE Lobes2015<F> eval_lobes2015(const Side<F>& side, const Geometry<F>& g, const Shading2015<F>& s,
                                             TransportMode mode) {
    F zero(0.0);
    Rgb<F> none{zero, zero, zero};
    MaskOf<F> scattered = scattered2015(side, g);
    Lobes2015<F> out = reflection2015(side, g, s);
    MaskOf<F> reflected = scattered & (side.wi.z > zero);
    out.diffuse = select(reflected, out.diffuse, none);
    out.sheen = select(reflected, out.sheen, none);
    out.specular = select(reflected, out.specular, none);
    out.clearcoat = select(reflected, out.clearcoat, none);
    out.diffuse_transmission = none;
    if (s.thin) {
        // no η² in importance mode: the sheet does not bend the light, and it is reciprocal as it stands
        MaskOf<F> through = scattered & (side.wi.z < zero);
        F t = s.opaque() ? zero : select(scattered, thin_transmission_value(side, s), zero);
        out.transmission = t * s.transmission_color;
        out.diffuse_transmission = select(through, s.diffuse_transmission, none);
    } else if (!s.opaque()) {
        F t = select(scattered, transmission_value(side, refraction_of(side, s.brdf.specular.ggx), s, mode), zero);
        out.transmission = t * s.transmission_color;
    }
    return out;
}

template <class F>
PB_MODEL_INLINE Lobes2015<F> eval_lobes2015(const Vec3<F>& wi, const Vec3<F>& wo, const Shading2015<F>& s,
                                             TransportMode mode) {
    Side<F> side = side_of(wi, wo, s);
    return eval_lobes2015(side, geometry_of(side.wi, side.wo), s, mode);
}

// ---------------------------------------------------------------- the sampling mixture (docs/sampling.md)
// Four lobes, chosen with probabilities P_k = w_k / Σ w from estimates of
// their albedo at the view: w0 = w_D (Cdlum + 0.1 sheen lum(Csheen))
// (cosine), w1 the specular reflection's, w2 the clearcoat's, w3 the
// solid's interface (lobe 3). The interface is drawn as a smooth interface is
// split at each microfacet: a half vector h is drawn first, and the draw
// reflects about it with probability q(h) = F / (F + (1 - F) t), F =
// F_D(wo·h; η_t), t = lum(sqrt(c)) outside and 1 inside, else refracts. So
// the weight of a reflection off a steep microfacet is not a ratio of two
// Fresnel factors at different angles (up to 1/F_D(cos θv): bright speckles
// in rough glass lit from behind). w3 = w_T (F + (1 - F) t) at h = n, and w1 =
// max(lum(F_s at cos θv) - w_T F_D(cos θv), 0.02): the specular reflection the
// interface does not draw. Inside only the interface exists (w0 = w1 = w2 =
// 0). The thin sheet: w1 = max(lum(F_s), 0.02), w0 times 1 - dt, w3 = w_T (1 -
// F_D) lum(c) its microfacet transmission, and w4 = w_D dt lum(c) (diffuse
// transmission). The reflected lobes count only above the viewer's side and
// the transmission only below: a draw that lands on the wrong side is no
// sample (pdf and weight 0).
template <class F>
struct LobeWeights2015 {
    F cosine, specular, clearcoat, transmission, diffuse_transmission;
    F inv_total;  // 0 where every weight is 0 (an opaque solid seen from inside)
    F transmitted_luminance;  // t of q(h): lum(sqrt(c)) outside, 1 inside
    F interface_reflection;   // w_T F_D(cos θv): the interface's share that reflects at h = n
};

template <class F>
PB_MODEL_INLINE LobeWeights2015<F> lobe_weights2015(const Side<F>& side, const Shading2015<F>& s) {
    F zero(0.0), one(1.0);
    F cos_v = side.wo.z;
    F fv = schlick_weight(cos_v);
    FresnelDielectric<F> fresnel = fresnel_dielectric_both(cos_v, side.eta_t);
    F exact = fresnel.reflectance;
    F t = select(side.inside, one, s.transmission_luminance);
    F grey = mul_add(s.dielectric, exact, s.schlick_grazing * fv);
    F specular = luminance_of(s.schlick_f0) * (one - fv) + grey;
    F transmitted = s.transmission_weight * fresnel.transmittance * t;
    LobeWeights2015<F> w;
    w.transmitted_luminance = t;
    w.interface_reflection = zero;
    w.cosine = select(side.inside, zero, s.brdf.diffuse.cosine_lobe_weight);
    w.clearcoat = select(side.inside, zero, s.brdf.clearcoat.weight(fv));
    if (s.thin) {
        w.specular = max(specular, F(0.02));
        w.transmission = transmitted;
        w.diffuse_transmission = s.diffuse_transmission_luminance;
    } else {
        F reflected = s.transmission_weight * exact;
        w.specular = select(side.inside, zero, max(specular - reflected, F(0.02)));
        w.transmission = reflected + transmitted;
        w.interface_reflection = reflected;
        w.diffuse_transmission = zero;
    }
    F total = w.cosine + w.specular + w.clearcoat + w.transmission + w.diffuse_transmission;
    w.inv_total = select(total > zero, one / total, zero);
    return w;
}

// The interface's chances at a microfacet of Fresnel factors F and T = 1 - F:
// to reflect, F / (F + T t), and to refract, T t / (F + T t).
template <class F>
struct InterfaceSplit {
    F reflects, refracts;
};

template <class F>
PB_MODEL_INLINE InterfaceSplit<F> interface_split(const FresnelDielectric<F>& fresnel, F t) {
    F through = fresnel.transmittance * t;
    F total = fresnel.reflectance + through;
    F inv_total = select(total > F(0.0), F(1.0) / total, F(0.0));
    return {fresnel.reflectance * inv_total, through * inv_total};
}

// The transmission lobe's density in wi: the half vector's (visible normals,
// G1(wo) (wo·h) D(h) / cos θv, or the distribution, D(h) cos θh) times
// |dωh/dωi| = η_t² |wi·h| / (wo·h + η_t wi·h)² (Walter et al. 2007 eq. 17),
// from H unnormalised as in transmission_value:
//   visible: 2 norm η_t² (wo·H) |wi·H| / (Q² S(wo)),  distribution: norm η_t² Hz |wi·H| / Q².
template <class F>
PB_MODEL_INLINE F transmission_pdf(const Side<F>& side, const Refraction<F>& r, const Ggx<F>& ggx, SpecularSampler sampler) {
    F common = ggx.norm * side.eta_t * side.eta_t * -r.wi_h / (r.stretched_h2 * r.stretched_h2);
    F pdf = sampler == SpecularSampler::kDistribution ? common * r.h.hz
                                                     : F(2.0) * common * r.wo_h / ggx.smith_denominator(side.wo);
    return select(r.valid, pdf, F(0.0));
}

// Σ P_k pdf_k(wi) given wo: 0 where a direction lies in the tangent plane or is not finite.
template <class F>
PB_MODEL_INLINE F pdf2015(const Side<F>& side, const Geometry<F>& g, const LobeWeights2015<F>& w,
                          const Shading2015<F>& s, SpecularSampler sampler) {
    F zero(0.0);
    MaskOf<F> scattered = scattered2015(side, g);
    const Shading<F>& b = s.brdf;
    F specular = b.specular.pdf(g, b.specular.ggx.smith_denominator(side.wo), sampler);
    F clearcoat = b.clearcoat.absent() ? zero : w.clearcoat * b.clearcoat.gtr1.pdf(g);
    F reflected = mul_add(w.cosine * F(kInvPi), side.wi.z, mul_add(w.specular, specular, clearcoat));
    F pdf = select(side.wi.z > zero, reflected, zero);
    if (s.thin) {
        F through = mul_add(w.diffuse_transmission * F(kInvPi), -side.wi.z,
                            w.transmission * thin_transmission_pdf(side, s.thin_ggx, sampler));
        pdf = select(side.wi.z < zero, through, pdf);
    } else if (!s.opaque()) {  // the interface, split at the microfacet: h_r of the reflection, h_t of the refraction
        Refraction<F> r = refraction_of(side, b.specular.ggx);
        MaskOf<F> below = side.wi.z < zero;
        F cos_h = select(below, r.wo_h * reciprocal_sqrt(r.h.h_len2), g.cos_theta_d);
        InterfaceSplit<F> split = interface_split(fresnel_dielectric_both(cos_h, side.eta_t), w.transmitted_luminance);
        F interface = select(below, split.refracts * transmission_pdf(side, r, b.specular.ggx, sampler),
                             split.reflects * specular);
        pdf = mul_add(w.transmission, interface, pdf);
    }
    return select(scattered, w.inv_total * pdf, zero);
}

template <class F>
PB_MODEL_INLINE F pdf2015(const Vec3<F>& wi, const Vec3<F>& wo, const Shading2015<F>& s, SpecularSampler sampler) {
    Side<F> side = side_of(wi, wo, s);
    return pdf2015(side, geometry_of(side.wi, side.wo), lobe_weights2015(side, s), s, sampler);
}

// The lobe a sample draws from: 0 cosine, 1 specular, 2 clearcoat, 3 transmission,
// 4 diffuse transmission (kSampledLobeNames), by u0 Σ w against the weights'
// running sums. The diffuse transmission draws the cosine lobe's direction
// and mirrors it below.
template <class F>
struct LobeChoice2015 {
    LobeChoice<F> reflected;  // the direction's draw (sample_direction's), for lanes not transmitting through a microfacet
    MaskOf<F> transmission, diffuse_transmission;
    F within_transmission;  // u0 rescaled to [0, 1) within the transmission's share (the interface's split)
};

template <class F>
PB_MODEL_INLINE LobeChoice2015<F> choose_lobe2015(F u0, const LobeWeights2015<F>& w) {
    F zero(0.0);
    F reflected_total = w.cosine + w.specular + w.clearcoat;
    F scaled = u0 * (reflected_total + w.transmission + w.diffuse_transmission);
    MaskOf<F> diffuse_transmission = !(scaled < reflected_total + w.transmission) & (w.diffuse_transmission > zero);
    MaskOf<F> transmission = !(scaled < reflected_total) & !diffuse_transmission & (w.transmission > zero);
    MaskOf<F> cosine = (scaled < w.cosine) | diffuse_transmission;
    // past the specular's share: the clearcoat when it has one, else the specular
    MaskOf<F> specular = !cosine & !transmission & ((scaled < w.cosine + w.specular) | (w.clearcoat <= zero));
    F within = (scaled - reflected_total) / select(transmission, w.transmission, F(1.0));
    return {{cosine, specular}, transmission, diffuse_transmission, within};
}

// wi refracted from wo about the microfacet normal h = d / |d| with η_t (Snell's
// law at the microfacet): with c = wo·h and cos²θt = (c² + (η_t - 1)(η_t + 1)) / η_t²,
//   wi = -wo / η_t + (c / η_t - cos θt) h;
// 0 under total internal reflection (cos²θt <= 0) or for d = 0.
template <class F>
PB_MODEL_INLINE Vec3<F> refract_about(const Vec3<F>& wo, const Vec3<F>& d, F eta_t) {
    F zero(0.0);
    F d_len2 = squared_length(d);
    F inv_len = reciprocal_sqrt(d_len2);
    Vec3<F> h{d.x * inv_len, d.y * inv_len, d.z * inv_len};
    F c = dot(wo, h);
    F cos2_t = cos2_theta_transmitted(c, eta_t);
    F inv_eta = F(1.0) / eta_t;
    F along_h = mul_sub(c, inv_eta, square_root_nonnegative(cos2_t));
    Vec3<F> wi{mul_sub(along_h, h.x, wo.x * inv_eta), mul_sub(along_h, h.y, wo.y * inv_eta), mul_sub(along_h, h.z, wo.z * inv_eta)};
    Vec3<F> none{zero, zero, zero};
    return select((cos2_t > zero) & (d_len2 > zero) & (c > zero), wi, none);
}

// One drawn sample: wi (in the caller's frame), its mixture pdf, weight
// f |cos θl| / pdf (0 with the pdf where wi is no sample), the lobe drawn from.
template <class F>
struct Sample2015 {
    Vec3<F> wi;
    F pdf;
    Rgb<F> weight;
    Lobes2015<F> lobes;  // f's lobes at (wi, wo)
    F scale;             // |cos θl| / pdf where valid, else 0
    LobeChoice2015<F> choice;
};

template <class F>
PB_MODEL_INLINE Sample2015<F> sample2015(const Vec3<F>& wo, const Uniforms<F>& u, const Shading2015<F>& s,
                                        SpecularSampler sampler, TransportMode mode) {
    F zero(0.0);
    Side<F> view = side_of(wo, wo, s);
    LobeWeights2015<F> w = lobe_weights2015(view, s);
    LobeChoice2015<F> choice = choose_lobe2015(u.u0, w);
    Vec3<F> wi = sample_direction(view.wo, u, choice.reflected, s.brdf, sampler).wi;
    wi = select(choice.diffuse_transmission, mirrored(wi), wi);
    if (s.thin && any(choice.transmission)) {
        // a reflection about a half vector of the sheet's GGX, mirrored below
        Shading<F> sheet = s.brdf;
        sheet.specular.ggx = s.thin_ggx;
        LobeChoice<F> specular{MaskOf<F>(false), MaskOf<F>(true)};
        wi = select(choice.transmission, mirrored(sample_direction(view.wo, u, specular, sheet, sampler).wi), wi);
    } else if (any(choice.transmission)) {
        // the solid's interface: h drawn as the specular's, then a reflection about it with probability
        // q(h) = F / (F + T t), else the refraction (the sampling mixture's comment)
        const Ggx<F>& ggx = s.brdf.specular.ggx;
        const auto [sin_phi, cos_phi] = sincos_turns(u.u1);
        Vec3<F> d = sampler == SpecularSampler::kDistribution ? ggx.sample_distribution(sin_phi, cos_phi, u.u2)
                                                               : ggx.sample_visible(view.wo, sin_phi, cos_phi, u.u2);
        F wo_d = dot(view.wo, d), d_len2 = squared_length(d);
        InterfaceSplit<F> split =
            interface_split(fresnel_dielectric_both(wo_d * reciprocal_sqrt(d_len2), view.eta_t), w.transmitted_luminance);
        MaskOf<F> reflects = choice.transmission & (choice.within_transmission < split.reflects);
        F scale = F(2.0) * wo_d / d_len2;
        Vec3<F> reflected{mul_sub(scale, d.x, view.wo.x), mul_sub(scale, d.y, view.wo.y), mul_sub(scale, d.z, view.wo.z)};
        wi = select(reflects, reflected, select(choice.transmission, refract_about(view.wo, d, view.eta_t), wi));
        choice.transmission = choice.transmission & !reflects;
        choice.reflected.specular = choice.reflected.specular | reflects;
    }
    // a draw counts only on its lobe's side: the reflected lobes' above, the transmission's below
    MaskOf<F> below = choice.transmission | choice.diffuse_transmission;
    MaskOf<F> on_its_side = (below & (wi.z < zero)) | (!below & (wi.z > zero));
    // the pair as the viewer sees it is the view with the drawn wi (side_of reads only wo)
    Side<F> pair = view;
    pair.wi = wi;
    Geometry<F> g = geometry_of(pair.wi, pair.wo);
    Sample2015<F> out;
    out.pdf = pdf2015(pair, g, w, s, sampler);
    out.lobes = eval_lobes2015(pair, g, s, mode);
    wi = select(view.flipped, mirrored(wi), wi);  // back to the caller's frame
    MaskOf<F> valid = (out.pdf > zero) & (view.wo.z > zero) & on_its_side;
    out.scale = select(valid, max(wi.z, -wi.z) / out.pdf, zero);
    Rgb<F> f = out.lobes.total();
    out.weight = {select(valid, out.scale * f.r, zero), select(valid, out.scale * f.g, zero), select(valid, out.scale * f.b, zero)};
    out.pdf = select(valid, out.pdf, zero);
    MaskOf<F> finite = squared_length(wo) <= F(kLargestDirectionsLength2);
    Vec3<F> none{zero, zero, zero};
    out.wi = select(finite, wi, none);
    out.choice = choice;
    return out;
}
