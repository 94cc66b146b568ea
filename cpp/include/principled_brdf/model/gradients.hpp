// Part of the model (docs/model.md): the partial derivatives of f with respect
// to the 13 parameter slots (params.hpp order, base colour expanded), over a
// number type F, written by hand beside the parts they differentiate.
//
// f is linear in most parameters (README "The model"): per channel c,
//   f_c = D dc_c + FH sc_c + T f0_c + (S FH + C),   T = S (1 - FH),
// with the material's colours dc (diffuse), sc (sheen), f0 (Cspec0) and the
// scalars of the pair: D (diffuse, from roughness and subsurface), FH,
// S (specular, from roughness and anisotropic) and C (clearcoat, linear in
// clearcoat, through GTR1 in clearcoat_gloss). So the Jacobian is
//   ∂f_c/∂p = ∂D/∂p dc_c + D ∂dc_c/∂p + FH ∂sc_c/∂p + ∂S/∂p ((1 - FH) f0_c + FH) + T ∂f0_c/∂p + ∂C/∂p:
// the colours' partials are per-material constants (MaterialPartials), the
// scalars' partials come from methods beside the lobes and distributions they
// differentiate (diffuse_partials, SpecularLobe::log_value_partials,
// ClearcoatLobe::unit_value, Gtr1::log_d_partial_alpha2, ...). Where the model
// clamps (alpha = max(0.001, ...)) the derivative is the active branch's;
// Ctint = 1 where lum(base_color) <= 0 has derivative 0.
#pragma once  // (per namespace that includes the model)

// ∂c/∂p of one colour c for every parameter slot p (zero where c does not depend on p).
template <class F>
struct ColourPartials {
    Rgb<F> slot[kParamSlots];
};

// The material's constants of the Jacobian: its colours' partials and the
// partials of the roughnesses the lobes read.
template <class F>
struct MaterialPartials {
    ColourPartials<F> diffuse, sheen, f0;
    // (∂ln ax/∂p ± ∂ln ay/∂p) / 2 for p = roughness, anisotropic (0 for an alpha its clamp holds):
    // what multiplies LogAlphaPartials' sum and difference
    F roughness_sum, roughness_difference;
    F anisotropic_sum, anisotropic_difference;
    F alpha_g2_roughness;                        // ∂alpha_g²/∂roughness (the 2012 model's Smith term)
    F clearcoat_alpha2_gloss;                    // ∂ac²/∂clearcoat_gloss
};

