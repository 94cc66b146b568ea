// The counter-based random generator of SPEC §5: uniform u_k for element i
// and seed s is a pure function of (s, i, k), so samples do not depend on
// threads, chunking or SIMD width.
//
//   A_k = lowbias32(lo32(s) + 0x9E3779B9 (k + 1)),  B_k = lowbias32(hi32(s) + 0x632BE5AB (k + 1))
//   x   = lowbias32(lowbias32(lo32(i) ^ A_k) + (hi32(i) ^ B_k))
//   u_k   = (x >> 8) 2^-24                       in [0, 1), 24 random bits
//
// lowbias32 is Chris Wellons' 32-bit integer hash (two multiply-xorshift
// rounds). Included inside a namespace by each user (kernel.hpp per
// instruction set, batch.cpp for the baseline), which must provide
// multiply_low(U, std::uint32_t) for its integer type U.
#pragma once  // (per translation unit)

struct CounterKeys {
    std::uint32_t low[3], high[3];
};

inline std::uint32_t multiply_low(std::uint32_t a, std::uint32_t b) { return a * b; }

template <class U>
PB_KERNEL_INLINE U lowbias32(U x) {
    x = x ^ (x >> 16);
    x = multiply_low(x, 0x7feb352du);
    x = x ^ (x >> 15);
    x = multiply_low(x, 0x846ca68bu);
    return x ^ (x >> 16);
}

inline CounterKeys counter_keys(std::uint64_t seed) {
    CounterKeys keys;
    for (std::uint32_t k = 0; k < 3; ++k) {
        keys.low[k] = lowbias32(static_cast<std::uint32_t>(seed) + 0x9E3779B9u * (k + 1));
        keys.high[k] = lowbias32(static_cast<std::uint32_t>(seed >> 32) + 0x632BE5ABu * (k + 1));
    }
    return keys;
}

// x of the header comment for element indices whose low and high 32-bit halves are given.
template <class U>
PB_KERNEL_INLINE U counter_bits(U index_low, std::uint32_t index_high, const CounterKeys& keys, int k) {
    return lowbias32(lowbias32(index_low ^ U(keys.low[k])) + U(index_high ^ keys.high[k]));
}

inline float counter_uniform(std::uint64_t index, const CounterKeys& keys, int k) {
    const std::uint32_t bits = counter_bits<std::uint32_t>(static_cast<std::uint32_t>(index),
                                                           static_cast<std::uint32_t>(index >> 32), keys, k);
    return static_cast<float>(bits >> 8) * 0x1p-24f;
}
