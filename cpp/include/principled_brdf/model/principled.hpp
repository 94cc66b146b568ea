// Part of the model (docs/model.md): the principled BRDF as the composition of
// its lobes, over a number type F: the material's constants, f and its lobes,
// the sampling mixture's weights and density, the lobe choice, the draw of wi
// and the weight of a drawn sample (docs/model.md, "The model"; docs/sampling.md).
#pragma once  // once per translation unit: included only by model.hpp, which allows one namespace

// Everything the lobes need of a material, independent of the directions.
template <class F>
struct Shading {
    DiffuseLobe<F> diffuse;
    SheenLobe<F> sheen;
    SpecularLobe<F> specular;
    ClearcoatLobe<F> clearcoat;
};

// From the kParamSlots values of params.hpp's order.
template <class F>
PB_MODEL_INLINE Shading<F> shading_of(const F* p) {
    F one(1.0);
    Rgb<F> base{p[kBaseColorR], p[kBaseColorG], p[kBaseColorB]};
    F metallic = p[kMetallic];
    F dielectric = one - metallic;

    F luminance = luminance_of(base);
    Rgb<F> tint = tint_of(base, luminance).color;
    Rgb<F> white{one, one, one};

    Shading<F> s;
    s.diffuse.color = (dielectric * F(kInvPi)) * base;
    s.diffuse.subsurface = p[kSubsurface];
    s.diffuse.roughness = p[kRoughness];
    Rgb<F> sheen_tint = mix(white, tint, p[kSheenTint]);
    s.sheen.color = (p[kSheen] * dielectric) * sheen_tint;
    s.diffuse.cosine_lobe_weight = dielectric * mul_add(F(0.1) * p[kSheen], luminance_of(sheen_tint), luminance);

    s.specular.f0 = mix((p[kSpecular] * F(0.08)) * mix(white, tint, p[kSpecularTint]), base, metallic);
    s.specular.f0_luminance = luminance_of(s.specular.f0);
    s.specular.ggx = ggx_of_roughness(p[kRoughness], p[kAnisotropic]);
    F alpha_g = mul_add(F(0.5), p[kRoughness], F(0.5));
    s.specular.alpha_g2 = (alpha_g * alpha_g) * (alpha_g * alpha_g);

    // ac = mix(0.1, 0.001, clearcoat_gloss) stays in [0.001, 0.1]
    s.clearcoat.gtr1 = Gtr1<F>::from_alpha(mix(F(0.1), F(0.001), p[kClearcoatGloss]));
    s.clearcoat.scale = F(0.25) * p[kClearcoat] * s.clearcoat.gtr1.norm;
    s.clearcoat.lobe_weight = F(0.25) * p[kClearcoat];
    return s;
}

// The lobes an evaluation computes, a compile-time choice (the kernels make it
// once per call from a uniform material): each set leaves out only terms that
// are exactly 0 for the materials it is chosen for, so that f has the same
// bits as with kAll (a multiply-add with a zero product returns its addend).
// The 2015 models keep their transmissions in every set (skipped when the
// material is opaque in every lane).
enum class LobeSet : int {
    kAll,       // every lobe (subsurface and clearcoat still skipped when 0 in every lane)
    kPlain,     // diffuse and primary specular: subsurface, sheen and clearcoat 0
    kSpecular,  // the primary specular alone: no diffuse, subsurface or sheen (metallic 1, or in the 2015
                // models spec_trans 1), clearcoat 0
};

// What f and the pdf need of wo alone.
template <class F>
struct View {
    F fv;               // Schlick(cos θv)
    F smith_visible;    // the GGX Smith denominator of wo: the 2014 model's, and the visible-normal pdf's
    F smith_specular;   // the model's Smith denominator of wo
    F smith_clearcoat;  // at alpha 0.25 (1 when no lane has a clearcoat)
};

