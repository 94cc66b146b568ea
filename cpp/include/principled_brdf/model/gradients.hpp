// Part of the model (docs/model.md): the partial derivatives of the 2012 and
// 2014 models' f with respect to their 13 parameter slots (params.hpp order,
// base color expanded, kGradientSlots), over a number type F, written by hand
// beside the parts they differentiate.
//
// f is linear in most parameters (docs/model.md, "The model"): per channel c,
//   f_c = diffuse dc_c + FH sc_c + T f0_c + (S FH + C),   T = S (1 - FH),
// with the material's colors dc (diffuse), sc (sheen), f0 (Cspec0) and the
// scalars of the pair: diffuse = mix(Fd, ss, subsurface) (LobeValues::diffuse,
// from roughness and subsurface; not the distribution D), FH,
// S (specular, from roughness and anisotropic) and C (clearcoat, linear in
// clearcoat, through GTR1 in clearcoat_gloss). So the Jacobian is
//   ∂f_c/∂p = ∂diffuse/∂p dc_c + diffuse ∂dc_c/∂p + FH ∂sc_c/∂p + ∂S/∂p ((1 - FH) f0_c + FH) + T ∂f0_c/∂p + ∂C/∂p:
// the colors' partials are per-material constants (MaterialPartials, only
// the non-zero ones: Cspec0 and Csheen move with base_color through Ctint, the
// diffuse color only in its own channel), the
// scalars' partials come from methods beside the lobes and distributions they
// differentiate (diffuse_partials, SpecularLobe::log_value_partials,
// ClearcoatLobe::unit_value, Gtr1::log_d_partial_alpha2, ...). Where the model
// clamps (alpha = max(0.001, ...)) the derivative is the active branch's;
// Ctint = 1 where lum(base_color) <= 0 has derivative 0.
#pragma once  // once per translation unit: included only by model.hpp, which allows one namespace

template <class F>
PB_MODEL_INLINE F channel_of(const Rgb<F>& color, int c) { return c == 0 ? color.r : c == 1 ? color.g : color.b; }

// The material's constants of the Jacobian: its colors' non-zero partials and
// the partials of the roughnesses the lobes read.
template <class F>
struct MaterialPartials {
    // base_color: ∂dc_c/∂base_k = δ_ck (1 - metallic)/π, ∂sc_c/∂base_k = sheen_tint_scale ∂Ctint_c/∂base_k,
    // ∂f0_c/∂base_k = δ_ck metallic + specular_tint_scale ∂Ctint_c/∂base_k
    F dielectric_over_pi, metallic;
    F sheen_tint_scale;     // sheen (1 - metallic) sheen_tint
    F specular_tint_scale;  // (1 - metallic) 0.08 specular specular_tint
    F tint_base[3][3];      // ∂Ctint_c/∂base_k = (δ_ck - Ctint_c w_k) / lum, 0 where Ctint = 1
    Rgb<F> diffuse_metallic, sheen_metallic, f0_metallic;  // ∂dc, ∂sc, ∂f0 / ∂metallic
    Rgb<F> f0_specular, f0_specular_tint;                  // ∂f0/∂specular, ∂f0/∂specular_tint
    Rgb<F> sheen_sheen, sheen_sheen_tint;                  // ∂sc/∂sheen, ∂sc/∂sheen_tint
    // (∂ln ax/∂p ± ∂ln ay/∂p) / 2 for p = roughness, anisotropic (0 for an alpha its clamp holds):
    // what multiplies LogAlphaPartials' sum and difference
    F roughness_sum, roughness_difference;
    F anisotropic_sum, anisotropic_difference;
    F alpha_g2_roughness;      // ∂alpha_g²/∂roughness (the 2012 model's Smith term)
    F clearcoat_alpha2_gloss;  // ∂ac²/∂clearcoat_gloss
};

