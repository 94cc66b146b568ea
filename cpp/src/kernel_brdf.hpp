// Part of kernel.hpp, included inside the per-arch namespace: the lobes of README "The model" on the unnormalised half vector.
#pragma once  // (per translation unit)

// n·w + sqrt(q), the denominator of the Smith factor S(w) = G1(w) / (2 n·w)
// of README "The model", given q = (w·x ax)² + (w·y ay)² + (n·w)². Products of these
// share one reciprocal.
PB_KERNEL_INLINE Floats smith_denominator(Floats cos_theta, Floats q) { return mul_add(q, reciprocal_sqrt(q), cos_theta); }

// Isotropic form for alpha² = a2 < 1 (the clearcoat's): q = a2 + cos²(1 - a2),
// both terms >= 0.
PB_KERNEL_INLINE Floats smith_denominator_iso(Floats cos_theta, Floats a2) {
    return smith_denominator(cos_theta, mul_add(cos_theta * cos_theta, Floats(1.0f) - a2, a2));
}

// Isotropic form for any alpha² = a2 (the 2012 model's alpha_g² reaches 10^15 at
// roughness 10^4): q = a2 ((w·x)² + (w·y)²) + (n·w)², where the form above
// cancels to 0.
PB_KERNEL_INLINE Floats smith_denominator_iso(const Vec3& w, Floats a2) {
    return smith_denominator(w.z, mul_add(a2, mul_add(w.x, w.x, w.y * w.y), w.z * w.z));
}

// The lobes as scalar factors of the material's colours (README "The model"):
//   diffuse   = D  base_color (1 - metallic) / π        (s.diffuse_color)
//   sheen     = FH sheen Csheen (1 - metallic)          (s.sheen_color)
//   specular  = S  mix(Cspec0, 1, FH),  S = Gs Ds
//   clearcoat = C  (grey)
struct LobeValues {
    Floats diffuse, fh, specular, clearcoat;
    Mask finite_half_vector;  // false where a direction held NaN or infinity (checks off)

    Rgb diffuse_rgb(const Shading& s) const { return diffuse * s.diffuse_color; }
    Rgb sheen_rgb(const Shading& s) const { return fh * s.sheen_color; }
    Rgb specular_rgb(const Shading& s) const { return specular * mix(s.specular_f0, Rgb{Floats(1.0f), Floats(1.0f), Floats(1.0f)}, fh); }

    // f per channel: D dc + FH sc + S (1 - FH) Cspec0 + (S FH + C), three FMAs a channel
    Rgb total(const Shading& s) const {
        const Floats specular_tinted = specular * (Floats(1.0f) - fh);
        const Floats grey = mul_add(specular, fh, clearcoat);
        auto channel = [&](Floats dc, Floats sc, Floats f0) {
            return mul_add(diffuse, dc, mul_add(fh, sc, mul_add(specular_tinted, f0, grey)));
        };
        return {channel(s.diffuse_color.r, s.sheen_color.r, s.specular_f0.r),
                channel(s.diffuse_color.g, s.sheen_color.g, s.specular_f0.g),
                channel(s.diffuse_color.b, s.sheen_color.b, s.specular_f0.b)};
    }
};

// What every lobe and pdf needs of a pair (wi, wo), through the unnormalised
// half vector H = wi + wo.
struct Geometry {
    Vec3 wi, wo;
    Floats hx2, hy2, hz, hz2;
    Floats h_len2;       // |H|²
    Floats cos_theta_d;  // |H| / 2 (= wi·h = wo·h for unit vectors)
    Floats one_minus_cos_theta_d;  // |wi - wo|² / (4 (1 + cos θd)): no cancellation as wi -> wo
    Mask finite;         // false where a direction held NaN or infinity (checks off)
};

PB_KERNEL_INLINE Geometry geometry_of(const Vec3& wi, const Vec3& wo) {
    Geometry g;
    g.wi = wi;
    g.wo = wo;
    const Floats hx = wi.x + wo.x, hy = wi.y + wo.y;
    g.hz = wi.z + wo.z;
    g.hx2 = hx * hx;
    g.hy2 = hy * hy;
    g.hz2 = g.hz * g.hz;
    g.h_len2 = g.hx2 + g.hy2 + g.hz2;
    g.finite = g.h_len2 <= Floats(std::numeric_limits<float>::max());
    g.cos_theta_d = 0.5f * g.h_len2 * reciprocal_sqrt(g.h_len2);
    const Floats dx = wi.x - wo.x, dy = wi.y - wo.y, dz = wi.z - wo.z;
    const Floats d_len2 = mul_add(dx, dx, mul_add(dy, dy, dz * dz));
    g.one_minus_cos_theta_d = d_len2 * reciprocal(mul_add(Floats(4.0f), g.cos_theta_d, Floats(4.0f)));
    return g;
}

