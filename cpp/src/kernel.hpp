// The SIMD kernel: the model (docs/model.md) over xsimd::batch<float, Arch>,
// branch-free, with the loads, stores, layouts, tails and loops around it.
//
// Included exactly once by each kernel_<isa>.cpp (which is nothing else), after it defines
// PRINCIPLED_BRDF_ARCH (the xsimd arch tag) and PRINCIPLED_BRDF_ARCH_NS (a
// namespace name). Everything here lives in that per-arch namespace, so code
// compiled with one instruction set's flags is never linked into another's.
//
// Accuracy (docs/validation.md): the half vector is kept unnormalised, H = wi + wo.
// Its components are exact float sums where wi and wo nearly cancel, so
// cos²θh = Hz²/|H|² and sin²θh = (Hx² + Hy²)/|H|² keep full relative precision
// at the narrow GTR peaks, where 1 - cos²θh would cancel.
//
// As in the model, locals are not declared const (docs/model.md, "No const locals").
#include <xsimd/xsimd.hpp>

#include <array>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>
#include <utility>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "kernel_api.hpp"
#include "principled_brdf/dielectric_energy_tables.hpp"
#include "principled_brdf/energy_corners.hpp"
#include "principled_brdf/energy_intercepts.hpp"

namespace principled_brdf::kernel::PRINCIPLED_BRDF_ARCH_NS {

using Arch = PRINCIPLED_BRDF_ARCH;
using Floats = xsimd::batch<float, Arch>;
using Mask = xsimd::batch_bool<float, Arch>;
using UInts = xsimd::batch<std::uint32_t, Arch>;
using Ints = xsimd::batch<std::int32_t, Arch>;
constexpr std::int64_t kLanes = static_cast<std::int64_t>(Floats::size);

#include "simd_ops.hpp"
#include "simd_double_ops.hpp"

// The model (docs/model.md), instantiated here for Floats.
#define PB_MODEL_INLINE PB_KERNEL_INLINE
#include "principled_brdf/model/model.hpp"
#undef PB_MODEL_INLINE

#include "kernel_material.hpp"
#include "kernel_memory.hpp"
#include "kernel_sampling.hpp"
#include "kernel_direction_gradient.hpp"
#include "kernel_eval.hpp"
#include "kernel_normal.hpp"
#include "kernel_sample.hpp"

// The kernel's entry points, each in one part: CMake compiles kernel_<isa>.cpp
// once per part (PRINCIPLED_BRDF_KERNEL_PART, kernel_parts.hpp), so that the
// parts of every instruction set compile side by side; without it one file
// holds them all.
#include "kernel_parts.hpp"

}  // namespace principled_brdf::kernel::PRINCIPLED_BRDF_ARCH_NS

#if PB_KERNEL_BUILDS(PB_KERNEL_PART_TABLE)
// The table dispatch.cpp reads: <ns>_kernels() of kernel_api.hpp.
#define PRINCIPLED_BRDF_JOIN2(a, b) a##b
#define PRINCIPLED_BRDF_JOIN(a, b) PRINCIPLED_BRDF_JOIN2(a, b)
#define PRINCIPLED_BRDF_QUOTE2(a) #a
#define PRINCIPLED_BRDF_QUOTE(a) PRINCIPLED_BRDF_QUOTE2(a)

namespace principled_brdf::kernel {

const KernelTable& PRINCIPLED_BRDF_JOIN(PRINCIPLED_BRDF_ARCH_NS, _kernels)() {
    namespace isa = PRINCIPLED_BRDF_ARCH_NS;
    static constexpr KernelTable table{PRINCIPLED_BRDF_QUOTE(PRINCIPLED_BRDF_ARCH_NS), static_cast<int>(isa::kLanes),
                                       &isa::eval_range, &isa::sample_range, &isa::normal_equations_range};
    return table;
}

}  // namespace principled_brdf::kernel
#endif
