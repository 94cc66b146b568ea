// The kernel for neon; CMake compiles this file with that instruction set's flags.
#include <xsimd/xsimd.hpp>

// xsimd 8.1 gives AArch64 float batches 32-bit ARM's division and square root:
// reciprocal (square root) estimates refined by two Newton-Raphson steps, not
// correctly rounded (and 1/x is -inf for 0 < x < 2^-128); and its fnma, c - a b,
// is -a b + c, two roundings. The kernels take exact division and square root
// and one rounding for every fused multiply-add (simd_ops.hpp), as on x86: these
// specializations, declared before any use, give them AArch64's instructions,
// in xsimd's own functions (log, exp) too.
namespace xsimd {

template <>
inline batch<float, neon64>& batch<float, neon64>::operator/=(batch<float, neon64> const& other) noexcept {
    return *this = vdivq_f32(*this, other);
}

template <>
inline batch<float, neon64> sqrt(batch<float, neon64> const& x) noexcept {
    return vsqrtq_f32(x);
}

template <>
inline batch<float, neon64> fnma(batch<float, neon64> const& x, batch<float, neon64> const& y,
                                 batch<float, neon64> const& z) noexcept {
    return vfmsq_f32(z, x, y);
}

template <>
inline batch<double, neon64> fnma(batch<double, neon64> const& x, batch<double, neon64> const& y,
                                  batch<double, neon64> const& z) noexcept {
    return vfmsq_f64(z, x, y);
}

}  // namespace xsimd

#define PRINCIPLED_BRDF_ARCH xsimd::neon64
#define PRINCIPLED_BRDF_ARCH_NS neon
#include "kernel.hpp"