// given FV and the visible-normal Smith denominator (sampling has them from the choice and the draw)
template <Model model, LobeSet lobes = LobeSet::kAll, class F>
PB_MODEL_INLINE View<F> view_of(const Vec3<F>& wo, const Shading<F>& s, F smith_visible, F fv) {
    View<F> v;
    v.fv = fv;
    v.smith_visible = smith_visible;
    if constexpr (model == Model::kDisney2012) {
        v.smith_specular = smith_denominator_iso(wo, s.specular.alpha_g2);
    } else {
        v.smith_specular = v.smith_visible;
    }
    if constexpr (lobes == LobeSet::kAll) {
        v.smith_clearcoat = s.clearcoat.smith_wo(wo);
    } else {
        v.smith_clearcoat = F(1.0);
    }
    return v;
}

template <Model model, LobeSet lobes = LobeSet::kAll, class F>
PB_MODEL_INLINE View<F> view_of(const Vec3<F>& wo, const Shading<F>& s) {
    return view_of<model, lobes>(wo, s, s.specular.ggx.smith_denominator(wo), schlick_weight(wo.z));
}

// The lobes as scalar factors of the material's colors:
//   diffuse   = diffuse  base_color (1 - metallic) / π   (s.diffuse.color)
//   sheen     = FH  sheen Csheen (1 - metallic)         (s.sheen.color)
//   specular  = specular  Fs,  specular = Ds Gs = D G / (4 cos θl cos θv),  Fs = mix(Cspec0, 1, FH)
//   clearcoat = clearcoat  (grey)
template <class F>
struct LobeValues {
    F diffuse, fh, specular, clearcoat;

    Rgb<F> diffuse_rgb(const Shading<F>& s) const { return diffuse * s.diffuse.color; }
    Rgb<F> sheen_rgb(const Shading<F>& s) const { return fh * s.sheen.color; }
    Rgb<F> specular_rgb(const Shading<F>& s) const { return specular * mix(s.specular.f0, Rgb<F>{F(1.0), F(1.0), F(1.0)}, fh); }  // Ds Gs Fs
    Rgb<F> clearcoat_rgb() const { return {clearcoat, clearcoat, clearcoat}; }

    // every lobe, the multiple-scattering one given (the transmissions are 0)
    LobeColors<F> colors(const Shading<F>& s, const Rgb<F>& multiple_scattering) const {
        LobeColors<F> lobes = no_lobes<F>();
        lobe_of(lobes, Lobe::kDiffuse) = diffuse_rgb(s);
        lobe_of(lobes, Lobe::kSheen) = sheen_rgb(s);
        lobe_of(lobes, Lobe::kSpecular) = specular_rgb(s);
        lobe_of(lobes, Lobe::kClearcoat) = clearcoat_rgb();
        lobe_of(lobes, Lobe::kMultipleScattering) = multiple_scattering;
        return lobes;
    }

    // f = diffuse + sheen + specular + clearcoat per channel, summed from the
    // clearcoat up with each lobe's product fused into the sum: three FMAs a
    // channel (fewer for a LobeSet without the diffuse or the sheen: their
    // terms are 0). The specular's Fresnel mix(Cspec0, 1, FH) is expanded as
    // (1 - FH) Cspec0 + FH, so that its grey half, specular FH, joins the
    // clearcoat once for the three channels and the tinted half is one FMA a
    // channel: specular + clearcoat = (specular (1 - FH)) Cspec0 + (specular FH + clearcoat).
    template <LobeSet lobes = LobeSet::kAll>
    Rgb<F> total(const Shading<F>& s) const {
        F specular_of_cspec0 = specular * (F(1.0) - fh);  // specular (1 - FH), Cspec0's factor
        F specular_grey_and_clearcoat = lobes == LobeSet::kAll ? mul_add(specular, fh, clearcoat) : specular * fh;
        auto channel = [&](F diffuse_color, F sheen_color, F cspec0) {
            F specular_and_clearcoat = mul_add(specular_of_cspec0, cspec0, specular_grey_and_clearcoat);
            if constexpr (lobes == LobeSet::kSpecular) {
                return specular_and_clearcoat;
            } else if constexpr (lobes == LobeSet::kPlain) {
                return mul_add(diffuse, diffuse_color, specular_and_clearcoat);
            } else {
                F sheen_specular_and_clearcoat = mul_add(fh, sheen_color, specular_and_clearcoat);
                return mul_add(diffuse, diffuse_color, sheen_specular_and_clearcoat);
            }
        };
        return {channel(s.diffuse.color.r, s.sheen.color.r, s.specular.f0.r),
                channel(s.diffuse.color.g, s.sheen.color.g, s.specular.f0.g),
                channel(s.diffuse.color.b, s.sheen.color.b, s.specular.f0.b)};
    }
};

