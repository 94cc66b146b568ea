// The kernel for avx2; CMake compiles this file with that instruction set's flags.
#define PRINCIPLED_BRDF_ARCH xsimd::fma3<xsimd::avx2>
#define PRINCIPLED_BRDF_ARCH_NS avx2
#include "kernel.hpp"

namespace principled_brdf::kernel {

const KernelTable& avx2_kernels() {
    static constexpr KernelTable table{"avx2", static_cast<int>(avx2::kLanes), &avx2::eval_range,
                                           &avx2::sample_range,
                                           &avx2::first_bad_direction};
    return table;
}

}  // namespace principled_brdf::kernel