// GTR2 aniso: Ds = 1/(π ax ay (hx²/ax² + hy²/ay² + hz²)²), with h = H/|H|
PB_KERNEL_INLINE Floats gtr2_aniso_d(const Geometry& g, const Shading& s) {
    const Floats stretched = mul_add(g.hx2, s.inv_alpha_x2, mul_add(g.hy2, s.inv_alpha_y2, g.hz2));
    const Floats ds_root = g.h_len2 * reciprocal(stretched);
    return s.ggx_norm * ds_root * ds_root;
}

// |H|² (ac² cos²θh + sin²θh): GTR1 is gtr1_norm |H|² over this
PB_KERNEL_INLINE Floats gtr1_denominator(const Geometry& g, const Shading& s) {
    return mul_add(s.clearcoat_alpha2, g.hz2, g.hx2 + g.hy2);
}

// What the lobes and the pdf need of wo alone.
struct View {
    Floats fv;                  // Schlick(cos θv)
    Floats smith_visible;       // cos θv + sqrt(q), q = (wo.x ax)² + (wo.y ay)² + cos²θv: the 2014 Smith
                                // denominator, and the visible-normal pdf's in both models
    Floats smith_specular;      // the model's Smith denominator for wo
    Floats smith_clearcoat;     // Smith denominator for wo at alpha 0.25 (1 when no lane has a clearcoat)
};

// given FV and the visible-normal Smith denominator (the sampling loop has them from
// the lobe choice and the draw)
template <Model model>
PB_KERNEL_INLINE View view_of(const Vec3& wo, const Shading& s, Floats smith_visible, Floats fv) {
    View v;
    v.fv = fv;
    v.smith_visible = smith_visible;
    if constexpr (model == Model::kDisney2012) {
        v.smith_specular = smith_denominator_iso(wo, s.alpha_g2);
    } else {
        v.smith_specular = v.smith_visible;
    }
    v.smith_clearcoat = Floats(1.0f);
    if (xsimd::any(s.clearcoat_scale != Floats(0.0f))) v.smith_clearcoat = smith_denominator_iso(wo.z, Floats(0.0625f));
    return v;
}

template <Model model>
PB_KERNEL_INLINE View view_of(const Vec3& wo, const Shading& s) {
    const Floats q = mul_add(s.alpha_x2, wo.x * wo.x, mul_add(s.alpha_y2, wo.y * wo.y, wo.z * wo.z));
    return view_of<model>(wo, s, smith_denominator(wo.z, q), schlick_weight(wo.z));
}

// Smith denominator of the 2014 model for wi: n·w + sqrt((w·x ax)² + (w·y ay)² + (n·w)²)
PB_KERNEL_INLINE Floats smith_denominator_aniso(const Vec3& w, const Shading& s) {
    return smith_denominator(w.z, mul_add(s.alpha_x2, w.x * w.x, mul_add(s.alpha_y2, w.y * w.y, w.z * w.z)));
}

