// The counter-based random generator of docs/sampling.md: uniform u_k for element i
// and seed s is a pure function of (s, i, k), so samples do not depend on
// threads, chunking or SIMD width.
//
//   key(s, h) = lowbias32(lowbias32(lowbias32(lo32(s) + 0x9E3779B9) + hi32(s)) + 0x632BE5AB h)
//   x         = lowbias32((3 lo32(i) + k) 0x9E3779B9 ^ key(s, hi32(i)))     (mod 2^32)
//   u_k       = (x >> 8) 2^-24                                   in [0, 1), 24 random bits
//
// Each element owns the three counter values 3 i + k, so the three streams of
// one call never reuse an input of the hash closer than 2^32 / 3 elements
// apart. The counter is spread by the golden-ratio multiplier (a Weyl
// sequence) before the hash: lowbias32 of plain consecutive counters fails a
// 256-bin uniformity test at 2^20 values, this passes it and the 2-D and 3-D
// tests of tests/sampling/test_simd_sampler.py. The key depends only on the seed and
// the high half of the index, so for a batch of lanes it is one scalar, and
// so is the first lane's spread counter (the others add a constant); a lane
// costs one hash (two multiplies) per uniform.
//
// lowbias32 is Chris Wellons' 32-bit integer hash (two multiply-xorshift
// rounds, a bijection). Included inside a namespace by each user (kernel.hpp
// per instruction set, batch.cpp for the baseline), which must provide
// multiply_low(U, std::uint32_t) for its integer type U.
#pragma once  // (per translation unit)

constexpr std::uint32_t multiply_low(std::uint32_t a, std::uint32_t b) { return a * b; }

constexpr std::uint32_t kGolden = 0x9E3779B9u;  // 2^32 / golden ratio

// lowbias32 after its first step x ^= x >> 16 (which the SIMD generator folds
// into its key, see counter_uniforms)
template <class U>
PB_KERNEL_INLINE U lowbias32_rounds(U x) {
    x = multiply_low(x, 0x7feb352du);
    x = x ^ (x >> 15);
    x = multiply_low(x, 0x846ca68bu);
    return x ^ (x >> 16);
}

template <class U>
PB_KERNEL_INLINE U lowbias32(U x) {
    return lowbias32_rounds(x ^ (x >> 16));
}

// What the key needs of the seed, computed once per call.
struct CounterSeed {
    std::uint32_t mixed;  // lowbias32(lowbias32(lo32(s) + 0x9E3779B9) + hi32(s))
};

inline CounterSeed counter_seed(std::uint64_t seed) {
    const std::uint32_t low = lowbias32(static_cast<std::uint32_t>(seed) + kGolden);
    return {lowbias32(low + static_cast<std::uint32_t>(seed >> 32))};
}

// key(s, h) of the header comment
inline std::uint32_t counter_key(const CounterSeed& seed, std::uint32_t index_high) {
    return lowbias32(seed.mixed + 0x632BE5ABu * index_high);
}

// 3 lo32(i) 0x9E3779B9, shared by the three counters of element i
template <class U>
PB_KERNEL_INLINE constexpr U spread_counter(U index_low) {
    return multiply_low(index_low, 3u * kGolden);
}

// x of the header comment, given spread_counter(lo32(i)) and the key of hi32(i)
template <class U>
PB_KERNEL_INLINE U counter_bits(U spread, std::uint32_t key, int k) {
    return lowbias32((spread + U(static_cast<std::uint32_t>(k) * kGolden)) ^ U(key));
}

inline float counter_uniform(std::uint64_t index, const CounterSeed& seed, int k) {
    const std::uint32_t key = counter_key(seed, static_cast<std::uint32_t>(index >> 32));
    const std::uint32_t spread = spread_counter(static_cast<std::uint32_t>(index));
    const std::uint32_t bits = counter_bits<std::uint32_t>(spread, key, k);
    return static_cast<float>(bits >> 8) * 0x1p-24f;
}
