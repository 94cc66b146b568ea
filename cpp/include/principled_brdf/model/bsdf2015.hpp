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

// What the solid and the thin sheet share of a material, independent of the
// directions: the 2014 lobes outside and the dielectric interface.
template <class F>
struct Interface2015 {
    // the 2014 lobes' constants, the diffuse and sheen colors and the cosine
    // lobe's weight times the share of the diffuse that stays outside (w_D =
    // (1 - metallic)(1 - spec_trans) of it, less the sheet's transmitted part)
    Shading<F> brdf;
    F flatness;
    // the specular's Fresnel factor F_s = dielectric F_D(cos θd; η) + schlick_f0 (1 - FH) + schlick_grazing FH:
    // dielectric = (1 - m)(1 - specular_tint), schlick_f0 = (1 - m) specular_tint 0.08 specular Ctint + m base_color,
    // schlick_grazing = (1 - m) specular_tint + m
    F dielectric;
    Rgb<F> schlick_f0;
    F schlick_grazing;
    F transmission_weight;      // w_T = (1 - metallic) spec_trans
    Rgb<F> transmission_color;  // the transmitted light's color c
    F transmission_luminance;   // lum(c)
    F eta, inv_eta;
    F eta_minus_one, inv_eta_minus_one;  // η - 1 and 1/η - 1 = -(η - 1)/η
    DielectricCompensation<F> compensation;  // the energy compensation's (the solid's, under the option; else none)

    PB_MODEL_INLINE bool opaque() const { return !nonzero_anywhere(transmission_weight); }
};

// The interface's constants with `kept` of the diffuse and sheen outside
// and transmitted light of color `transmitted`.
template <class F>
PB_MODEL_INLINE Interface2015<F> interface2015_of(const F* p, F kept, const Rgb<F>& transmitted) {
    F one(1.0);
    Interface2015<F> s;
    s.brdf = shading_of(p);
    F metallic = p[kMetallic], dielectric = one - metallic;
    s.brdf.diffuse.color = kept * s.brdf.diffuse.color;
    s.brdf.diffuse.subsurface = F(0.0);
    s.brdf.sheen.color = kept * s.brdf.sheen.color;
    s.brdf.diffuse.cosine_lobe_weight = kept * s.brdf.diffuse.cosine_lobe_weight;
    s.flatness = p[kFlatness];

    Rgb<F> base{p[kBaseColorR], p[kBaseColorG], p[kBaseColorB]};
    Rgb<F> tint = tint_of(base, luminance_of(base)).color;
    F specular_tint = p[kSpecularTint];
    s.dielectric = dielectric * (one - specular_tint);
    s.schlick_f0 = (dielectric * specular_tint * F(0.08) * p[kSpecular]) * tint + metallic * base;
    s.schlick_grazing = mul_add(dielectric, specular_tint, metallic);
    s.transmission_weight = dielectric * p[kSpecTrans];
    s.transmission_color = transmitted;
    s.transmission_luminance = luminance_of(transmitted);
    s.eta_minus_one = eta_minus_one_of_specular(p[kSpecular]);
    s.eta = s.eta_minus_one + one;
    s.inv_eta = one / s.eta;
    s.inv_eta_minus_one = -s.eta_minus_one * s.inv_eta;
    return s;
}

// The solid (disney2015): the interface refracts, transmitted light takes
// c = sqrt(base_color) (it crosses the surface twice), the diffuse keeps 1 - spec_trans.
template <class F>
struct Solid2015 : Interface2015<F> {
    static constexpr bool thin = false;

    static PB_MODEL_INLINE Solid2015 of(const F* p) {
        Rgb<F> base{p[kBaseColorR], p[kBaseColorG], p[kBaseColorB]};
        Rgb<F> root{square_root(base.r), square_root(base.g), square_root(base.b)};
        return {interface2015_of(p, F(1.0) - p[kSpecTrans], root)};
    }
};

// The thin sheet (disney2015_thin): dt = diff_trans / 2 of the diffuse goes
// through the sheet as a diffuse transmission, w_D dt c / π, sampled with
// weight w_D dt lum(c); the microfacet transmission takes its own GGX, of
// r_t = clamp((0.65 η - 0.35) r, 0, 1) with roughness's anisotropy; the light
// that passes keeps c = base_color.
template <class F>
struct ThinSheet2015 : Interface2015<F> {
    static constexpr bool thin = true;
    Ggx<F> transmission_ggx;
    Rgb<F> diffuse_transmission;
    F diffuse_transmission_luminance;