template <class F>
PB_MODEL_INLINE MaterialPartials<F> material_partials_of(const F* p) {
    F zero(0.0), one(1.0);
    Rgb<F> base{p[kBaseColorR], p[kBaseColorG], p[kBaseColorB]};
    F metallic = p[kMetallic], dielectric = one - metallic;
    F luminance = luminance_of(base);
    Tint<F> tinted = tint_of(base, luminance);
    Rgb<F> tint = tinted.color;
    const F weight_of[3] = {F(0.3), F(0.6), F(0.1)};  // lum's weights
    F sheen = p[kSheen], sheen_tint = p[kSheenTint];
    F specular_scale = F(0.08) * p[kSpecular], specular_tint = p[kSpecularTint];
    Rgb<F> white{one, one, one};
    Rgb<F> sheen_mix = mix(white, tint, sheen_tint);        // Csheen
    Rgb<F> specular_mix = mix(white, tint, specular_tint);  // mix(1, Ctint, specular_tint)
    Rgb<F> tint_minus_one{tint.r - one, tint.g - one, tint.b - one};

    MaterialPartials<F> d;
    d.dielectric_over_pi = dielectric * F(kInvPi);
    d.metallic = metallic;
    d.sheen_tint_scale = sheen * dielectric * sheen_tint;
    d.specular_tint_scale = dielectric * specular_scale * specular_tint;
    for (int c = 0; c < 3; ++c)
        for (int k = 0; k < 3; ++k)
            d.tint_base[c][k] = select(tinted.defined, neg_mul_add(channel_of(tint, c), weight_of[k], c == k ? one : zero) *
                                                               tinted.inverse_luminance, zero);
    d.diffuse_metallic = F(-kInvPi) * base;
    d.sheen_metallic = -sheen * sheen_mix;
    d.f0_metallic = {neg_mul_add(specular_scale, specular_mix.r, base.r), neg_mul_add(specular_scale, specular_mix.g, base.g),
                     neg_mul_add(specular_scale, specular_mix.b, base.b)};
    d.f0_specular = (dielectric * F(0.08)) * specular_mix;
    d.f0_specular_tint = (dielectric * specular_scale) * tint_minus_one;
    d.sheen_sheen = dielectric * sheen_mix;
    d.sheen_sheen_tint = (sheen * dielectric) * tint_minus_one;

    // ax = max(0.001, r² / aspect), ay = max(0.001, r² aspect), aspect = sqrt(1 - 0.9 anisotropic):
    // ∂ln ax/∂r = ∂ln ay/∂r = 2 / r, ∂ln ax/∂anisotropic = -∂ln ay/∂anisotropic = 0.45 / aspect²
    F roughness = p[kRoughness];
    Alphas<F> alphas = alphas_of(roughness, p[kAnisotropic]);
    MaskOf<F> x_active = alphas.x > F(0.001), y_active = alphas.y > F(0.001);
    F log_roughness = F(2.0) * reciprocal(select(x_active | y_active, roughness, one));
    F log_aspect = F(0.45) * (alphas.inv_aspect * alphas.inv_aspect);
    F x_roughness = select(x_active, log_roughness, zero), y_roughness = select(y_active, log_roughness, zero);
    F x_anisotropic = select(x_active, log_aspect, zero), y_anisotropic = select(y_active, -log_aspect, zero);
    F half(0.5);
    d.roughness_sum = half * (x_roughness + y_roughness);
    d.roughness_difference = half * (x_roughness - y_roughness);
    d.anisotropic_sum = half * (x_anisotropic + y_anisotropic);
    d.anisotropic_difference = half * (x_anisotropic - y_anisotropic);
    // alpha_g² = ((0.5 + roughness / 2)²)²: ∂/∂roughness = 2 alpha_g³
    F alpha_g = mul_add(F(0.5), roughness, F(0.5));
    d.alpha_g2_roughness = F(2.0) * alpha_g * alpha_g * alpha_g;
    // ac = mix(0.1, 0.001, gloss) = 0.1 - 0.099 gloss: ∂ac²/∂gloss = -0.198 ac
    F clearcoat_alpha = mix(F(0.1), F(0.001), p[kClearcoatGloss]);
    d.clearcoat_alpha2_gloss = F(-0.198) * clearcoat_alpha;
    return d;
}

// 1 - FH without cancellation as θd -> 90°, where FH -> 1 and ∂f/∂Cspec0 =
// S (1 - FH) would lose its digits: 1 - m⁵ = (1 - m)(1 + m + m² + m³ + m⁴)
// with m = clamp(1 - cos θd) and 1 - m taken as cos θd itself.
template <class F>
PB_MODEL_INLINE F one_minus_schlick_weight(const Geometry<F>& g) {
    F one(1.0), zero(0.0);
    F m = min(max(g.one_minus_cos_theta_d, zero), one);
    return min(max(g.cos_theta_d, zero), one) * mul_add(m, mul_add(m, mul_add(m, m + one, one), one), one);
}

// Whether a sink takes slot p's column: a sink with a wants(p) method says
// which (the kernels' column selections); any other sink takes them all.
template <class Sink, class = void>
struct SelectsColumns : std::false_type {};
template <class Sink>
struct SelectsColumns<Sink, std::void_t<decltype(std::declval<const Sink&>().wants(0))>> : std::true_type {};

template <class Sink>
PB_MODEL_INLINE bool sink_wants(const Sink& sink, int p) {
    if constexpr (SelectsColumns<std::decay_t<Sink>>::value) {
        return sink.wants(p);
    } else {
        return true;
    }
}