template <class F>
PB_MODEL_INLINE MaterialPartials<F> material_partials_of(const F* p) {
    const F zero(0.0), one(1.0);
    const Rgb<F> base{p[kBaseColorR], p[kBaseColorG], p[kBaseColorB]};
    const F metallic = p[kMetallic], dielectric = one - metallic;
    const F luminance = luminance_of(base);
    const MaskOf<F> has_luminance = luminance > zero;
    const F inv_luminance = reciprocal(select(has_luminance, luminance, one));
    const F tint_of[3] = {select(has_luminance, base.r * inv_luminance, one), select(has_luminance, base.g * inv_luminance, one),
                          select(has_luminance, base.b * inv_luminance, one)};
    const F weight_of[3] = {F(0.3), F(0.6), F(0.1)};  // lum's weights
    // ∂Ctint_c/∂base_k = (δ_ck - Ctint_c w_k) / lum, 0 where Ctint = 1
    auto tint_partial = [&](int c, int k) {
        const F delta = c == k ? one : zero;
        return select(has_luminance, neg_mul_add(tint_of[c], weight_of[k], delta) * inv_luminance, zero);
    };
    auto channel = [](Rgb<F>& colour, int c) -> F& { return c == 0 ? colour.r : c == 1 ? colour.g : colour.b; };

    MaterialPartials<F> d{};
    for (int s = 0; s < kParamSlots; ++s) d.diffuse.slot[s] = d.sheen.slot[s] = d.f0.slot[s] = {zero, zero, zero};
    const F sheen = p[kSheen], sheen_tint = p[kSheenTint];
    const F specular_scale = F(0.08) * p[kSpecular], specular_tint = p[kSpecularTint];
    for (int c = 0; c < 3; ++c) {
        const F base_c = c == 0 ? base.r : c == 1 ? base.g : base.b;
        const F sheen_mix = mix(one, tint_of[c], sheen_tint);     // Csheen_c
        const F specular_mix = mix(one, tint_of[c], specular_tint);
        // dc_c = (1 - metallic) base_c / π
        channel(d.diffuse.slot[kBaseColorR + c], c) = dielectric * F(kInvPi);
        channel(d.diffuse.slot[kMetallic], c) = -base_c * F(kInvPi);
        // sc_c = sheen (1 - metallic) Csheen_c
        for (int k = 0; k < 3; ++k)
            channel(d.sheen.slot[kBaseColorR + k], c) = sheen * dielectric * sheen_tint * tint_partial(c, k);
        channel(d.sheen.slot[kMetallic], c) = -sheen * sheen_mix;
        channel(d.sheen.slot[kSheen], c) = dielectric * sheen_mix;
        channel(d.sheen.slot[kSheenTint], c) = sheen * dielectric * (tint_of[c] - one);
        // f0_c = metallic base_c + (1 - metallic) 0.08 specular mix(1, Ctint_c, specular_tint)
        for (int k = 0; k < 3; ++k)
            channel(d.f0.slot[kBaseColorR + k], c) =
                    mul_add(dielectric * specular_scale * specular_tint, tint_partial(c, k), c == k ? metallic : zero);
        channel(d.f0.slot[kMetallic], c) = neg_mul_add(specular_scale, specular_mix, base_c);
        channel(d.f0.slot[kSpecular], c) = dielectric * F(0.08) * specular_mix;
        channel(d.f0.slot[kSpecularTint], c) = dielectric * specular_scale * (tint_of[c] - one);
    }

    // ax = max(0.001, r² / aspect), ay = max(0.001, r² aspect), aspect = sqrt(1 - 0.9 anisotropic):
    // ∂ln ax/∂r = ∂ln ay/∂r = 2 / r, ∂ln ax/∂anisotropic = -∂ln ay/∂anisotropic = 0.45 / aspect²
    const F roughness = p[kRoughness];
    const F aspect2 = neg_mul_add(F(0.9), p[kAnisotropic], one);
    const F inv_aspect = reciprocal_sqrt(aspect2);
    const F alpha = roughness * roughness;
    const MaskOf<F> x_active = alpha * inv_aspect > F(0.001), y_active = alpha * (aspect2 * inv_aspect) > F(0.001);
    const F log_roughness = F(2.0) * reciprocal(select(x_active | y_active, roughness, one));
    const F log_aspect = F(0.45) * reciprocal(aspect2);
    const F x_roughness = select(x_active, log_roughness, zero), y_roughness = select(y_active, log_roughness, zero);
    const F x_anisotropic = select(x_active, log_aspect, zero), y_anisotropic = select(y_active, -log_aspect, zero);
    const F half(0.5);
    d.roughness_sum = half * (x_roughness + y_roughness);
    d.roughness_difference = half * (x_roughness - y_roughness);
    d.anisotropic_sum = half * (x_anisotropic + y_anisotropic);
    d.anisotropic_difference = half * (x_anisotropic - y_anisotropic);
    // alpha_g² = ((0.5 + roughness / 2)²)²: ∂/∂roughness = 2 alpha_g³
    const F alpha_g = mul_add(F(0.5), roughness, F(0.5));
    d.alpha_g2_roughness = F(2.0) * alpha_g * alpha_g * alpha_g;
    // ac = mix(0.1, 0.001, gloss) = 0.1 - 0.099 gloss: ∂ac²/∂gloss = -0.198 ac
    const F clearcoat_alpha = mix(F(0.1), F(0.001), p[kClearcoatGloss]);
    d.clearcoat_alpha2_gloss = F(-0.198) * clearcoat_alpha;
    return d;
}

