// Part of kernel.hpp, included inside the per-arch namespace: a batch's material
// parameters, loaded from the per-element arrays or broadcast from the uniform
// values. The model's shading_of turns them into the lobes' constants (per call
// when uniform, per batch otherwise).
#pragma once  // (per translation unit)

// The kParamSlots (16) parameter slots of one batch of elements.
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

PB_KERNEL_INLINE Shading<Floats> shading_of(const RawMaterial& m) { return shading_of(m.slot); }

// A model's constants for f, the pdf and the draw: the BRDFs' Shading, the 2015 models' Solid2015 or
// ThinSheet2015 (with the solid's energy compensation where `compensated`; the BRDFs' is their own type).
template <Model model>
PB_KERNEL_INLINE auto model_shading_of(const RawMaterial& m, bool compensated = false) {
    if constexpr (is_bsdf(model)) {
        return shading2015_of<Shading2015<model, Floats>>(m.slot, compensated);
    } else {
        return shading_of(m);
    }
}

// For a uniform material, once per call (model/energy.hpp): the energy
// table's two rows about its r_eff blended into one (values and slopes, so
// linear in r like the lookup of two rows), so that a lookup reads one
// interval instead of two. The lobe reads `values` from then on.
//
// For the 2014 model the blended row's lines are written from μ = 0, 1 - E =
// v0 + μ s (energy_intercepts.hpp), which spares each lookup the interval's
// end and μ's offset in it (four vector operations): every row of its table
// allows that (its worst cancellation 14.1, at roughness 0; tested). The 2012
// model's rows below roughness 23/64 = 0.36 do not (70,000 at roughness 1/32,
// where 1 - E falls from 5e-3 to 2e-6 over μ's last interval before 1), and
// its rows keep the lines from their ends. One form a model, fixed at compile
// time, so that a loop holds the code of one form only.
struct BlendedEnergyRow {
    alignas(64) float values[2 * 64];  // laid out by row_value_at and row_slope_at (simd_ops.hpp)

    template <Model model>
    PB_KERNEL_INLINE void use_for(MultipleScatteringLobe<Floats>& ms) {
        alignas(64) std::int32_t offset[kLanes];
        alignas(64) float fraction[kLanes];
        ms.row.offset.store_aligned(offset);
        ms.row.fraction.store_aligned(fraction);
        // one form a model (a constant the compiler carries into the loops, which then hold it alone)
        constexpr bool from_zero = model == Model::kDisney2014;
        ms.lookup = from_zero ? EnergyLookup::kRowFromZero : EnergyLookup::kRowFromEnd;
        fill((from_zero ? energy::kMissingIntercepts2014 : ms.missing) + 2 * offset[0], fraction[0]);
        ms.missing = values;
    }

    // The row at below ((value, slope) an interval) blended with the next one
    // by t, in float64 and rounded once. Out of line: it runs once per call,
    // and its loops then stay out of the batch loops' functions, whose largest
    // loop bench/loop_asm.py reports.
    __attribute__((noinline)) void fill(const float* below, float t) {
        const float* above = below + 2 * energy::kIntervals;
        const double weight = t, weight_below = 1.0 - weight;
        for (int b = 0; b < energy::kIntervals; ++b) {
            values[row_value_at(b)] = static_cast<float>(below[2 * b] * weight_below + above[2 * b] * weight);
            values[row_slope_at(b)] = static_cast<float>(below[2 * b + 1] * weight_below + above[2 * b + 1] * weight);
        }
        for (int b = energy::kIntervals; b < 64; ++b) {  // the slots past the last interval (μ = 1, flat) repeat it
            values[row_value_at(b)] = values[row_value_at(energy::kIntervals - 1)];
            values[row_slope_at(b)] = values[row_slope_at(energy::kIntervals - 1)];
        }
    }
};