template <Model model>
PB_KERNEL_INLINE LobeValues eval_lobes(const Geometry& g, const Shading& s, const View& view) {
    const Floats one(1.0f);
    const Vec3& wi = g.wi;
    const Floats cos_theta_l = wi.z, cos_theta_v = g.wo.z;
    const Floats cos2_theta_d = 0.25f * g.h_len2;
    LobeValues out;
    out.finite_half_vector = g.finite;

    const Floats fl = schlick_weight(cos_theta_l);
    const Floats fv = view.fv;
    const Floats fh = schlick_weight_of_complement(g.one_minus_cos_theta_d);

    // Diffuse: Fd = mix(1, Fd90, FL) mix(1, Fd90, FV), Fd90 = 0.5 + 2 roughness cos²θd
    const Floats fd90_minus_1 = mul_add(2.0f * s.roughness, cos2_theta_d, Floats(-0.5f));
    const Floats fd = mul_add(fd90_minus_1, fl, one) * mul_add(fd90_minus_1, fv, one);
    out.diffuse = fd;
    // Lobes whose weight is 0 in every lane are skipped: for a uniform material
    // the test has the same outcome for every batch, and the result is the same
    // bits (mix(fd, ss, 0) = fd, 0 clearcoat x finite = 0).
    if (xsimd::any(s.subsurface != Floats(0.0f))) {
        // Subsurface: ss = 1.25 (Fss (1/(cos θl + cos θv) - 0.5) + 0.5), Fss90 = roughness cos²θd
        const Floats fss90_minus_1 = mul_sub(s.roughness, cos2_theta_d, one);
        const Floats fss = mul_add(fss90_minus_1, fl, one) * mul_add(fss90_minus_1, fv, one);
        const Floats inv_cos_sum = reciprocal(cos_theta_l + cos_theta_v);
        const Floats ss = 1.25f * mul_add(fss, inv_cos_sum - 0.5f, Floats(0.5f));
        out.diffuse = mix(fd, ss, s.subsurface);
    }

    out.fh = fh;

    const Floats ds = gtr2_aniso_d(g, s);
    Floats gs_denominator;
    if constexpr (model == Model::kDisney2012) {
        gs_denominator = smith_denominator_iso(wi, s.alpha_g2) * view.smith_specular;
    } else {
        gs_denominator = smith_denominator_aniso(wi, s) * view.smith_specular;
    }
    out.specular = ds * reciprocal(gs_denominator);

    // Clearcoat 0.25 clearcoat Gr Fr Dr with GTR1 Dr = (ac² - 1)/(π ln ac²) / (ac² cos²θh + sin²θh)
    // (the constants are in clearcoat_scale) and Gr = S(wi) S(wo) at alpha 0.25.
    out.clearcoat = Floats(0.0f);
    if (xsimd::any(s.clearcoat_scale != Floats(0.0f))) {
        const Floats fr = mul_add(Floats(0.96f), fh, Floats(0.04f));
        const Floats quarter2 = Floats(0.0625f);
        const Floats gr_denominator = smith_denominator_iso(cos_theta_l, quarter2) * view.smith_clearcoat;
        out.clearcoat = s.clearcoat_scale * fr * g.h_len2 * reciprocal(gtr1_denominator(g, s) * gr_denominator);
    }
    return out;
}


// ---------------------------------------------------------------- pdf
// README "Sampling and pdf": the mixture of the cosine lobe, the primary
// specular and the clearcoat, with probabilities from the albedo estimates.

// The unnormalised weights w1, w2 at wo (w0 is the material's) and 1 / Σ w:
// the lobe choice compares u0 Σ w against them, so it does not wait for the
// reciprocal, and the pdf multiplies by it once.
struct LobeWeights {
    Floats specular, clearcoat, inv_total;
};

// w0 = (1 - metallic)(Cdlum + 0.1 sheen lum(Csheen)), w1 = max(lum(mix(Cspec0, 1, FV)), 0.02),
// w2 = 0.25 clearcoat mix(0.04, 1, FV); P_k = w_k / Σ w.
PB_KERNEL_INLINE LobeWeights lobe_weights(Floats fv, const Shading& s) {
    const Floats w1 = xsimd::max(mix(s.specular_f0_luminance, Floats(1.0f), fv), Floats(0.02f));
    const Floats w2 = s.clearcoat_lobe_weight * mul_add(Floats(0.96f), fv, Floats(0.04f));
    return {w1, w2, reciprocal(s.cosine_lobe_weight + w1 + w2)};
}

// Σ P_k pdf_k(wi), before the horizon test:
//   pdf0 = cos θl / π
//   pdf1 = G1(wo) Ds / (4 cos θv) = Ds / (2 (cos θv + sqrt(q_v)))   (visible normals)
//        = Ds cos θh / (4 cos θd) = Ds Hz / (2 |H|²)                (distribution)
//   pdf2 = Dr cos θh / (4 cos θd) = gtr1_norm Hz / (2 gtr1_denominator)
// with cos θh = Hz / |H| and cos θd = |H| / 2.
PB_KERNEL_INLINE Floats mixture_pdf(const Geometry& g, const Shading& s, const View& view, const LobeWeights& w,
                                    SpecularSampler sampler) {
    const Floats ds = gtr2_aniso_d(g, s);
    const Floats pdf1 = sampler == SpecularSampler::kDistribution
                            ? ds * g.hz * reciprocal(2.0f * g.h_len2)
                            : ds * reciprocal(2.0f * view.smith_visible);
    const Floats pdf2 = s.gtr1_norm * g.hz * reciprocal(2.0f * gtr1_denominator(g, s));
    return w.inv_total * mul_add(s.cosine_lobe_weight * kInvPi, g.wi.z, mul_add(w.specular, pdf1, w.clearcoat * pdf2));
}
