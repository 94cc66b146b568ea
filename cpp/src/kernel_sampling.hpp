// Part of kernel.hpp, included inside the per-arch namespace: the counter-based
// uniforms of docs/sampling.md (the draw itself is the model's).
#pragma once  // (per translation unit)

using UInts = xsimd::batch<std::uint32_t, Arch>;
using Ints = xsimd::batch<std::int32_t, Arch>;

// Low 32 bits of a 32 x 32-bit product (xsimd 8.1 has no native one for AVX-512).
#if defined(__AVX512F__)
PB_KERNEL_INLINE UInts multiply_low(UInts a, std::uint32_t b) { return _mm512_mullo_epi32(a, _mm512_set1_epi32(static_cast<int>(b))); }
#elif defined(__AVX2__)
PB_KERNEL_INLINE UInts multiply_low(UInts a, std::uint32_t b) { return _mm256_mullo_epi32(a, _mm256_set1_epi32(static_cast<int>(b))); }
#else
PB_KERNEL_INLINE UInts multiply_low(UInts a, std::uint32_t b) { return a * UInts(b); }
#endif

#include "counter_rng.hpp"


// The three counters of lane j, spread: spread_counter(j) + k 0x9E3779B9 for
// stream k. Those of a batch are the first element's spread counter plus
// these (the spread is linear mod 2^32): one add per stream instead of a
// 32-bit multiply.
struct LaneCounters {
    alignas(64) std::uint32_t lanes[3][kLanes];
    constexpr LaneCounters() : lanes{} {
        for (std::uint32_t k = 0; k < 3; ++k)
            for (std::int64_t j = 0; j < kLanes; ++j) lanes[k][j] = spread_counter(static_cast<std::uint32_t>(j)) + k * kGolden;
    }
};
inline constexpr LaneCounters kLaneCounters{};

// The top 24 bits of x as a float in [0, 1): (x >> 8) 2^-24. On AVX-512 as
// (x & ~0xFF) 2^-32 with an unsigned conversion, which fuses with the hash's
// last xor into one three-input logic op.
PB_KERNEL_INLINE Floats unit_interval(UInts x) {
#if defined(__AVX512F__)
    return Floats(_mm512_cvtepu32_ps(x & UInts(0xFFFFFF00u))) * 0x1p-32f;
#else
    return xsimd::to_float(xsimd::bitwise_cast<Ints>(x >> 8)) * 0x1p-24f;
#endif
}

// u_k for elements first + 0 .. first + kLanes - 1; first is a multiple of
// kLanes, so the low 32 bits never carry into the high ones within a batch.
// lowbias32's first step of c ^ key, y ^ (y >> 16) with y = c ^ key, is
// c ^ (c >> 16) ^ (key ^ (key >> 16)) (a logical shift distributes over ^):
// the key's part is one scalar and the rest fuses into one op on AVX-512.
PB_KERNEL_INLINE Uniforms<Floats> counter_uniforms(std::uint64_t first, const CounterSeed& seed) {
    const std::uint32_t key = counter_key(seed, static_cast<std::uint32_t>(first >> 32));
    UInts key_shifted_in(key ^ (key >> 16));
    UInts first_spread(spread_counter(static_cast<std::uint32_t>(first)));
    Floats u[3];
    for (int k = 0; k < 3; ++k) {
        UInts counter = UInts::load_aligned(kLaneCounters.lanes[k]) + first_spread;
        u[k] = unit_interval(lowbias32_rounds(counter ^ key_shifted_in ^ (counter >> 16)));
    }
    return {u[0], u[1], u[2]};
}
