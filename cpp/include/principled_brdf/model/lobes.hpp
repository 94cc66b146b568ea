// Part of the model (docs/model.md): the lobes of the principled BRDF over a
// number type F, each with the constants it prepares once per material (per
// call for a uniform material, per batch otherwise) and what it contributes:
// its value, its share of the lobe choice (a cheap estimate of its albedo at
// wo) and its density.
#pragma once  // once per translation unit: included only by model.hpp, which allows one namespace

// f's lobes, a color each, in kLobeNames' order (Lobe indexes them); the
// lobes a model does not have are 0.
template <class F>
using LobeColors = std::array<Rgb<F>, kLobeCount>;

template <class F>
PB_MODEL_INLINE LobeColors<F> no_lobes() {
    LobeColors<F> lobes;
    for (Rgb<F>& lobe : lobes) lobe = {F(0.0), F(0.0), F(0.0)};
    return lobes;
}

template <class F>
PB_MODEL_INLINE Rgb<F>& lobe_of(LobeColors<F>& lobes, Lobe lobe) { return lobes[static_cast<int>(lobe)]; }

// What the lobes read of a pair (wi, wo): the half vector H = wi + wo kept
// unnormalised (docs/model.md, "The model", numerics).
template <class F>
struct Geometry : HalfVector<F> {
    Vec3<F> wi, wo;
    F cos_theta_d;            // |H| / 2 (= wi·h = wo·h for unit vectors)
    F one_minus_cos_theta_d;  // |wi - wo|² / (4 (1 + cos θd)): no cancellation as wi -> wo
    MaskOf<F> in_range;       // |wi|² + |wo|² <= kLargestDirectionsLength2: false for NaN, infinities and long vectors
};

// With the direction check off, a pair is evaluated as given while
// |wi|² + |wo|² <= 8 (a unit vector beside one of length up to √7), and gives
// f = 0 beyond: within it every term of the model stays finite in float32 for
// parameters within the kernels' range (Fd90 grows with |H|², the distributions
// with |H|⁴ / |H|² ratios), beyond it they need not (docs/bad-input.md).
inline constexpr double kLargestDirectionsLength2 = 8.0;

template <class F>
PB_MODEL_INLINE Geometry<F> geometry_of(const Vec3<F>& wi, const Vec3<F>& wo) {
    Geometry<F> g;
    g.wi = wi;
    g.wo = wo;
    F hx = wi.x + wo.x, hy = wi.y + wo.y;
    g.hz = wi.z + wo.z;
    g.hx2 = hx * hx;
    g.hy2 = hy * hy;
    g.hz2 = g.hz * g.hz;
    g.h_len2 = g.hx2 + g.hy2 + g.hz2;
    g.cos_theta_d = F(0.5) * square_root_nonnegative(g.h_len2);
    F dx = wi.x - wo.x, dy = wi.y - wo.y, dz = wi.z - wo.z;
    F d_len2 = mul_add(dx, dx, mul_add(dy, dy, dz * dz));
    // |H|² + |wi - wo|² = 2 (|wi|² + |wo|²) (the parallelogram law)
    g.in_range = g.h_len2 + d_len2 <= F(2.0 * kLargestDirectionsLength2);
    g.one_minus_cos_theta_d = d_len2 / mul_add(F(4.0), g.cos_theta_d, F(4.0));
    return g;
}

// The Schlick weights of the pair: FL, FV, FH.
template <class F>
struct Fresnel {
    F fl, fv, fh;
};

// Diffuse with its subsurface blend (Burley 2012 §5.3):
//   (1/π) mix(Fd, ss, subsurface) base_color (1 - metallic),
//   Fd = mix(1, Fd90, FL) mix(1, Fd90, FV),  Fd90 = 0.5 + 2 roughness cos²θd,
//   ss = 1.25 (Fss (1 / (cos θl + cos θv) - 0.5) + 0.5),  Fss90 = roughness cos²θd.
// Sampled by the cosine lobe (cos θl / π), which also serves the sheen.
template <class F>
struct DiffuseLobe {
    Rgb<F> color;  // base_color (1 - metallic) / π
    F subsurface, roughness;
    F cosine_lobe_weight;  // w0 = (1 - metallic) (Cdlum + 0.1 sheen lum(Csheen))

