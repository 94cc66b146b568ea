// The SIMD kernel: the model of README "The model" over xsimd::batch<float, Arch>, branch-free.
//
// Included exactly once by each kernel_<isa>.cpp (which is nothing else), after it defines
// PRINCIPLED_BRDF_ARCH (the xsimd arch tag) and PRINCIPLED_BRDF_ARCH_NS (a
// namespace name). Everything here lives in that per-arch namespace, so code
// compiled with one instruction set's flags is never linked into another's.
//
// Accuracy (README "What is checked"): the half vector is kept unnormalised, H = wi + wo.
// Its components are exact float sums where wi and wo nearly cancel, so
// cos²θh = Hz²/|H|² and sin²θh = (Hx² + Hy²)/|H|² keep full relative precision
// at the narrow GTR peaks, where 1 - cos²θh would cancel.
#include <xsimd/xsimd.hpp>

#include <cstdint>
#include <limits>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "kernel_api.hpp"

namespace principled_brdf::kernel::PRINCIPLED_BRDF_ARCH_NS {

using Arch = PRINCIPLED_BRDF_ARCH;
using Floats = xsimd::batch<float, Arch>;
using Mask = xsimd::batch_bool<float, Arch>;
constexpr std::int64_t kLanes = static_cast<std::int64_t>(Floats::size);

#include "simd_ops.hpp"

constexpr float kInvPi = 0.318309886183790671538f;

struct Vec3 {
    Floats x, y, z;
};

struct Rgb {
    Floats r, g, b;
};

PB_KERNEL_INLINE Rgb operator*(Floats s, const Rgb& c) { return {s * c.r, s * c.g, s * c.b}; }
PB_KERNEL_INLINE Rgb operator+(const Rgb& a, const Rgb& b) { return {a.r + b.r, a.g + b.g, a.b + b.b}; }

// mix(a, b, t) = a (1 - t) + b t: for a, b >= 0 nothing cancels (a + (b - a) t
// loses b's digits when b << a and t -> 1, e.g. Csheen of a saturated colour).
PB_KERNEL_INLINE Floats mix(Floats a, Floats b, Floats t) { return mul_add(b, t, a * (Floats(1.0f) - t)); }
PB_KERNEL_INLINE Rgb mix(const Rgb& a, const Rgb& b, Floats t) { return {mix(a.r, b.r, t), mix(a.g, b.g, t), mix(a.b, b.b, t)}; }

// Schlick(u) = clamp(1 - u, 0, 1)^5, given 1 - u
PB_KERNEL_INLINE Floats schlick_weight_of_complement(Floats one_minus_u) {
    const Floats m = xsimd::min(xsimd::max(one_minus_u, Floats(0.0f)), Floats(1.0f));
    const Floats m2 = m * m;
    return m2 * m2 * m;
}

PB_KERNEL_INLINE Floats schlick_weight(Floats u) { return schlick_weight_of_complement(Floats(1.0f) - u); }

#include "kernel_material.hpp"
#include "kernel_brdf.hpp"
#include "kernel_memory.hpp"
#include "kernel_sampling.hpp"
#include "kernel_eval.hpp"
#include "kernel_sample.hpp"

}  // namespace principled_brdf::kernel::PRINCIPLED_BRDF_ARCH_NS

// The table dispatch.cpp reads: <ns>_kernels() of kernel_api.hpp.
#define PRINCIPLED_BRDF_JOIN2(a, b) a##b
#define PRINCIPLED_BRDF_JOIN(a, b) PRINCIPLED_BRDF_JOIN2(a, b)
#define PRINCIPLED_BRDF_QUOTE2(a) #a
#define PRINCIPLED_BRDF_QUOTE(a) PRINCIPLED_BRDF_QUOTE2(a)

namespace principled_brdf::kernel {

const KernelTable& PRINCIPLED_BRDF_JOIN(PRINCIPLED_BRDF_ARCH_NS, _kernels)() {
    namespace isa = PRINCIPLED_BRDF_ARCH_NS;
    static constexpr KernelTable table{PRINCIPLED_BRDF_QUOTE(PRINCIPLED_BRDF_ARCH_NS), static_cast<int>(isa::kLanes),
                                       &isa::eval_range, &isa::sample_range};
    return table;
}

}  // namespace principled_brdf::kernel