    static PB_MODEL_INLINE ThinSheet2015 of(const F* p) {
        F one(1.0);
        Rgb<F> base{p[kBaseColorR], p[kBaseColorG], p[kBaseColorB]};
        F opaque_fraction = one - p[kSpecTrans];
        F through = F(0.5) * p[kDiffTrans];
        Interface2015<F> shared = interface2015_of(p, opaque_fraction * (one - through), base);
        F diffuse_weight = (one - p[kMetallic]) * opaque_fraction * through;
        F roughness = min(max(mul_add(F(0.65), shared.eta, F(-0.35)) * p[kRoughness], F(0.0)), one);
        return {shared, ggx_of_roughness(roughness, p[kAnisotropic]), (diffuse_weight * F(kInvPi)) * base,
                diffuse_weight * shared.transmission_luminance};
    }
};

// The model's constants of a material: Solid2015 or ThinSheet2015.
template <Model model, class F>
using Shading2015 = std::conditional_t<model == Model::kDisney2015Thin, ThinSheet2015<F>, Solid2015<F>>;

// S::of(p), with the energy compensation (model/dielectric_energy.hpp) where
// `compensated` (the solid's; a thin sheet has none)
template <class S, class F>
PB_MODEL_INLINE S shading2015_of(const F* p, bool compensated) {
    S s = S::of(p);
    if constexpr (!S::thin) {
        if (compensated) s.compensation = dielectric_compensation_of(p, s.eta, s.eta_minus_one, s.transmission_weight);
    }
    return s;
}

// (the reference's row caches take a function of the row alone)
template <class S, class F, bool compensated>
PB_MODEL_INLINE S shading2015_of_row(const F* p) {
    return shading2015_of<S>(p, compensated);
}

// The diffuse transmission's color (a solid has none).
template <class S>
PB_MODEL_INLINE auto diffuse_transmission_of(const S& s) {
    using Number = decltype(s.eta);
    if constexpr (S::thin) {
        return s.diffuse_transmission;
    } else {
        return Rgb<Number>{Number(0.0), Number(0.0), Number(0.0)};
    }
}

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

template <class F, class S>
PB_MODEL_INLINE Side<F> side_of(const Vec3<F>& wi, const Vec3<F>& wo, const S& s) {
    Side<F> side;
    side.flipped = wo.z < F(0.0);
    side.inside = S::thin ? MaskOf<F>(false) : side.flipped;
    side.wi = select(side.flipped, mirrored(wi), wi);
    side.wo = select(side.flipped, mirrored(wo), wo);
    side.eta_t = select(side.inside, s.inv_eta, s.eta);
    side.eta_t_minus_one = select(side.inside, s.inv_eta_minus_one, s.eta_minus_one);
    return side;
}

// The lobes of f at a pair, per channel.
template <class F>
struct Lobes2015 {
    Rgb<F> diffuse, sheen, specular, clearcoat, transmission, diffuse_transmission, multiple_scattering;

    LobeColors<F> colors() const {
        LobeColors<F> lobes = no_lobes<F>();
        lobe_of(lobes, Lobe::kDiffuse) = diffuse;
        lobe_of(lobes, Lobe::kSheen) = sheen;
        lobe_of(lobes, Lobe::kSpecular) = specular;
        lobe_of(lobes, Lobe::kClearcoat) = clearcoat;
        lobe_of(lobes, Lobe::kTransmission) = transmission;
        lobe_of(lobes, Lobe::kDiffuseTransmission) = diffuse_transmission;
        lobe_of(lobes, Lobe::kMultipleScattering) = multiple_scattering;
        return lobes;
    }
};

// The lobes as scalar factors of the material's colors (as the 2014 model's
// LobeValues), 0 where the pair does not scatter into the lobe:
//   diffuse       of brdf.diffuse.color       Fd + flatness (ss - f_L), outside, reflected
//   sheen         of brdf.sheen.color         FH, outside, reflected
//   specular_f0   of schlick_f0               Ds Gs (1 - FH), outside, reflected
//   specular_grey (grey)                      Ds Gs (dielectric F_D + schlick_grazing FH) outside,
//                                             Ds Gs w_T F_D(cos θd; 1/η) inside, reflected
//   clearcoat     (grey)                      outside, reflected
//   transmission  of transmission_color       through the interface or the sheet
//   diffuse_transmission of diffuse_transmission  1 through the sheet, else 0
//   compensation  (grey, transmission_color, the metal's color)  the energy compensation's lobes
// F_s per channel is schlick_f0 (1 - FH) + the grey part, so the specular is
// specular_f0 schlick_f0 + specular_grey.
template <class F>
struct LobeValues2015 {
    F diffuse, sheen, specular_f0, specular_grey, clearcoat, transmission, diffuse_transmission;
    CompensationValues<F> compensation{F(0.0), F(0.0), F(0.0)};