    // the scalar factor of color (with_subsurface false: for a subsurface of 0, known)
    template <bool with_subsurface = true>
    PB_MODEL_INLINE F factor(const Geometry<F>& g, const Fresnel<F>& fresnel) const {
        F one(1.0);
        F cos2_theta_d = F(0.25) * g.h_len2;
        // mix(1, F90, FL) as 1 + (F90 - 1) FL, one rounding
        F fd90_minus_1 = mul_add(F(2.0) * roughness, cos2_theta_d, F(-0.5));
        F fd = mul_add(fd90_minus_1, fresnel.fl, one) * mul_add(fd90_minus_1, fresnel.fv, one);
        // Skipped when 0 in every lane: for a uniform material the test has the
        // same outcome for every batch, and mix(fd, ss, 0) = fd bit for bit.
        if (!with_subsurface || !nonzero_anywhere(subsurface)) return fd;
        return mix(fd, subsurface_shape(g, fresnel), subsurface);
    }

    // ss, the Hanrahan-Krueger-like shape (the 2015 models' flatness reads it too)
    PB_MODEL_INLINE F subsurface_shape(const Geometry<F>& g, const Fresnel<F>& fresnel) const {
        F one(1.0);
        F cos2_theta_d = F(0.25) * g.h_len2;
        F fss90_minus_1 = mul_sub(roughness, cos2_theta_d, one);
        F fss = mul_add(fss90_minus_1, fresnel.fl, one) * mul_add(fss90_minus_1, fresnel.fv, one);
        F inv_cos_sum = reciprocal(g.wi.z + g.wo.z);
        return F(1.25) * mul_add(fss, inv_cos_sum - F(0.5), F(0.5));
    }
};

// D and its partials in roughness and subsurface (gradients.hpp).
template <class F>
struct DiffusePartials {
    F value, roughness, subsurface;
};

// DiffuseLobe::factor with its partials: fd and Fss are products of two lines
// in roughness, (1 + (F90 - 1) FL)(1 + (F90 - 1) FV), and D = mix(fd, ss, subsurface)
template <class F>
PB_MODEL_INLINE DiffusePartials<F> diffuse_partials(const DiffuseLobe<F>& lobe, const Geometry<F>& g, const Fresnel<F>& fresnel) {
    F one(1.0), half(0.5);
    F cos2_theta_d = F(0.25) * g.h_len2;
    F fd90_minus_1 = mul_add(F(2.0) * lobe.roughness, cos2_theta_d, F(-0.5));
    F fd_l = mul_add(fd90_minus_1, fresnel.fl, one), fd_v = mul_add(fd90_minus_1, fresnel.fv, one);
    F fd = fd_l * fd_v;
    F fd_roughness = F(2.0) * cos2_theta_d * mul_add(fresnel.fl, fd_v, fresnel.fv * fd_l);
    F fss90_minus_1 = mul_sub(lobe.roughness, cos2_theta_d, one);
    F fss_l = mul_add(fss90_minus_1, fresnel.fl, one), fss_v = mul_add(fss90_minus_1, fresnel.fv, one);
    F fss_roughness = cos2_theta_d * mul_add(fresnel.fl, fss_v, fresnel.fv * fss_l);
    F inv_cos_sum_minus_half = reciprocal(g.wi.z + g.wo.z) - half;
    F ss = F(1.25) * mul_add(fss_l * fss_v, inv_cos_sum_minus_half, half);
    F ss_roughness = F(1.25) * fss_roughness * inv_cos_sum_minus_half;
    return {mix(fd, ss, lobe.subsurface), mix(fd_roughness, ss_roughness, lobe.subsurface), ss - fd};
}

