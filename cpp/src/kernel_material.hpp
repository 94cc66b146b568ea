// Part of kernel.hpp, included inside the per-arch namespace: the material constants of README "The model" (per call when uniform, per batch otherwise).
#pragma once  // (per translation unit)

// The 13 parameter slots of one batch of elements.
struct RawMaterial {
    Floats slot[kParamSlots];
};

PB_KERNEL_INLINE RawMaterial load_material(const ParamSlot* params, std::int64_t i) {
    RawMaterial m;
    const ParamSlot& red = params[kBaseColorR];
    if (red.per_element() && red.stride == 3) {
        load_interleaved(red.data + 3 * i, m.slot[kBaseColorR], m.slot[kBaseColorG], m.slot[kBaseColorB]);
    } else {
        for (int s = kBaseColorR; s <= kBaseColorB; ++s) {
            const ParamSlot& p = params[s];
            m.slot[s] = p.per_element() ? Floats::load_unaligned(p.data + i) : Floats(p.value);
        }
    }
    for (int s = kMetallic; s < kParamSlots; ++s) {
        const ParamSlot& p = params[s];
        m.slot[s] = p.per_element() ? Floats::load_unaligned(p.data + i) : Floats(p.value);
    }
    return m;
}

// What the lobes need of a material, independent of the directions: computed
// once per call for a uniform material, per batch otherwise.
struct Shading {
    Rgb diffuse_color;  // base_color (1 - metallic) / π
    Floats subsurface;
    Floats roughness;
    Rgb sheen_color;    // sheen Csheen (1 - metallic)
    Rgb specular_f0;    // Cspec0
    Floats inv_alpha_x2, inv_alpha_y2, ggx_norm;  // GTR2 aniso: 1/ax², 1/ay², 1/(π ax ay)
    Floats alpha_x2, alpha_y2;                     // Smith (2014): ax², ay²
    Floats alpha_g2;                               // Smith (2012): alpha_g²
    Floats clearcoat_scale;                        // 0.25 clearcoat (ac² - 1) / (π ln ac²)
    Floats clearcoat_alpha2;                       // ac²
    // Sampling (README "Sampling and pdf")
    Floats alpha_x, alpha_y;
    Floats gtr1_norm;                  // (ac² - 1) / (π ln ac²)
    Floats clearcoat_log_alpha2;       // ln ac²
    Floats clearcoat_sin2_scale;       // ac² / (1 - ac²)
    Floats cosine_lobe_weight;         // w0 = (1 - metallic) (Cdlum + 0.1 sheen lum(Csheen))
    Floats specular_f0_luminance;      // lum(Cspec0)
    Floats clearcoat_lobe_weight;      // 0.25 clearcoat
};

PB_KERNEL_INLINE Floats luminance_of(const Rgb& c) { return mul_add(Floats(0.3f), c.r, mul_add(Floats(0.6f), c.g, 0.1f * c.b)); }

PB_KERNEL_INLINE Shading shading_of(const RawMaterial& m) {
    const Floats* p = m.slot;
    const Floats one(1.0f);
    const Rgb base{p[kBaseColorR], p[kBaseColorG], p[kBaseColorB]};
    const Floats metallic = p[kMetallic];
    const Floats dielectric = one - metallic;

    // Ctint: hue and saturation at unit luminance (1 where the luminance is 0)
    const Floats luminance = luminance_of(base);
    const Mask has_luminance = luminance > Floats(0.0f);
    const Floats inv_luminance = reciprocal(xsimd::select(has_luminance, luminance, one));
    const Rgb tint{xsimd::select(has_luminance, base.r * inv_luminance, one),
                   xsimd::select(has_luminance, base.g * inv_luminance, one),
                   xsimd::select(has_luminance, base.b * inv_luminance, one)};
    const Rgb white{one, one, one};

    Shading s;
    s.diffuse_color = (dielectric * kInvPi) * base;
    s.subsurface = p[kSubsurface];
    s.roughness = p[kRoughness];
    const Rgb sheen_tint = mix(white, tint, p[kSheenTint]);
    s.sheen_color = (p[kSheen] * dielectric) * sheen_tint;
    s.specular_f0 = mix((p[kSpecular] * 0.08f) * mix(white, tint, p[kSpecularTint]), base, metallic);

    // 2014 addenda: aspect = sqrt(1 - 0.9 anisotropic), alpha = roughness²
    const Floats aspect2 = neg_mul_add(Floats(0.9f), p[kAnisotropic], one);  // in [0.1, 1]
    const Floats inv_aspect = reciprocal_sqrt(aspect2);
    const Floats aspect = aspect2 * inv_aspect;
    const Floats alpha = p[kRoughness] * p[kRoughness];
    const Floats alpha_x = xsimd::max(Floats(0.001f), alpha * inv_aspect);
    const Floats alpha_y = xsimd::max(Floats(0.001f), alpha * aspect);
    s.alpha_x2 = alpha_x * alpha_x;
    s.alpha_y2 = alpha_y * alpha_y;
    s.inv_alpha_x2 = reciprocal(s.alpha_x2);
    s.inv_alpha_y2 = reciprocal(s.alpha_y2);
    s.ggx_norm = kInvPi * reciprocal(alpha_x * alpha_y);
    const Floats alpha_g = mul_add(Floats(0.5f), p[kRoughness], Floats(0.5f));
    s.alpha_g2 = (alpha_g * alpha_g) * (alpha_g * alpha_g);

    // GTR1 with ac = mix(0.1, 0.001, clearcoat_gloss); ac stays in [0.001, 0.1]
    const Floats clearcoat_alpha = mix(Floats(0.1f), Floats(0.001f), p[kClearcoatGloss]);
    s.clearcoat_alpha2 = clearcoat_alpha * clearcoat_alpha;
    s.clearcoat_log_alpha2 = xsimd::log(s.clearcoat_alpha2);
    s.gtr1_norm = kInvPi * (s.clearcoat_alpha2 - one) * reciprocal(s.clearcoat_log_alpha2);
    s.clearcoat_scale = 0.25f * p[kClearcoat] * s.gtr1_norm;
    s.clearcoat_sin2_scale = s.clearcoat_alpha2 * reciprocal(one - s.clearcoat_alpha2);

    s.alpha_x = alpha_x;
    s.alpha_y = alpha_y;
    s.cosine_lobe_weight = dielectric * mul_add(0.1f * p[kSheen], luminance_of(sheen_tint), luminance);
    s.specular_f0_luminance = luminance_of(s.specular_f0);
    s.clearcoat_lobe_weight = 0.25f * p[kClearcoat];
    return s;
}

