// The kernel for neon; CMake compiles this file with that instruction set's flags.
#define PRINCIPLED_BRDF_ARCH xsimd::neon64
#define PRINCIPLED_BRDF_ARCH_NS neon
#include "kernel.hpp"

namespace principled_brdf::kernel {

const KernelTable& neon_kernels() {
    static constexpr KernelTable table{"neon", static_cast<int>(neon::kLanes), &neon::eval_range,
                                           &neon::sample_range,
                                           &neon::first_bad_direction};
    return table;
}

}  // namespace principled_brdf::kernel