// Sheen: FH sheen Csheen (1 - metallic), Csheen = mix(1, Ctint, sheen_tint).
template <class F>
struct SheenLobe {
    Rgb<F> color;  // sheen Csheen (1 - metallic); the lobe is FH times it
};

// The GGX alphas of a roughness and an anisotropy (Burley 2012 with the 2014
// addenda): aspect = sqrt(1 - 0.9 anisotropic), r² / aspect and r² aspect,
// before the lobes' floor of 0.001.
template <class F>
struct Alphas {
    F x, y;
    F inv_aspect;  // 1 / aspect
};

template <class F>
PB_MODEL_INLINE Alphas<F> alphas_of(F roughness, F anisotropic) {
    F aspect2 = neg_mul_add(F(0.9), anisotropic, F(1.0));  // in [0.1, 1]
    F inv_aspect = reciprocal_sqrt(aspect2);
    F alpha = roughness * roughness;
    return {alpha * inv_aspect, alpha * (aspect2 * inv_aspect), inv_aspect};
}

template <class F>
PB_MODEL_INLINE Ggx<F> ggx_of_roughness(F roughness, F anisotropic) {
    Alphas<F> a = alphas_of(roughness, anisotropic);
    return Ggx<F>::from_alphas(max(F(0.001), a.x), max(F(0.001), a.y));
}

// The primary specular, the microfacet BRDF D F G / (4 cos θl cos θv) with
//   D = Ds, anisotropic GGX,
//   F = Fs = mix(Cspec0, 1, FH), per channel (applied by LobeValues),
//   G = G1(wi) G1(wo), separable Smith: anisotropic in the 2014 model,
//       isotropic with alpha_g = (0.5 + roughness / 2)² in the 2012 one.
// ds_gs() is its scalar factor D G / (4 cos θl cos θv) = Ds Gs (docs/model.md's
// Gs = S(wi) S(wo), S(w) = G1(w) / (2 n·w)).
template <class F>
struct SpecularLobe {
    Rgb<F> f0;        // Cspec0
    F f0_luminance;   // lum(Cspec0)
    Ggx<F> ggx;
    F alpha_g2;       // alpha_g² of the 2012 model's Smith term

    // D G / (4 cos θl cos θv), the scalar factor of Fs, given the Smith denominator of wo.
    // G / (4 cos θl cos θv) is taken as 1 / (smith_denominator(wi) smith_denominator(wo)):
    // each G1(w) = 2 n·w / smith_denominator(w) brings the 2 n·w that the
    // 1/(4 cos θl cos θv) divides out, so neither G1 nor the cosines' product is
    // formed (no 0/0 at grazing angles), and D over the product is one rounded quotient.
    template <Model model>
    PB_MODEL_INLINE F ds_gs(const Geometry<F>& g, F smith_wo) const {
        F four_cos_cos_over_g;  // 4 cos θl cos θv / G
        if constexpr (model == Model::kDisney2012) {
            four_cos_cos_over_g = smith_denominator_iso(g.wi, alpha_g2) * smith_wo;
        } else {
            four_cos_cos_over_g = ggx.smith_denominator(g.wi) * smith_wo;
        }
        F d = ggx.d(g);
        return d / four_cos_cos_over_g;
    }

    // w1 = max(lum(mix(Cspec0, 1, FV)), 0.02)
    PB_MODEL_INLINE F weight(F fv) const { return max(mix(f0_luminance, F(1.0), fv), F(0.02)); }

    // the log-derivatives of Gs Ds in ax and ay (the 2012 model's Smith term
    // reads alpha_g, not ax and ay)
    template <Model model>
    PB_MODEL_INLINE LogAlphaPartials<F> log_value_partials(const Geometry<F>& g) const {
        LogAlphaPartials<F> d = ggx.log_d_partials(g);
        if constexpr (model == Model::kDisney2014) {
            LogAlphaPartials<F> smith_i = ggx.log_smith_partials(g.wi), smith_o = ggx.log_smith_partials(g.wo);
            d = {d.sum - (smith_i.sum + smith_o.sum), d.difference - (smith_i.difference + smith_o.difference)};
        }
        return d;
    }