// f = 0 unless both directions lie strictly above the surface (and, checks
// off, H is finite): the values are selected away there, whatever they are.
template <class F>
PB_MODEL_INLINE MaskOf<F> above_surface(const Geometry<F>& g) {
    return (g.wi.z > F(0.0)) & (g.wo.z > F(0.0)) & g.in_range;
}

// (the lobes a LobeSet leaves out are 0)
template <Model model, LobeSet lobes = LobeSet::kAll, class F>
PB_MODEL_INLINE LobeValues<F> eval_lobes(const Geometry<F>& g, const Shading<F>& s, const View<F>& view) {
    F fh = schlick_weight_of_complement(g.one_minus_cos_theta_d);
    LobeValues<F> out;
    if constexpr (lobes == LobeSet::kSpecular) {
        out.diffuse = F(0.0);
    } else {
        out.diffuse = s.diffuse.template factor<lobes == LobeSet::kAll>(g, Fresnel<F>{schlick_weight(g.wi.z), view.fv, fh});
    }
    out.fh = fh;
    out.specular = s.specular.template ds_gs<model>(g, view.smith_specular);
    if constexpr (lobes == LobeSet::kAll) {
        out.clearcoat = s.clearcoat.grey_value(g, fh, view.smith_clearcoat);
    } else {
        out.clearcoat = F(0.0);
    }
    return out;
}

// ---------------------------------------------------------------- the sampling mixture
// Lobes 0 (cosine: diffuse, subsurface, sheen), 1 (specular), 2 (clearcoat),
// chosen with probabilities P_k = w_k / Σ w from the lobes' albedo estimates:
// w0 = (1 - metallic)(Cdlum + 0.1 sheen lum(Csheen)), w1 and w2 from FV.

// w1, w2 at wo (w0 is the material's) and 1 / Σ w: the choice compares
// u0 Σ w against them, so it does not wait for the reciprocal.
template <class F>
struct LobeWeights {
    F specular, clearcoat, inv_total;
};

template <class F>
PB_MODEL_INLINE LobeWeights<F> lobe_weights(F fv, const Shading<F>& s) {
    F w1 = s.specular.weight(fv), w2 = s.clearcoat.weight(fv);
    return {w1, w2, reciprocal(s.diffuse.cosine_lobe_weight + w1 + w2)};
}

// Σ P_k pdf_k(wi), before the horizon test:
//   pdf0 = cos θl / π,  pdf1 the specular sampler's,  pdf2 the GTR1 draw's.
// A LobeSet without the clearcoat has P2 = +0, and P2 pdf2 = +0 wherever
// pdf2 is finite (both directions above the surface): its kernels add +0
// without computing pdf2, the same bits there.
template <LobeSet lobes = LobeSet::kAll, class F>
PB_MODEL_INLINE F mixture_pdf(const Geometry<F>& g, const Shading<F>& s, const View<F>& view, const LobeWeights<F>& w,
                              SpecularSampler sampler) {
    F pdf1 = s.specular.pdf(g, view.smith_visible, sampler);
    F clearcoat_part = lobes == LobeSet::kAll ? w.clearcoat * s.clearcoat.gtr1.pdf(g) : F(0.0);
    return w.inv_total * mul_add(s.diffuse.cosine_lobe_weight * F(kInvPi), g.wi.z, mul_add(w.specular, pdf1, clearcoat_part));
}

template <class F>
struct LobeChoice {
    MaskOf<F> cosine, specular;  // clearcoat otherwise
};

