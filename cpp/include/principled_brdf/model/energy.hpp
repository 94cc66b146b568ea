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
// energy_interval (the interval of ν = μ + 1/8, the exact sum, that holds a
// lane, 16 an octave from 1/8, and that interval's end: ν's exponent and top
// four mantissa bits, plus one; no division), value_and_slope_in_row (an interval's
// value and slope from a blended row that every lane shares, which the AVX-512
// kernel reads by register permutes instead of gathers), gather_pair_in_row
// ((row[index], row[index + 1]) from a row of intervals + 1 nodes, the table
// of 1 - E_avg) and gather_corners (an interval's value and slope in two
// adjacent rows of the 1 - E table at once, energy_corners.hpp).
#pragma once  // once per translation unit: included only by model.hpp, which allows one namespace

// The roughness rows' spacing is a power of two, so that r (kRoughnesses - 1)
// is exact in float32 and so is the interpolation weight between rows; within
// an interval, μ - μ_b+1 is exact (μ_b+1 = ν_b+1 - 1/8 has few bits), and the
// interval is the exact sum's (the lines meet at its ends, but near μ = 1 at low
// roughness a line continued one ulp past its end errs by 2e-3): the float32 lookup
// then differs from the float64 one by its roundings alone, also where 1 - E
// is small and steep (near μ = 1 at low roughness in the 2012 model, where a
// rounded μ would move it by 1e-4 of itself). Each line is written from its
// interval's end, where 1 - E is the smaller near μ = 1: from the start, it
// would there be the difference of nearly equal terms. (The kernels write a
// uniform material's blended row from μ = 0 in the 2014 model, whose lines
// cancel little there: kRowFromZero, energy_intercepts.hpp.)
static_assert(((energy::kRoughnesses - 1) & (energy::kRoughnesses - 2)) == 0, "kRoughnesses - 1 is a power of two");
static_assert(energy::kIntervalsPerOctave == 16 && energy::kIntervals == 51, "3 octaves of ν from 1/8, [1, 1 + 1/8], then μ = 1");

template <class F>
using IndexOf = decltype(truncate_to_index(F()));

// Where a material's roughness falls between the tables' rows.
template <class F>
struct EnergyRow {
    IndexOf<F> offset;  // j kIntervals: the row below r_eff
    F fraction;         // r_eff's position between rows j and j + 1
};

// How missing_energy reads its table: two rows by corners (the float64 path and
// per-element materials), or one row blended between them (a uniform
// material), its lines written from each interval's end like the table's, or
// from μ = 0 (energy_intercepts.hpp).
enum class EnergyLookup { kCorners, kRowFromEnd, kRowFromZero };

template <class F>
struct MultipleScatteringLobe {
    const float* missing;  // the model's 1 - E table, or one blended row of it (lookup != kCorners)
    const float* corners;  // the same table by corners (energy_corners.hpp), which the lookup reads otherwise
    EnergyRow<F> row;
    EnergyLookup lookup = EnergyLookup::kCorners;
    Rgb<F> color;          // F_avg² E_avg / (1 - F_avg (1 - E_avg)) / (π (1 - E_avg))
    F albedo_scale;        // lum(F_avg² E_avg / (1 - F_avg (1 - E_avg))): w3 = albedo_scale (1 - E(μo))

    // 1 - E(μ) at r_eff: linear in μ within each interval, linear in r between the rows
    // (for μ in [0, 1 + 1/16); below the surface, where the lobe is discarded, some finite value)
    PB_MODEL_INLINE F missing_energy(F mu) const {
        const auto [interval, end] = energy_interval(mu);
        if (lookup == EnergyLookup::kRowFromZero) {  // value at μ = 0: no interval end, no offset
            const auto [value, slope] = value_and_slope_in_row(missing, interval);
            return mul_add(mu, slope, value);
        }
        F along = mu - (end - F(energy::kCosineOffset));  // <= 0
        if (lookup == EnergyLookup::kRowFromEnd) {
            const auto [value, slope] = value_and_slope_in_row(missing, interval);
            return mul_add(along, slope, value);
        }
        const auto [below, below_slope, above, above_slope] = gather_corners(corners, row.offset, interval);
        return mix(mul_add(along, below_slope, below), mul_add(along, above_slope, above), row.fraction);
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
    F one(1.0);
    MultipleScatteringLobe<F> ms;
    const int table = row_of(model).energy_table;
    ms.missing = energy::kMissing[table];
    ms.corners = energy::kMissingCorners[table];
    // r_eff clamped to the tables' [0, 1]
    F y = min(max(p[kRoughness], F(0.0)), one) * F(energy::kRoughnesses - 1);
    IndexOf<F> j = min(truncate_to_index(y), IndexOf<F>(energy::kRoughnesses - 2));
    ms.row = {truncate_to_index(index_to_real(j) * F(energy::kIntervals)), y - index_to_real(j)};
    const float* average = energy::kMissingAverage[table];
    const auto [average_j, average_next] = gather_pair_in_row<energy::kRoughnesses - 1>(average, j);
    F missing_average = mix(average_j, average_next, ms.row.fraction);
    F e_average = one - missing_average;
    // F_avg = (20 Cspec0 + 1) / 21 per channel, at most 1 (Cspec0 > 1 for a base_color or
    // specular past the physical range, where 1 - F_avg (1 - E_avg) could reach 0)
    auto factor = [&](F f0) {
        F f_avg = min(mul_add(F(20.0 / 21.0), f0, F(1.0 / 21.0)), F(1.0));
        return f_avg * f_avg * e_average / neg_mul_add(f_avg, missing_average, one);
    };
    Rgb<F> tint{factor(s.specular.f0.r), factor(s.specular.f0.g), factor(s.specular.f0.b)};
    ms.albedo_scale = luminance_of(tint);
    F norm = F(kInvPi) / max(missing_average, F(1e-7));
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
    Geometry<F> g = geometry_of(drawn.wi, wo);
    out.multiple_scattering = ms.rgb(ms.value(g, missing_wo));
    Rgb<F> share = w.share(out.multiple_scattering);
    w.weight = {w.weight.r + share.r, w.weight.g + share.g, w.weight.b + share.b};
    return out;
}