    template <class S>
    Rgb<F> compensation_rgb(const S& s) const {
        const DielectricCompensation<F>& c = s.compensation;
        auto channel = [&](F color, F metal_color) {
            return mul_add(compensation.transmitted, color, mul_add(compensation.metal, metal_color, compensation.reflected));
        };
        return {channel(s.transmission_color.r, c.metal_color.r), channel(s.transmission_color.g, c.metal_color.g),
                channel(s.transmission_color.b, c.metal_color.b)};
    }

    template <class S>
    Lobes2015<F> rgb(const S& s) const {
        auto grey = [](F x) { return Rgb<F>{x, x, x}; };
        auto specular = [&](F f0) { return mul_add(specular_f0, f0, specular_grey); };
        Rgb<F> none = grey(F(0.0));
        return {diffuse * s.brdf.diffuse.color,
                sheen * s.brdf.sheen.color,
                {specular(s.schlick_f0.r), specular(s.schlick_f0.g), specular(s.schlick_f0.b)},
                grey(clearcoat),
                transmission * s.transmission_color,
                diffuse_transmission * diffuse_transmission_of(s),
                s.compensation.active() ? compensation_rgb(s) : none};
    }

    // f per channel, each lobe's product fused into one sum (a LobeSet's
    // left-out lobes are 0 for the materials it is chosen for, and so are the
    // transmissions of an opaque solid: their terms are skipped)
    template <LobeSet lobes = LobeSet::kAll, class S>
    Rgb<F> total(const S& s) const {
        F grey = lobes == LobeSet::kAll ? specular_grey + clearcoat : specular_grey;
        const bool transmits = !s.opaque();
        auto channel = [&](F diffuse_color, F sheen_color, F f0, F transmission_color, F diffuse_transmission_color) {
            F sum = mul_add(specular_f0, f0, grey);
            if (transmits) sum = mul_add(transmission, transmission_color, sum);
            if constexpr (S::thin) sum = mul_add(diffuse_transmission, diffuse_transmission_color, sum);
            if constexpr (lobes == LobeSet::kAll) sum = mul_add(sheen, sheen_color, sum);
            if constexpr (lobes != LobeSet::kSpecular) sum = mul_add(diffuse, diffuse_color, sum);
            return sum;
        };
        const Shading<F>& b = s.brdf;
        Rgb<F> dt = diffuse_transmission_of(s);
        Rgb<F> f{channel(b.diffuse.color.r, b.sheen.color.r, s.schlick_f0.r, s.transmission_color.r, dt.r),
                 channel(b.diffuse.color.g, b.sheen.color.g, s.schlick_f0.g, s.transmission_color.g, dt.g),
                 channel(b.diffuse.color.b, b.sheen.color.b, s.schlick_f0.b, s.transmission_color.b, dt.b)};
        if (!s.compensation.active()) return f;
        Rgb<F> added = compensation_rgb(s);
        return {f.r + added.r, f.g + added.g, f.b + added.b};
    }
};

// The microfacet of a pair, one a lane whichever way the light goes (Walter
// et al. 2007 eq. 16): H = wi + wo where the light is reflected, wo + η_t wi
// where the solid's interface transmits it (the light below the viewer's
// side), turned to H.z >= 0 (generalized_half_vector); a transmission is
// valid where each direction sees the microfacet from its own side
// (wo·H > 0 > wi·H). Kept unnormalised: with
// Q = Hx²/ax² + Hy²/ay² + Hz², D(h) = norm |H|⁴ / Q², and G1(w) / (2 |cos θ|)
// = 1 / S(w), S the Smith denominator of w turned above the surface, so that
//   reflection:   Ds Gs = D G1 G1 / (4 |cos θl| |cos θv|) = norm |H|⁴ / (Q² S(wo) S(wi)),
//   transmission: D G1 G1 |wo·h| |wi·h| / (|cos θv| |cos θl| (wo·h + η_t wi·h)²)
//                 = 4 norm (wo·H) |wi·H| / (Q² S(wo) S(wi))   (wo·H + η_t wi·H = |H|²),
// one quotient for either, with no normalisation and no cancellation in the
// denominator, and the exact Fresnel factors once, at wo·h.
template <class F>
struct Microfacet {
    HalfVector<F> h;
    F wo_h, wi_h;         // wo·H, wi·H
    F cos_h;              // wo·h (cos θd where the light is reflected)
    F one_minus_cos_h;    // 1 - cos θd where the light is reflected, as geometry_of forms it
    F smith_wo, smith_wi;  // S(wo), S(wi)
    F over;               // norm / (Q² S(wo) S(wi))
    MaskOf<F> transmits;  // a valid transmitted pair
};

