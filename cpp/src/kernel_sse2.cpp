// The kernel for sse2; CMake compiles this file with that instruction set's flags.
#define PRINCIPLED_BRDF_ARCH xsimd::sse2
#define PRINCIPLED_BRDF_ARCH_NS sse2
#include "kernel.hpp"

namespace principled_brdf::kernel {

const KernelTable& sse2_kernels() {
    static constexpr KernelTable table{"sse2", static_cast<int>(sse2::kLanes), &sse2::eval_range,
                                           &sse2::sample_range,
                                           &sse2::first_bad_direction};
    return table;
}

}  // namespace principled_brdf::kernel