// f (per channel, as eval_lobes(...).total), returned, and its Jacobian, given
// to `jacobian(c, p, value)` for every channel c and every slot p the sink
// wants (sink_wants): the kernels store or reduce each value as it comes
// instead of holding 39 of them, and the scalars only unwanted columns need
// (the diffuse, specular and clearcoat partials) are not computed. A column's
// value is the same expression whichever others are wanted, so its bits do not
// depend on the selection. Every Jacobian entry
// is a sum of products of a per-material constant with one of nine scalars of
// the pair; `weigh` is applied to those scalars (the kernels: times cos θl
// if asked, 0 below the surface, where they may not be finite), so the
// entries need no masking of their own.
template <Model model, class F, class Weigh, class Sink>
PB_MODEL_INLINE Rgb<F> eval_gradient(const Geometry<F>& g, const Shading<F>& s, const View<F>& view,
                                     const MaterialPartials<F>& d, const Weigh& weigh, Sink&& jacobian) {
    auto wanted = [&](int p) { return sink_wants(jacobian, p); };
    LobeValues<F> lobes = eval_lobes<model>(g, s, view);
    F fh = lobes.fh, one_minus_fh = one_minus_schlick_weight(g);
    F zero(0.0);
    // diffuse, S, C per unit clearcoat, with their partials, where a wanted column reads them
    F diffuse_roughness = zero, diffuse_subsurface = zero;
    if (wanted(kRoughness) || wanted(kSubsurface)) {
        DiffusePartials<F> diffuse = diffuse_partials(s.diffuse, g, Fresnel<F>{schlick_weight(g.wi.z), view.fv, fh});
        diffuse_roughness = weigh(diffuse.roughness);
        diffuse_subsurface = weigh(diffuse.subsurface);
    }
    F specular_roughness = zero, specular_anisotropic = zero;
    if (wanted(kRoughness) || wanted(kAnisotropic)) {
        LogAlphaPartials<F> log_specular = s.specular.template log_value_partials<model>(g);
        F log_specular_roughness = mul_add(log_specular.sum, d.roughness_sum, log_specular.difference * d.roughness_difference);
        if constexpr (model == Model::kDisney2012)
            log_specular_roughness = mul_add(s.specular.log_value_partial_alpha_g2(g), d.alpha_g2_roughness, log_specular_roughness);
        F log_specular_anisotropic =
                mul_add(log_specular.sum, d.anisotropic_sum, log_specular.difference * d.anisotropic_difference);
        specular_roughness = weigh(lobes.specular * log_specular_roughness);
        specular_anisotropic = weigh(lobes.specular * log_specular_anisotropic);
    }
    F clearcoat_unit = zero, clearcoat_gloss = zero;
    if (wanted(kClearcoat) || wanted(kClearcoatGloss)) {
        F clearcoat_unit_raw = s.clearcoat.unit_value(g, fh);
        clearcoat_unit = weigh(clearcoat_unit_raw);
        if (wanted(kClearcoatGloss))
            clearcoat_gloss = weigh(F(4.0) * s.clearcoat.lobe_weight * clearcoat_unit_raw *
                                    s.clearcoat.gtr1.log_d_partial_alpha2(g) * d.clearcoat_alpha2_gloss);
    }
    // the weighed scalars (fh and 1 - fh stay as they are inside specular_factor, a finite factor)
    F diffuse_value = weigh(lobes.diffuse), fh_weighed = weigh(fh);
    F specular_tinted = weigh(lobes.specular * one_minus_fh);  // T

    // base_color: ∂f_c/∂base_k = δ_ck (diffuse (1 - metallic)/π + T metallic) + (FH sheen_tint_scale + T specular_tint_scale) ∂Ctint_c/∂base_k
    F own_channel = mul_add(diffuse_value, d.dielectric_over_pi, specular_tinted * d.metallic);
    F through_tint = mul_add(fh_weighed, d.sheen_tint_scale, specular_tinted * d.specular_tint_scale);
    for (int c = 0; c < 3; ++c) {
        F dc = channel_of(s.diffuse.color, c), f0 = channel_of(s.specular.f0, c);
        for (int k = 0; k < 3; ++k) {
            if (!wanted(kBaseColorR + k)) continue;
            F tinted = through_tint * d.tint_base[c][k];
            jacobian(c, kBaseColorR + k, c == k ? own_channel + tinted : tinted);
        }
        if (wanted(kMetallic))
            jacobian(c, kMetallic,
                     mul_add(diffuse_value, channel_of(d.diffuse_metallic, c),
                             mul_add(fh_weighed, channel_of(d.sheen_metallic, c), specular_tinted * channel_of(d.f0_metallic, c))));
        if (wanted(kSubsurface)) jacobian(c, kSubsurface, diffuse_subsurface * dc);
        if (wanted(kSpecular)) jacobian(c, kSpecular, specular_tinted * channel_of(d.f0_specular, c));
        if (wanted(kSpecularTint)) jacobian(c, kSpecularTint, specular_tinted * channel_of(d.f0_specular_tint, c));
        F specular_factor = mul_add(one_minus_fh, f0, fh);  // ∂f_c/∂S = (1 - FH) f0_c + FH
        if (wanted(kRoughness)) jacobian(c, kRoughness, mul_add(diffuse_roughness, dc, specular_roughness * specular_factor));
        if (wanted(kAnisotropic)) jacobian(c, kAnisotropic, specular_anisotropic * specular_factor);
        if (wanted(kSheen)) jacobian(c, kSheen, fh_weighed * channel_of(d.sheen_sheen, c));
        if (wanted(kSheenTint)) jacobian(c, kSheenTint, fh_weighed * channel_of(d.sheen_sheen_tint, c));
        if (wanted(kClearcoat)) jacobian(c, kClearcoat, clearcoat_unit);
        if (wanted(kClearcoatGloss)) jacobian(c, kClearcoatGloss, clearcoat_gloss);
    }
    return lobes.total(s);
}
