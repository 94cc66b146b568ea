// Part of kernel.hpp, included inside the per-arch namespace: a batch's material
// parameters, loaded from the per-element arrays or broadcast from the uniform
// values. The model's shading_of turns them into the lobes' constants (per call
// when uniform, per batch otherwise).
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

PB_KERNEL_INLINE Shading<Floats> shading_of(const RawMaterial& m) { return shading_of(m.slot); }

// For a uniform material, once per call (model/energy.hpp): the energy
// table's two rows about its r_eff blended into one (values and slopes, so
// linear in r like the lookup of two rows), so that a lookup reads one
// interval instead of two. The lobe reads `values` from then on.
struct BlendedEnergyRow {
    alignas(64) float values[2 * 64];  // laid out by row_value_at and row_slope_at (simd_ops.hpp)

    PB_KERNEL_INLINE void use_for(MultipleScatteringLobe<Floats>& ms) {
        alignas(64) std::int32_t offset[kLanes];
        alignas(64) float fraction[kLanes];
        ms.row.offset.store_aligned(offset);
        ms.row.fraction.store_aligned(fraction);
        fill(ms.missing + 2 * offset[0], fraction[0]);
        ms.missing = values;
        ms.single_row = true;
    }

    // The row at below ((value, slope) an interval) blended with the next one by t.
    // Out of line: it runs once per call, and its loop then stays out of the
    // batch loops' functions, whose largest loop bench/loop_asm.py reports.
    __attribute__((noinline)) void fill(const float* below, float t) {
        const float* above = below + 2 * energy::kIntervals;
        auto blend = [&](int at) { return below[at] * (1.0f - t) + above[at] * t; };
        for (int b = 0; b < 64; ++b) {  // the slots past the last interval (μ = 1, flat) repeat it
            int interval = std::min(b, energy::kIntervals - 1);
            values[row_value_at(b)] = blend(2 * interval);
            values[row_slope_at(b)] = blend(2 * interval + 1);
        }
    }
};