// Lobe 0 if u0 < P0, else 1 if u0 < P0 + P1, else 2, compared as u0 Σ w
// against w0 and w0 + w1; never 2 when w2 = 0 (u0 may be 1 if passed).
template <class F>
PB_MODEL_INLINE LobeChoice<F> choose_lobe(F u0, const Shading<F>& s, const LobeWeights<F>& w) {
    F w0 = s.diffuse.cosine_lobe_weight;
    F scaled = u0 * (w0 + w.specular + w.clearcoat);
    MaskOf<F> cosine = scaled < w0;
    MaskOf<F> specular = ((scaled < w0 + w.specular) | (w.clearcoat <= F(0.0))) & !cosine;
    return {cosine, specular};
}

template <class F>
struct Uniforms {
    F u0, u1, u2;
};

// What the draw returns: wi, and the visible-normal Smith denominator of wo
// (View::smith_visible), which the draw computes on the way.
template <class F>
struct Direction {
    Vec3<F> wi;
    F smith_visible;  // cos θv + |V|, V = (ax wo.x, ay wo.y, wo.z)
};

// wi for the chosen lobes. Each lobe draws a point at azimuth φ = 2π u1 about
// a centre and stretches it (docs/sampling.md):
//   m = (sinθ cos φ + c.x, sinθ sin φ + c.y, cosθ + c.z),  d = (sx m.x, sy m.y, m.z)
// cosine lobe:  sin²θ = u2, c = 0, s = 1, wi = d
// clearcoat:    sin²θ of the GTR1 draw, c = 0, s = 1, h ∝ d
// specular, visible normals by spherical caps (Dupuy & Benyoub 2023):
//               c = normalize(ax wo.x, ay wo.y, wo.z), cosθ = (1 - u2)(1 + c.z) - c.z,
//               s = (ax, ay), h ∝ d
// specular, distribution (Burley 2012 eq. 14-15): sin²θ = u2, c = 0, s = (ax, ay), h ∝ d
// and wi = 2 (wo·h) h - wo for the reflected lobes: the distributions' own
// draws (Ggx::sample_visible, sample_distribution, Gtr1::draw_sin2) merged
// into one construction, so that every lane does one draw, whatever the
// mixture of lobes in its batch; the parts of a lobe no
// lane chose are skipped, which changes no result. A d of length 0 (u2 = 1 at
// special angles) gives h = 0 and wi = -wo: below the horizon like every
// other u2 = 1 sample of the reflected lobes.
template <class F>
PB_MODEL_INLINE Direction<F> sample_direction(const Vec3<F>& wo, const Uniforms<F>& u, const LobeChoice<F>& lobe,
                                              const Shading<F>& s, SpecularSampler sampler) {
    using Mask = MaskOf<F>;
    F zero(0.0), one(1.0);
    const Ggx<F>& ggx = s.specular.ggx;
    // the visible-normal cap construction scaled by L = |V|, V = (ax wo.x, ay wo.y, wo.z),
    // so V need not be normalised: L cosθ = (1 - u2)(L + V.z) - V.z, L² sin²θ = L² - (L cosθ)²;
    // cos θv + L is the View's smith_visible, which the weight needs anyway
    Vec3<F> stretched = ggx.stretch(wo);
    F length2 = squared_length(stretched);
    F length = square_root_nonnegative(length2);
    F smith_visible = wo.z + length;
    const auto [sin_phi, cos_phi] = sincos_turns(u.u1);
    if (all(lobe.cosine)) {
        F radius = square_root(u.u2);
        return {{radius * cos_phi, radius * sin_phi, square_root(one - u.u2)}, smith_visible};
    }
    Mask clearcoat = !lobe.cosine & !lobe.specular;
    const bool visible_normals = sampler == SpecularSampler::kVisibleNormals;
    Mask visible_specular = visible_normals ? lobe.specular : Mask(false);

    F sin2_theta = u.u2;  // cosine lobe, distribution sampler
    F scaled_cos = zero;  // L cosθ of the visible-normal specular
    F centre_x = zero, centre_y = zero;
    if (visible_normals && any(lobe.specular)) {
        scaled_cos = Ggx<F>::cap_scaled_cos(u.u2, length, stretched.z);
        sin2_theta = select(lobe.specular, neg_mul_add(scaled_cos, scaled_cos, length2), sin2_theta);
        centre_x = select(lobe.specular, stretched.x, zero);
        centre_y = select(lobe.specular, stretched.y, zero);
    }
    if (any(clearcoat)) sin2_theta = select(clearcoat, s.clearcoat.gtr1.draw_sin2(u.u2), sin2_theta);
    F sin_theta = square_root(sin2_theta);
    // m.z: L cosθ + V.z for the visible-normal specular, else cosθ from sin²θ (a
    // square root that a batch of visible-normal draws alone, a metal's, skips)
    F height = scaled_cos + stretched.z;
    if (!all(visible_specular)) height = select(visible_specular, height, square_root(one - sin2_theta));
    F stretch_x = select(lobe.specular, ggx.alpha_x, one);
    F stretch_y = select(lobe.specular, ggx.alpha_y, one);
    Vec3<F> d{stretch_x * mul_add(sin_theta, cos_phi, centre_x), stretch_y * mul_add(sin_theta, sin_phi, centre_y), height};

    // wi = 2 (wo·h) h - wo with h = d / |d|
    F d_len2 = squared_length(d);
    F scale = select(d_len2 > zero, F(2.0) * dot(wo, d) / d_len2, zero);
    Vec3<F> reflected{mul_sub(scale, d.x, wo.x), mul_sub(scale, d.y, wo.y), mul_sub(scale, d.z, wo.z)};
    return {select(lobe.cosine, d, reflected), smith_visible};
}

