// The kernel for avx512; CMake compiles this file with that instruction set's flags.
#define PRINCIPLED_BRDF_ARCH xsimd::avx512bw
#define PRINCIPLED_BRDF_ARCH_NS avx512
#include "kernel.hpp"

namespace principled_brdf::kernel {

const KernelTable& avx512_kernels() {
    static constexpr KernelTable table{"avx512", static_cast<int>(avx512::kLanes), &avx512::eval_range,
                                           &avx512::sample_range,
                                           &avx512::first_bad_direction};
    return table;
}

}  // namespace principled_brdf::kernel