template <class F>
PB_MODEL_INLINE Microfacet<F> microfacet_of(const Side<F>& side, const Ggx<F>& ggx, bool refracts) {
    F zero(0.0);
    const Vec3<F>& wi = side.wi;
    const Vec3<F>& wo = side.wo;
    MaskOf<F> below = wi.z < zero;
    Vec3<F> h = generalized_half_vector(wi, wo, refracts ? select(below, side.eta_t_minus_one, zero) : zero);
    Microfacet<F> m;
    m.h.hx2 = h.x * h.x;
    m.h.hy2 = h.y * h.y;
    m.h.hz = h.z;
    m.h.hz2 = h.z * h.z;
    m.h.h_len2 = m.h.hx2 + m.h.hy2 + m.h.hz2;
    m.wo_h = dot(wo, h);
    m.wi_h = dot(wi, h);
    // a reflection's wo·H is |H|² / 2 for unit vectors, which does not cancel where wi nears -wo
    m.cos_h = select(below, m.wo_h, F(0.5) * m.h.h_len2) * reciprocal_sqrt(m.h.h_len2);
    F dx = wi.x - wo.x, dy = wi.y - wo.y, dz = wi.z - wo.z;
    m.one_minus_cos_h = mul_add(dx, dx, mul_add(dy, dy, dz * dz)) / mul_add(F(4.0), m.cos_h, F(4.0));
    F q = mul_add(m.h.hx2, ggx.inv_alpha_x2, mul_add(m.h.hy2, ggx.inv_alpha_y2, m.h.hz2));
    m.smith_wo = ggx.smith_denominator(wo);
    m.smith_wi = ggx.smith_denominator(Vec3<F>{wi.x, wi.y, max(wi.z, -wi.z)});
    m.over = ggx.norm / (q * q * (m.smith_wo * m.smith_wi));
    m.transmits = below & (m.wo_h > zero) & (m.wi_h < zero) & (m.h.h_len2 > zero);
    return m;
}

// Every lobe at (wi, wo) is 0 where the pair is not one the model scatters:
// a direction in the tangent plane, or not finite (geometry_of's test).
template <class F>
PB_MODEL_INLINE MaskOf<F> scattered2015(const Side<F>& side) {
    F length2 = squared_length(side.wi) + squared_length(side.wo);
    return (side.wo.z > F(0.0)) & (side.wi.z != F(0.0)) & (length2 <= F(kLargestDirectionsLength2));
}

// What f and the density read of a pair: its side, microfacet and the
// exact Fresnel factors there (F_D(wo·h; η_t)).
template <class F>
struct Pair2015 {
    Side<F> side;
    Microfacet<F> microfacet;
    FresnelDielectric<F> fresnel;
    MaskOf<F> scattered;
};

template <class F, class S>
PB_MODEL_INLINE Pair2015<F> pair2015_of(const Side<F>& side, const S& s) {
    Pair2015<F> p;
    p.side = side;
    p.microfacet = microfacet_of(side, s.brdf.specular.ggx, !S::thin && !s.opaque());
    p.fresnel = fresnel_dielectric_both(p.microfacet.cos_h, side.eta_t);
    p.scattered = scattered2015(side);
    return p;
}

// The reflection's Geometry (lobes.hpp) read from its microfacet, H = wi + wo,
// for the lobes outside (the diffuse, the clearcoat).
template <class F>
PB_MODEL_INLINE Geometry<F> reflection_geometry(const Pair2015<F>& p) {
    Geometry<F> g;
    static_cast<HalfVector<F>&>(g) = p.microfacet.h;
    g.wi = p.side.wi;
    g.wo = p.side.wo;
    g.cos_theta_d = p.microfacet.cos_h;
    g.one_minus_cos_theta_d = p.microfacet.one_minus_cos_h;
    g.in_range = p.scattered;
    return g;
}