    // ∂ln(Gs Ds)/∂alpha_g² (the 2012 model's isotropic Smith term; 0 in the 2014 model)
    PB_MODEL_INLINE F log_value_partial_alpha_g2(const Geometry<F>& g) const {
        return -(log_smith_denominator_iso_partial(g.wi, alpha_g2) + log_smith_denominator_iso_partial(g.wo, alpha_g2));
    }

    // the density in wi of the half vector drawn by `sampler`
    PB_MODEL_INLINE F pdf(const Geometry<F>& g, F smith_visible_wo, SpecularSampler sampler) const {
        F d_h = ggx.d(g);
        return sampler == SpecularSampler::kDistribution ? ggx.distribution_pdf(d_h, g) : ggx.visible_pdf(d_h, smith_visible_wo);
    }
};

// Clearcoat, 0.25 clearcoat times the microfacet BRDF D F G / (4 cos θl cos θv) with
//   D = Dr, GTR1 with ac = mix(0.1, 0.001, clearcoat_gloss),
//   F = Fr = mix(0.04, 1, FH),
//   G = Gr, separable isotropic Smith GGX at alpha 0.25,
// G / (4 cos θl cos θv) taken from the Smith denominators as the specular's.
template <class F>
struct ClearcoatLobe {
    Gtr1<F> gtr1;
    F scale;        // 0.25 clearcoat (ac² - 1) / (π ln ac²): the lobe's strength times D's normaliser
    F lobe_weight;  // 0.25 clearcoat

    static constexpr double kSmithAlpha2 = 0.0625;  // Gr's alpha 0.25, squared

    PB_MODEL_INLINE bool absent() const { return !nonzero_anywhere(scale); }

    // the Smith denominator n·w + sqrt(...) = 2 n·w / G1(w) of wo at alpha 0.25 (1 when no lane has a clearcoat)
    PB_MODEL_INLINE F smith_wo(const Vec3<F>& wo) const {
        return absent() ? F(1.0) : smith_denominator_iso_small(wo.z, F(kSmithAlpha2));
    }

    // 0.25 clearcoat D F G / (4 cos θl cos θv), grey (0 in every lane without a clearcoat):
    // with D = norm |H|² / gtr1.denominator (Gtr1::d), one quotient
    // (0.25 clearcoat norm) F |H|² / (gtr1.denominator (4 cos θl cos θv / G))
    PB_MODEL_INLINE F grey_value(const Geometry<F>& g, F fh, F smith_wo) const {
        if (absent()) return F(0.0);
        F f = mul_add(F(0.96), fh, F(0.04));  // F = mix(0.04, 1, FH)
        F four_cos_cos_over_g = smith_denominator_iso_small(g.wi.z, F(kSmithAlpha2)) * smith_wo;  // 4 cos θl cos θv / G
        return scale * f * g.h_len2 / (gtr1.denominator(g) * four_cos_cos_over_g);
    }

    // the value per unit clearcoat, 0.25 D F G / (4 cos θl cos θv), computed whether or not the lobe is present
    PB_MODEL_INLINE F unit_value(const Geometry<F>& g, F fh) const {
        F f = mul_add(F(0.96), fh, F(0.04));  // F = mix(0.04, 1, FH)
        F alpha2 = F(kSmithAlpha2);
        F four_cos_cos_over_g = smith_denominator_iso_small(g.wi.z, alpha2) * smith_denominator_iso_small(g.wo.z, alpha2);
        return F(0.25) * gtr1.norm * f * g.h_len2 / (gtr1.denominator(g) * four_cos_cos_over_g);
    }

    // w2 = 0.25 clearcoat mix(0.04, 1, FV)
    PB_MODEL_INLINE F weight(F fv) const { return lobe_weight * mul_add(F(0.96), fv, F(0.04)); }
};
