// What the model calls (docs/model.md), for batches of double: the number type
// of the derivatives in the directions (kernel_direction_gradient.hpp), whose
// sums cancel to a small fraction of their terms (docs/gradients.md). The same
// names as simd_ops.hpp's for Floats and model/scalar_ops.hpp's for double:
// IEEE double arithmetic, and xsimd's log, exp and expm1 (within an ulp or two).
//
// Included by kernel.hpp inside the per-arch namespace, before the model.
#pragma once  // (per translation unit)

using Doubles = xsimd::batch<double, Arch>;
using DoubleMask = xsimd::batch_bool<double, Arch>;

#if defined(__AVX512F__)  // (xsimd 8.1 writes x * y + z for AVX-512: two roundings)
PB_KERNEL_INLINE Doubles mul_add(Doubles a, Doubles b, Doubles c) { return _mm512_fmadd_pd(a, b, c); }
PB_KERNEL_INLINE Doubles mul_sub(Doubles a, Doubles b, Doubles c) { return _mm512_fmsub_pd(a, b, c); }
PB_KERNEL_INLINE Doubles neg_mul_add(Doubles a, Doubles b, Doubles c) { return _mm512_fnmadd_pd(a, b, c); }
#else
PB_KERNEL_INLINE Doubles mul_add(Doubles a, Doubles b, Doubles c) { return xsimd::fma(a, b, c); }
PB_KERNEL_INLINE Doubles mul_sub(Doubles a, Doubles b, Doubles c) { return xsimd::fms(a, b, c); }
PB_KERNEL_INLINE Doubles neg_mul_add(Doubles a, Doubles b, Doubles c) { return xsimd::fnma(a, b, c); }
#endif

PB_KERNEL_INLINE Doubles reciprocal(Doubles x) { return Doubles(1.0) / x; }
PB_KERNEL_INLINE Doubles reciprocal_sqrt(Doubles x) { return Doubles(1.0) / xsimd::sqrt(x); }
// sqrt(x), 0 for x <= 0 (and for NaN on x86, where max returns its second operand)
PB_KERNEL_INLINE Doubles square_root(Doubles x) { return xsimd::sqrt(xsimd::max(x, Doubles(0.0))); }
PB_KERNEL_INLINE Doubles square_root_nonnegative(Doubles x) { return xsimd::sqrt(x); }

PB_KERNEL_INLINE Doubles select(const DoubleMask& m, Doubles a, Doubles b) { return xsimd::select(m, a, b); }
PB_KERNEL_INLINE Doubles min(Doubles a, Doubles b) { return xsimd::min(a, b); }
PB_KERNEL_INLINE Doubles max(Doubles a, Doubles b) { return xsimd::max(a, b); }
PB_KERNEL_INLINE bool any(const DoubleMask& m) { return xsimd::any(m); }
PB_KERNEL_INLINE bool all(const DoubleMask& m) { return xsimd::all(m); }
PB_KERNEL_INLINE Doubles log(Doubles x) { return xsimd::log(x); }
PB_KERNEL_INLINE Doubles exp(Doubles x) { return xsimd::exp(x); }
PB_KERNEL_INLINE Doubles exp_minus_one(Doubles x) { return xsimd::expm1(x); }
// table lookups of whole nodes (model/dielectric_energy.hpp): floor(x) for x >= 0, and
// (table[i], table[i + 1]) per lane for a whole i held as a real
PB_KERNEL_INLINE Doubles floor_of(Doubles x) { return xsimd::floor(x); }
PB_KERNEL_INLINE std::pair<Doubles, Doubles> table_pair(const float* table, Doubles index) {
    alignas(64) double at[Doubles::size], below[Doubles::size], above[Doubles::size];
    index.store_aligned(at);
    for (std::size_t l = 0; l < Doubles::size; ++l) {
        const std::int64_t i = static_cast<std::int64_t>(at[l]);
        below[l] = table[i];
        above[l] = table[i + 1];
    }
    return {Doubles::load_aligned(below), Doubles::load_aligned(above)};
}

// ---------------------------------------------------------------- a float batch as two double batches
// Lanes [0, kLanes / 2) of a Floats are half 0, the rest half 1.

inline constexpr int kHalves = 2;
inline constexpr int kHalfLanes = static_cast<int>(Doubles::size);
static_assert(kHalves * kHalfLanes == kLanes, "a float batch is two double batches");

PB_KERNEL_INLINE Doubles half_of(Floats x, int half) {
    alignas(64) float lanes[kLanes];
    x.store_aligned(lanes);
    alignas(64) double wide[kHalfLanes];
    for (int l = 0; l < kHalfLanes; ++l) wide[l] = lanes[half * kHalfLanes + l];
    return Doubles::load_aligned(wide);
}

// The float batch of kLanes doubles (both halves), each rounded once.
PB_KERNEL_INLINE Floats rounded_to_floats(const double* lanes) {
    alignas(64) float narrow[kLanes];
    for (int l = 0; l < kLanes; ++l) narrow[l] = static_cast<float>(lanes[l]);
    return Floats::load_aligned(narrow);
}