// The thin sheet's microfacet transmission, viewer above, light below
// (Burley 2015): the light's direction mirrored, wi' = mirror(wi), h' the half
// vector of (wi', wo),
//   w_T c (1 - F_D(wo·h'; η)) D_t(h') G1_t(wo) G1_t(wi') / (4 |cos θl| |cos θv|),
// formed as the specular's Ds Gs (SpecularLobe::ds_gs) with the sheet's GGX; c applied by the caller.
template <class F, class S>
PB_MODEL_INLINE F thin_transmission_value(const Side<F>& side, const S& s) {
    Vec3<F> through = mirrored(side.wi);
    Geometry<F> g = geometry_of(through, side.wo);
    F ds_gs = s.transmission_ggx.d(g) / (s.transmission_ggx.smith_denominator(through) * s.transmission_ggx.smith_denominator(side.wo));
    F value = s.transmission_weight * fresnel_dielectric_transmittance(g.cos_theta_d, s.eta) * ds_gs;
    return select((side.wi.z < F(0.0)) & g.in_range, value, F(0.0));
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
    return select((side.wi.z < F(0.0)) & g.in_range, pdf, F(0.0));
}

// The lobes' factors (LobeValues2015; a LobeSet's left-out lobes 0). The
// reflection, both directions on the viewer's side: outside, the 2014 lobes
// with F_s; inside, only the interface. The transmission, the light below
// (Walter et al. 2007 eq. 21, times η_t² in importance mode).
template <LobeSet lobes = LobeSet::kAll, class F, class S>
PB_MODEL_INLINE LobeValues2015<F> lobe_values2015(const Pair2015<F>& p, const S& s, TransportMode mode) {
    const Shading<F>& b = s.brdf;
    const Side<F>& side = p.side;
    const Microfacet<F>& m = p.microfacet;
    F zero(0.0), one(1.0);
    MaskOf<F> reflected = p.scattered & (side.wi.z > zero);
    MaskOf<F> reflected_outside = reflected & !side.inside;
    F fh = schlick_weight_of_complement(m.one_minus_cos_h);
    LobeValues2015<F> out;
    out.diffuse = zero;
    out.sheen = zero;
    out.clearcoat = zero;
    if constexpr (lobes != LobeSet::kSpecular) {
        Geometry<F> g = reflection_geometry(p);
        Fresnel<F> schlick{schlick_weight(side.wi.z), schlick_weight(side.wo.z), fh};
        // Fd + flatness (ss - f_L), f_L = (1 - FL/2)(1 - FV/2): (1 - flatness) f_L + flatness ss + f_R with f_L + f_R = Fd
        F diffuse = b.diffuse.template factor<false>(g, schlick);
        if (nonzero_anywhere(s.flatness)) {
            F lambert = neg_mul_add(F(0.5), schlick.fl, one) * neg_mul_add(F(0.5), schlick.fv, one);
            diffuse = mul_add(s.flatness, b.diffuse.subsurface_shape(g, schlick) - lambert, diffuse);
        }
        out.diffuse = select(reflected_outside, diffuse, zero);
        if constexpr (lobes == LobeSet::kAll) {
            out.sheen = select(reflected_outside, fh, zero);
            out.clearcoat = select(reflected_outside, b.clearcoat.grey_value(g, fh, b.clearcoat.smith_wo(side.wo)), zero);
        }
    }
    F ds_gs = m.h.h_len2 * m.h.h_len2 * m.over;
    F exact = p.fresnel.reflectance;
    F grey = select(side.inside, s.transmission_weight * exact, mul_add(s.dielectric, exact, s.schlick_grazing * fh));
    out.specular_f0 = select(reflected_outside, ds_gs * (one - fh), zero);
    out.specular_grey = select(reflected, ds_gs * grey, zero);
    out.transmission = zero;
    out.diffuse_transmission = zero;
    if constexpr (S::thin) {
        // no η² in importance mode: the sheet does not bend the light, and it is reciprocal as it stands
        if (!s.opaque()) out.transmission = select(p.scattered, thin_transmission_value(side, s), zero);
        out.diffuse_transmission = select(p.scattered & (side.wi.z < zero), one, zero);
    } else if (!s.opaque()) {
        F t = F(4.0) * s.transmission_weight * p.fresnel.transmittance * (m.wo_h * -m.wi_h) * m.over;
        if (mode == TransportMode::kImportance) t = t * (side.eta_t * side.eta_t);
        out.transmission = select(p.scattered & m.transmits, t, zero);
    }
    if (s.compensation.active()) {
        CompensationValues<F> c = compensation_values(s.compensation, side.wo.z, max(side.wi.z, -side.wi.z), side.inside,
                                                      side.wi.z < zero, side.eta_t, mode);
        out.compensation = {select(p.scattered, c.reflected, zero), select(p.scattered, c.transmitted, zero),
                            select(p.scattered, c.metal, zero)};
    }
    return out;
}

