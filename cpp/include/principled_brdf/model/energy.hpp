// Part of the model (docs/model.md "Energy compensation"): the multiple-
// scattering lobe of the primary specular (Kulla & Conty 2017), over a number
// type F. The tables of principled_brdf/energy_tables.hpp hold the lobe's
// missing energy 1 - E(μ; r) and 1 - E_avg(r) per model (2014 and 2012 differ
// in Gs); with F_avg = (20 Cspec0 + 1) / 21 (the hemispherical average of
// Schlick's Fresnel with F90 = 1, exact) per channel,
//   f_ms = F_avg² E_avg / (1 - F_avg (1 - E_avg)) · (1 - E(μl)) (1 - E(μo)) / (π (1 - E_avg))
// (Kulla & Conty 2017, "Revisiting Physically Based Shading at Imageworks":
// the compensation lobe, tinted by its Fresnel term). It is reciprocal and
// has no φ dependence; anisotropic materials read the isotropic tables at
// r_eff = (ax ay)^(1/4), which for ax = r² / aspect, ay = r² aspect is the
// roughness itself (the 0.001 floors aside, where 1 - E is below 1e-5).
// Sampling draws it by the cosine lobe, its weight the lobe's albedo at wo,
//   ∫ f_ms cos θl dωl = lum(F_avg² E_avg / (1 - F_avg (1 - E_avg))) (1 - E(μo))
// (since 2 ∫ (1 - E(μ)) μ dμ = 1 - E_avg), added to the cosine lobe's w0.
// The ops of the number type provide truncate_to_index (x >= 0), index_to_real,
// gather_pair_in_row ((row[index], row[index + 1]) per lane from a row of
// intervals + 1 nodes that every lane shares, a blended row of 1 - E or the
// table of 1 - E_avg, which the AVX-512 kernel reads by register permutes
// instead of gathers) and gather_corners (the four nodes about a point of
// the 1 - E table, energy_corners.hpp).
#pragma once  // (per namespace that includes the model)

// The nodes' spacings are powers of two, so that μ (kCosines - 1) and
// r (kRoughnesses - 1) are exact in float32 and so are the interpolation weights:
// the float32 lookup then differs from the float64 one by the blend's roundings
// alone, also where 1 - E is small and steep between nodes.
static_assert(((energy::kCosines - 1) & (energy::kCosines - 2)) == 0, "kCosines - 1 is a power of two");
static_assert(((energy::kRoughnesses - 1) & (energy::kRoughnesses - 2)) == 0, "kRoughnesses - 1 is a power of two");

template <class F>
using IndexOf = decltype(truncate_to_index(F()));

// Where a material's roughness falls between the tables' rows.
template <class F>
struct EnergyRow {
    IndexOf<F> offset;  // j kCosines: the row below r_eff
    F fraction;         // r_eff's position between rows j and j + 1
};

template <class F>
struct MultipleScatteringLobe {
    const float* missing;  // the model's 1 - E table, or one row of it (single_row)
    const float* corners;  // the same table by corners (energy_corners.hpp), which the lookup reads otherwise
    EnergyRow<F> row;
    bool single_row = false;  // missing is 1 - E at r_eff already, blended between the rows (a uniform material)
    Rgb<F> color;          // F_avg² E_avg / (1 - F_avg (1 - E_avg)) / (π (1 - E_avg))
    F albedo_scale;        // lum(F_avg² E_avg / (1 - F_avg (1 - E_avg))): w3 = albedo_scale (1 - E(μo))

    // 1 - E(μ) at r_eff: bilinear, linear in μ between the nodes μ_k = k / (kCosines - 1)
    PB_MODEL_INLINE F missing_energy(F mu) const {
        const F x = min(max(mu, F(0.0)), F(1.0)) * F(energy::kCosines - 1);
        const IndexOf<F> k = min(truncate_to_index(x), IndexOf<F>(energy::kCosines - 2));
        const F t = x - index_to_real(k);
        if (single_row) {
            const auto [at_k, at_next] = gather_pair_in_row<energy::kCosines - 1>(missing, k);
            return mix(at_k, at_next, t);
        }
        const auto [below_k, below_next, above_k, above_next] = gather_corners(corners, row.offset + k);
        return mix(mix(below_k, below_next, t), mix(above_k, above_next, t), row.fraction);
    }

