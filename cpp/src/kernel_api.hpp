// The per-instruction-set kernel entry points, as seen from baseline code.
// No xsimd here: this header is included by baseline and per-arch code alike.
#pragma once

#include <cstdint>

#include "principled_brdf/batch.hpp"

// The kernels' small functions pass batches of registers around; GCC's
// heuristics leave some of them out of line, which spills every argument.
// (The sanitizer build defines it as plain inline: far fewer inlined copies to
// instrument, minutes instead of most of an hour per kernel file.)
#ifndef PB_KERNEL_INLINE
#define PB_KERNEL_INLINE inline __attribute__((always_inline))
#endif

namespace principled_brdf::kernel {

struct KernelTable {
    const char* isa;  // "sse2", "avx2", "avx512", "neon"
    int float_lanes;
    // Evaluates elements [begin, end) of job and returns -1 when all are
    // written. With job.check enabled, stops at the first batch holding a bad
    // direction and returns that element's index (the rest stay unwritten).
    std::int64_t (*eval_range)(const EvalJob& job, std::int64_t begin, std::int64_t end);
    // As eval_range, for sampling (the check is on wo).
    std::int64_t (*sample_range)(const SampleJob& job, std::int64_t begin, std::int64_t end);
    // The normal equations of job.problems[begin .. end) (batch.hpp).
    void (*normal_equations_range)(const NormalEquationsJob& job, std::int64_t begin, std::int64_t end);
};

// Defined in kernel_<isa>.cpp, each compiled with its own flags; call one
// only after the CPU was found to support it (dispatch.cpp).
const KernelTable& sse2_kernels();
const KernelTable& avx2_kernels();
const KernelTable& avx512_kernels();
const KernelTable& neon_kernels();

}  // namespace principled_brdf::kernel