template <class F, class S>
PB_MODEL_INLINE Lobes2015<F> eval_lobes2015(const Vec3<F>& wi, const Vec3<F>& wo, const S& s,
                                             TransportMode mode) {
    return lobe_values2015(pair2015_of(side_of(wi, wo, s), s), s, mode).rgb(s);
}

// f, the lobes summed (LobeValues2015::total)
template <LobeSet lobes = LobeSet::kAll, class F, class S>
PB_MODEL_INLINE Rgb<F> eval2015(const Vec3<F>& wi, const Vec3<F>& wo, const S& s, TransportMode mode) {
    return lobe_values2015<lobes>(pair2015_of(side_of(wi, wo, s), s), s, mode).template total<lobes>(s);
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
// transmission). With the solid's energy compensation (model/dielectric_energy.hpp)
// its added reflections join w0 and its added transmission is w4, a cosine
// draw mirrored below like the sheet's. The reflected lobes count only above
// the viewer's side and the transmission only below: a draw that lands on the
// wrong side is no sample (pdf and weight 0).
template <class F>
struct LobeWeights2015 {
    F cosine, specular, clearcoat, transmission, diffuse_transmission;
    F inv_total;  // 0 where every weight is 0 (an opaque solid seen from inside)
    F transmitted_luminance;  // t of q(h): lum(sqrt(c)) outside, 1 inside
    F interface_reflection;   // w_T F_D(cos θv): the interface's share that reflects at h = n
};

template <class F, class S>
PB_MODEL_INLINE LobeWeights2015<F> lobe_weights2015(const Side<F>& side, const S& s) {
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
    if constexpr (S::thin) {
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
    if (s.compensation.active()) {  // the added lobes: reflected by the cosine lobe's draw, transmitted by its mirror image
        CompensationWeights<F> added = compensation_weights(s.compensation, cos_v, side.inside, s.transmission_luminance);
        w.cosine = w.cosine + added.reflected;
        w.diffuse_transmission = w.diffuse_transmission + added.transmitted;
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

// Σ P_k pdf_k(wi) given wo: 0 where a direction lies in the tangent plane or
// is not finite. The specular's density of a reflected wi, from the
// microfacet's quotient (D = norm |H|⁴ / Q²):
//   visible normals D / (2 S(wo)),  the distribution D Hz / (2 |H|²);
// the transmission's, the half vector's density times |dωh/dωi| = η_t² |wi·h|
// / (wo·h + η_t wi·h)² (Walter et al. 2007 eq. 17):
//   visible normals 2 norm η_t² (wo·H) |wi·H| / (Q² S(wo)),  the distribution norm η_t² Hz |wi·H| / Q².
// The interface is split at the pair's own microfacet (interface_split).
template <class F, class S>
PB_MODEL_INLINE F pdf2015(const Pair2015<F>& p, const LobeWeights2015<F>& w, const S& s,
                          SpecularSampler sampler) {
    F zero(0.0), half(0.5);
    const Side<F>& side = p.side;
    const Microfacet<F>& m = p.microfacet;
    const Shading<F>& b = s.brdf;
    const bool distribution = sampler == SpecularSampler::kDistribution;
    F d_over_smith_wo = m.over * m.smith_wi * m.h.h_len2;  // D / (S(wo) |H|²)
    F specular = distribution ? half * d_over_smith_wo * m.smith_wo * m.h.hz : half * d_over_smith_wo * m.h.h_len2;
    F clearcoat = b.clearcoat.absent() ? zero : w.clearcoat * b.clearcoat.gtr1.pdf(m.h);
    F reflected = mul_add(w.cosine * F(kInvPi), side.wi.z, mul_add(w.specular, specular, clearcoat));
    MaskOf<F> below = side.wi.z < zero;
    F pdf = select(below, zero, reflected);
    if constexpr (S::thin) {
        F through = mul_add(w.diffuse_transmission * F(kInvPi), -side.wi.z,
                            w.transmission * thin_transmission_pdf(side, s.transmission_ggx, sampler));
        pdf = select(below, through, pdf);
    } else {
        // the compensation's transmission: the cosine lobe mirrored below
        if (s.compensation.active()) pdf = select(below, w.diffuse_transmission * F(kInvPi) * -side.wi.z, pdf);
        if (!s.opaque()) {
            InterfaceSplit<F> split = interface_split(p.fresnel, w.transmitted_luminance);
            F through_h = (side.eta_t * side.eta_t) * -m.wi_h * m.over * m.smith_wi;  // norm η_t² |wi·H| / (Q² S(wo))
            F through = distribution ? through_h * m.smith_wo * m.h.hz : F(2.0) * through_h * m.wo_h;
            F interface = select(below, select(m.transmits, split.refracts * through, zero), split.reflects * specular);
            pdf = mul_add(w.transmission, interface, pdf);
        }
    }
    return select(p.scattered, w.inv_total * pdf, zero);
}

template <class F, class S>
PB_MODEL_INLINE F pdf2015(const Vec3<F>& wi, const Vec3<F>& wo, const S& s, SpecularSampler sampler) {
    Side<F> side = side_of(wi, wo, s);
    return pdf2015(pair2015_of(side, s), lobe_weights2015(side, s), s, sampler);
}

// f and the pdf of a pair from its one microfacet (eval_pdf)
template <class F>
struct ValuePdf2015 {
    Rgb<F> f;
    F pdf;
};

template <LobeSet lobes = LobeSet::kAll, class F, class S>
PB_MODEL_INLINE ValuePdf2015<F> eval_pdf2015(const Vec3<F>& wi, const Vec3<F>& wo, const S& s,
                                             TransportMode mode, SpecularSampler sampler) {
    Side<F> side = side_of(wi, wo, s);
    Pair2015<F> pair = pair2015_of(side, s);
    return {lobe_values2015<lobes>(pair, s, mode).template total<lobes>(s),
            pdf2015(pair, lobe_weights2015(side, s), s, sampler)};
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

// One drawn sample: wi (in the caller's frame), its mixture pdf, weight
// f |cos θl| / pdf (0 with the pdf where wi is no sample), the lobe drawn from.
template <class F>
struct Sample2015 {
    Vec3<F> wi;
    F pdf;
    Rgb<F> weight;
    LobeValues2015<F> lobes;  // f's lobes at (wi, wo)
    F scale;                  // |cos θl| / pdf where valid, else 0
    LobeChoice2015<F> choice;
};

// A draw in three stages, as the kernels' sampling loop runs them: the
// choice at wo alone (the weights and the lobe), the direction, its weight.
template <class F>
struct Chosen2015 {
    LobeWeights2015<F> weights;
    LobeChoice2015<F> choice;
};

template <class F, class S>
PB_MODEL_INLINE Chosen2015<F> choose2015(const Vec3<F>& wo, F u0, const S& s) {
    Chosen2015<F> c;
    c.weights = lobe_weights2015(side_of(wo, wo, s), s);
    c.choice = choose_lobe2015(u0, c.weights);
    return c;
}

// wi as the viewer sees it, and the lobe it came from once the interface has
// chosen between reflection and refraction.
template <class F>
struct Drawn2015 {
    Vec3<F> wi;
    LobeChoice2015<F> choice;
};

template <class F, class S>
PB_MODEL_INLINE Drawn2015<F> draw2015(const Vec3<F>& wo, const Uniforms<F>& u, const Chosen2015<F>& c,
                                      const S& s, SpecularSampler sampler) {
    Side<F> view = side_of(wo, wo, s);
    LobeChoice2015<F> choice = c.choice;
    Vec3<F> wi = sample_direction(view.wo, u, choice.reflected, s.brdf, sampler).wi;
    wi = select(choice.diffuse_transmission, mirrored(wi), wi);
    if constexpr (S::thin) {
        if (any(choice.transmission)) {
            // a reflection about a half vector of the sheet's GGX, mirrored below
            Shading<F> sheet = s.brdf;
            sheet.specular.ggx = s.transmission_ggx;
            LobeChoice<F> specular{MaskOf<F>(false), MaskOf<F>(true)};
            wi = select(choice.transmission, mirrored(sample_direction(view.wo, u, specular, sheet, sampler).wi), wi);
        }
    } else if (any(choice.transmission)) {
        // the solid's interface: h drawn as the specular's, then a reflection about it with probability
        // q(h) = F / (F + T t), else the refraction (the sampling mixture's comment)
        const Ggx<F>& ggx = s.brdf.specular.ggx;
        const auto [sin_phi, cos_phi] = sincos_turns(u.u1);
        Vec3<F> d = sampler == SpecularSampler::kDistribution ? ggx.sample_distribution(sin_phi, cos_phi, u.u2)
                                                               : ggx.sample_visible(view.wo, sin_phi, cos_phi, u.u2);
        F d_len2 = squared_length(d);
        F inv_len = reciprocal_sqrt(d_len2);
        Vec3<F> h{d.x * inv_len, d.y * inv_len, d.z * inv_len};
        F wo_h = dot(view.wo, h);
        InterfaceSplit<F> split = interface_split(fresnel_dielectric_both(wo_h, view.eta_t), c.weights.transmitted_luminance);
        MaskOf<F> reflects = choice.transmission & (choice.within_transmission < split.reflects);
        F scale = F(2.0) * wo_h;
        Vec3<F> reflected{mul_sub(scale, h.x, view.wo.x), mul_sub(scale, h.y, view.wo.y), mul_sub(scale, h.z, view.wo.z)};
        Vec3<F> none{F(0.0), F(0.0), F(0.0)};
        Vec3<F> refracted = select((d_len2 > F(0.0)) & (wo_h > F(0.0)), refract(view.wo, h, view.eta_t), none);
        wi = select(reflects, reflected, select(choice.transmission, refracted, wi));
        choice.transmission = choice.transmission & !reflects;
        choice.reflected.specular = choice.reflected.specular | reflects;
    }
    return {wi, choice};
}

// (LobeSet as for lobe_values2015)
template <LobeSet lobes = LobeSet::kAll, class F, class S>
PB_MODEL_INLINE Sample2015<F> weigh2015(const Vec3<F>& wo, const Chosen2015<F>& c, const Drawn2015<F>& drawn,
                                       const S& s, SpecularSampler sampler, TransportMode mode) {
    F zero(0.0);
    Side<F> side = side_of(wo, wo, s);
    Vec3<F> wi = drawn.wi;
    // a draw counts only on its lobe's side: the reflected lobes' above, the transmission's below
    MaskOf<F> below = drawn.choice.transmission | drawn.choice.diffuse_transmission;
    MaskOf<F> on_its_side = (below & (wi.z < zero)) | (!below & (wi.z > zero));
    // the pair as the viewer sees it is the view with the drawn wi (side_of reads only wo)
    side.wi = wi;
    Pair2015<F> pair = pair2015_of(side, s);
    Sample2015<F> out;
    out.pdf = pdf2015(pair, c.weights, s, sampler);
    out.lobes = lobe_values2015<lobes>(pair, s, mode);
    wi = select(side.flipped, mirrored(wi), wi);  // back to the caller's frame
    MaskOf<F> valid = (out.pdf > zero) & (side.wo.z > zero) & on_its_side;
    out.scale = select(valid, max(wi.z, -wi.z) / out.pdf, zero);
    Rgb<F> f = out.lobes.template total<lobes>(s);
    out.weight = {select(valid, out.scale * f.r, zero), select(valid, out.scale * f.g, zero), select(valid, out.scale * f.b, zero)};
    out.pdf = select(valid, out.pdf, zero);
    MaskOf<F> finite = squared_length(wo) <= F(kLargestDirectionsLength2);
    Vec3<F> none{zero, zero, zero};
    out.wi = select(finite, wi, none);
    out.choice = drawn.choice;
    return out;
}

template <LobeSet lobes = LobeSet::kAll, class F, class S>
PB_MODEL_INLINE Sample2015<F> sample2015(const Vec3<F>& wo, const Uniforms<F>& u, const S& s,
                                        SpecularSampler sampler, TransportMode mode) {
    Chosen2015<F> c = choose2015(wo, u.u0, s);
    return weigh2015<lobes>(wo, c, draw2015(wo, u, c, s, sampler), s, sampler, mode);
}