    // the scalar factor of color: (1 - E(μl)) (1 - E(μo)), 1 - E(μo) given
    PB_MODEL_INLINE F value(const Geometry<F>& g, F missing_wo) const { return missing_energy(g.wi.z) * missing_wo; }

    Rgb<F> rgb(F value) const { return value * color; }

    // f + f_ms, one rounding a channel
    PB_MODEL_INLINE Rgb<F> added_to(const Rgb<F>& f, F value) const {
        return {mul_add(value, color.r, f.r), mul_add(value, color.g, f.g), mul_add(value, color.b, f.b)};
    }

    // w3 at wo, from 1 - E(μo)
    PB_MODEL_INLINE F weight(F missing_wo) const { return albedo_scale * missing_wo; }
};

// For a material of kParamSlots values (params.hpp's order) and its Shading.
template <class F>
PB_MODEL_INLINE MultipleScatteringLobe<F> multiple_scattering_of(const F* p, const Shading<F>& s, Model model) {
    const F one(1.0);
    MultipleScatteringLobe<F> ms;
    ms.missing = energy::kMissing[static_cast<int>(model)];
    ms.corners = energy::kMissingCorners[static_cast<int>(model)];
    // r_eff clamped to the tables' [0, 1]
    const F y = min(max(p[kRoughness], F(0.0)), one) * F(energy::kRoughnesses - 1);
    const IndexOf<F> j = min(truncate_to_index(y), IndexOf<F>(energy::kRoughnesses - 2));
    ms.row = {truncate_to_index(index_to_real(j) * F(energy::kCosines)), y - index_to_real(j)};
    const float* average = energy::kMissingAverage[static_cast<int>(model)];
    const auto [average_j, average_next] = gather_pair_in_row<energy::kRoughnesses - 1>(average, j);
    const F missing_average = mix(average_j, average_next, ms.row.fraction);
    const F e_average = one - missing_average;
    // F_avg = (20 Cspec0 + 1) / 21 per channel, at most 1 (Cspec0 > 1 for a base_color or
    // specular past the physical range, where 1 - F_avg (1 - E_avg) could reach 0)
    auto factor = [&](F f0) {
        const F f_avg = min(mul_add(F(20.0 / 21.0), f0, F(1.0 / 21.0)), F(1.0));
        return f_avg * f_avg * e_average * reciprocal(neg_mul_add(f_avg, missing_average, one));
    };
    const Rgb<F> tint{factor(s.specular.f0.r), factor(s.specular.f0.g), factor(s.specular.f0.b)};
    ms.albedo_scale = luminance_of(tint);
    const F norm = F(kInvPi) * reciprocal(max(missing_average, F(1e-7)));
    ms.color = norm * tint;
    return ms;
}

// The material with w3 at wo added to the cosine lobe's weight w0: the
// mixture's choice, pdf and 1 / Σ w then include the multiple-scattering lobe
// (drawn, like the diffuse, by cos θl / π).
template <class F>
PB_MODEL_INLINE Shading<F> with_multiple_scattering_weight(const Shading<F>& s, F w3) {
    Shading<F> c = s;
    c.diffuse.cosine_lobe_weight = s.diffuse.cosine_lobe_weight + w3;
    return c;
}

// A sample weighed with the lobe: weigh() of principled.hpp for the material of
// with_multiple_scattering_weight (its pdf includes w3), plus the lobe's share
// select(valid, scale f_ms, 0) in the weight.
template <class F>
struct CompensatedWeighed {
    Weighed<F> weighed;
    Rgb<F> multiple_scattering;  // f_ms, unmasked
};

template <Model model, class F>
PB_MODEL_INLINE CompensatedWeighed<F> weigh_compensated(const Vec3<F>& wo, F fv, const LobeWeights<F>& weights,
                                                        const Direction<F>& drawn, const Shading<F>& compensated,
                                                        const MultipleScatteringLobe<F>& ms, F missing_wo,
                                                        SpecularSampler sampler) {
    CompensatedWeighed<F> out;
    out.weighed = weigh<model>(wo, fv, weights, drawn, compensated, sampler);
    Weighed<F>& w = out.weighed;
    const Geometry<F> g = geometry_of(drawn.wi, wo);
    out.multiple_scattering = ms.rgb(ms.value(g, missing_wo));
    const Rgb<F> share = w.share(out.multiple_scattering);
    w.weight = {w.weight.r + share.r, w.weight.g + share.g, w.weight.b + share.b};
    return out;
}