// 1 - FH without cancellation as θd -> 90°, where FH -> 1 and ∂f/∂Cspec0 =
// S (1 - FH) would lose its digits: 1 - m⁵ = (1 - m)(1 + m + m² + m³ + m⁴)
// with m = clamp(1 - cos θd) and 1 - m taken as cos θd itself.
template <class F>
PB_MODEL_INLINE F one_minus_schlick_weight(const Geometry<F>& g) {
    const F one(1.0), zero(0.0);
    const F m = min(max(g.one_minus_cos_theta_d, zero), one);
    return min(max(g.cos_theta_d, zero), one) * mul_add(m, mul_add(m, mul_add(m, m + one, one), one), one);
}

// f (per channel, as eval_lobes(...).total) and its Jacobian, jacobian[c][p] = ∂f_c/∂p.
template <class F>
struct ValueGradient {
    Rgb<F> value;
    F jacobian[3][kParamSlots];
};

template <Model model, class F>
PB_MODEL_INLINE ValueGradient<F> eval_gradient(const Geometry<F>& g, const Shading<F>& s, const View<F>& view,
                                               const MaterialPartials<F>& d) {
    const F one(1.0);
    const LobeValues<F> lobes = eval_lobes<model>(g, s, view);
    const F fh = lobes.fh, one_minus_fh = one_minus_schlick_weight(g);
    // D, S, C per unit clearcoat, with their partials
    const DiffusePartials<F> diffuse = diffuse_partials(s.diffuse, g, Fresnel<F>{schlick_weight(g.wi.z), view.fv, fh});
    const LogAlphaPartials<F> log_specular = s.specular.template log_value_partials<model>(g);
    F log_specular_roughness = mul_add(log_specular.sum, d.roughness_sum, log_specular.difference * d.roughness_difference);
    if constexpr (model == Model::kDisney2012)
        log_specular_roughness = mul_add(s.specular.log_value_partial_alpha_g2(g), d.alpha_g2_roughness, log_specular_roughness);
    const F log_specular_anisotropic =
            mul_add(log_specular.sum, d.anisotropic_sum, log_specular.difference * d.anisotropic_difference);
    const F specular_roughness = lobes.specular * log_specular_roughness;
    const F specular_anisotropic = lobes.specular * log_specular_anisotropic;
    const F clearcoat_unit = s.clearcoat.unit_value(g, fh);
    const F clearcoat_gloss = F(4.0) * s.clearcoat.lobe_weight * clearcoat_unit *
                              s.clearcoat.gtr1.log_d_partial_alpha2(g) * d.clearcoat_alpha2_gloss;

    const F specular_tinted = lobes.specular * one_minus_fh;  // T
    const Rgb<F> dc = s.diffuse.color, f0 = s.specular.f0;
    ValueGradient<F> out;
    out.value = lobes.total(s);
    for (int c = 0; c < 3; ++c) {
        auto at = [c](const Rgb<F>& colour) { return c == 0 ? colour.r : c == 1 ? colour.g : colour.b; };
        F* row = out.jacobian[c];
        // the colours' parameters: D ∂dc + FH ∂sc + T ∂f0
        for (int p : {kBaseColorR, kBaseColorG, kBaseColorB, kMetallic, kSpecular, kSpecularTint, kSheen, kSheenTint})
            row[p] = mul_add(lobes.diffuse, at(d.diffuse.slot[p]), mul_add(fh, at(d.sheen.slot[p]), specular_tinted * at(d.f0.slot[p])));
        const F specular_factor = mul_add(one_minus_fh, at(f0), fh);  // ∂f_c/∂S = (1 - FH) f0_c + FH
        row[kSubsurface] = diffuse.subsurface * at(dc);
        row[kRoughness] = mul_add(diffuse.roughness, at(dc), specular_roughness * specular_factor);
        row[kAnisotropic] = specular_anisotropic * specular_factor;
        row[kClearcoat] = clearcoat_unit;
        row[kClearcoatGloss] = clearcoat_gloss;
    }
    return out;
}