// A drawn sample weighed: its mixture pdf and weight = f cos θl / pdf, both 0
// unless wi and wo lie above the surface with pdf > 0; wi = 0 where H was not
// finite (a NaN, infinite or huge wo, checks off).
template <class F>
struct Weighed {
    Vec3<F> wi;
    F pdf;
    Rgb<F> weight;
    // what each lobe's share of the weight, select(valid, scale * lobe, 0), needs
    LobeValues<F> lobes;
    F scale;  // cos θl / pdf
    MaskOf<F> valid;

    Rgb<F> share(const Rgb<F>& lobe) const {
        Rgb<F> zero{F(0.0), F(0.0), F(0.0)};
        return select(valid, scale * lobe, zero);
    }
};

// (LobeSet as for eval_lobes; the lobes' values are then only the set's)
template <Model model, LobeSet set = LobeSet::kAll, class F>
PB_MODEL_INLINE Weighed<F> weigh(const Vec3<F>& wo, F fv, const LobeWeights<F>& weights, const Direction<F>& drawn,
                                 const Shading<F>& s, SpecularSampler sampler) {
    const Vec3<F>& wi = drawn.wi;
    View<F> view = view_of<model, set>(wo, s, drawn.smith_visible, fv);
    Geometry<F> g = geometry_of(wi, wo);
    F pdf = mixture_pdf<set>(g, s, view, weights, sampler);
    MaskOf<F> valid = (min(wi.z, wo.z) > F(0.0)) & g.in_range & (pdf > F(0.0));
    LobeValues<F> lobes = eval_lobes<model, set>(g, s, view);
    Rgb<F> f = lobes.template total<set>(s);
    F scale = wi.z / pdf;  // cos θl / pdf
    // select after multiplying: below the horizon f may be infinite or NaN
    auto weight = [&](F value) { return select(valid, scale * value, F(0.0)); };
    auto finite = [&](F value) { return select(g.in_range, value, F(0.0)); };
    Weighed<F> w;
    w.wi = {finite(wi.x), finite(wi.y), finite(wi.z)};
    w.pdf = select(valid, pdf, F(0.0));
    w.weight = {weight(f.r), weight(f.g), weight(f.b)};
    w.lobes = lobes;
    w.scale = scale;
    w.valid = valid;
    return w;
}
