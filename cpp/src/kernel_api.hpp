// The per-instruction-set kernel entry points, as seen from baseline code.
// No xsimd here: this header is included by baseline and per-arch code alike.
#pragma once

#include <cstdint>

#include "principled_brdf/batch.hpp"

// The kernels' small functions pass batches of registers around; GCC's
// heuristics leave some of them out of line, which spills every argument.
#define PB_KERNEL_INLINE inline __attribute__((always_inline))

namespace principled_brdf::kernel {

struct KernelTable {
    const char* isa;  // "sse2", "avx2", "avx512", "neon"
    int float_lanes;
    // Evaluates elements [begin, end) of job. With job.check_directions, stops
    // at the first batch holding a bad direction and returns that element's
    // index (its batch stays unwritten); else returns -1.
    std::int64_t (*eval_range)(const EvalJob& job, std::int64_t begin, std::int64_t end);
    // First i in [begin, end) whose squared length is outside [lowest, highest]
    // or not finite, else -1.
    // As eval_range, for sampling (the check is on wo).
    std::int64_t (*sample_range)(const SampleJob& job, std::int64_t begin, std::int64_t end);
    std::int64_t (*first_bad_direction)(const Vec3Array& directions, std::int64_t begin, std::int64_t end,
                                        float lowest, float highest);
};

// Defined in kernel_<isa>.cpp, each compiled with its own flags; call one
// only after the CPU was found to support it (dispatch.cpp).
const KernelTable& sse2_kernels();
const KernelTable& avx2_kernels();
const KernelTable& avx512_kernels();
const KernelTable& neon_kernels();

}  // namespace principled_brdf::kernel
