// The kernel's entry points in parts (included by kernel.hpp inside the
// per-arch namespace). CMake compiles kernel_<isa>.cpp once per part, with
// PRINCIPLED_BRDF_KERNEL_PART set to its number, so that the parts of all
// instruction sets compile side by side and none is a long critical path;
// each compilation instantiates only its part's loops. Without the macro (0)
// one compilation holds the whole kernel.
//
// The evaluation's outputs are split into four families, each a part, and
// the samples into two; eval_range and sample_range, in the table's part, send
// a job to its part.

#define PB_KERNEL_PART_TABLE 1       // the table, eval_range, sample_range and the normal equations
#define PB_KERNEL_PART_VALUES 2      // f and its lobes
#define PB_KERNEL_PART_DENSITIES 3   // the sampling pdf, and f with it
#define PB_KERNEL_PART_GRADIENTS 4   // f's Jacobian and vector-Jacobian product in the parameters
#define PB_KERNEL_PART_DIRECTIONS 5  // the same in the directions
#define PB_KERNEL_PART_SAMPLES 6     // the samples of a uniform material
#define PB_KERNEL_PART_SAMPLES_PER_ELEMENT 7  // those of per-element materials
#ifndef PRINCIPLED_BRDF_KERNEL_PART
#define PRINCIPLED_BRDF_KERNEL_PART 0
#endif
#define PB_KERNEL_BUILDS(part) (PRINCIPLED_BRDF_KERNEL_PART == 0 || PRINCIPLED_BRDF_KERNEL_PART == (part))

using ValueOutputs = OutputList<Output::kTotal, Output::kLobes>;
using DensityOutputs = OutputList<Output::kPdf, Output::kValuePdf>;
using GradientOutputs = OutputList<Output::kGradient, Output::kVjp>;
using DirectionOutputs = OutputList<Output::kDirectionGradient, Output::kDirectionVjp>;

constexpr bool each_output_in_one_family() {
    for (int k = 0; k <= static_cast<int>(Output::kDirectionVjp); ++k) {
        auto output = static_cast<Output>(k);
        if (ValueOutputs::holds(output) + DensityOutputs::holds(output) + GradientOutputs::holds(output) +
                DirectionOutputs::holds(output) != 1)
            return false;
    }
    return true;
}
static_assert(each_output_in_one_family(), "eval_range sends each output to one part");

std::int64_t eval_values_range(const EvalJob& job, std::int64_t begin, std::int64_t end);
std::int64_t eval_densities_range(const EvalJob& job, std::int64_t begin, std::int64_t end);
std::int64_t eval_gradients_range(const EvalJob& job, std::int64_t begin, std::int64_t end);
std::int64_t eval_directions_range(const EvalJob& job, std::int64_t begin, std::int64_t end);
std::int64_t sample_uniform_range(const SampleJob& job, std::int64_t begin, std::int64_t end);
std::int64_t sample_per_element_range(const SampleJob& job, std::int64_t begin, std::int64_t end);

#if PB_KERNEL_BUILDS(PB_KERNEL_PART_VALUES)
std::int64_t eval_values_range(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    return eval_job_range<ValueOutputs>(job, begin, end);
}
#endif

#if PB_KERNEL_BUILDS(PB_KERNEL_PART_DENSITIES)
std::int64_t eval_densities_range(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    return eval_job_range<DensityOutputs>(job, begin, end);
}
#endif

#if PB_KERNEL_BUILDS(PB_KERNEL_PART_GRADIENTS)
std::int64_t eval_gradients_range(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    return eval_job_range<GradientOutputs>(job, begin, end);
}
#endif

#if PB_KERNEL_BUILDS(PB_KERNEL_PART_DIRECTIONS)
std::int64_t eval_directions_range(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    return eval_job_range<DirectionOutputs>(job, begin, end);
}
#endif

#if PB_KERNEL_BUILDS(PB_KERNEL_PART_SAMPLES)
std::int64_t sample_uniform_range(const SampleJob& job, std::int64_t begin, std::int64_t end) {
    return sample_job_range<false>(job, begin, end);
}
#endif

#if PB_KERNEL_BUILDS(PB_KERNEL_PART_SAMPLES_PER_ELEMENT)
std::int64_t sample_per_element_range(const SampleJob& job, std::int64_t begin, std::int64_t end) {
    return sample_job_range<true>(job, begin, end);
}
#endif

#if PB_KERNEL_BUILDS(PB_KERNEL_PART_TABLE)
std::int64_t eval_range(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    if (ValueOutputs::holds(job.output)) return eval_values_range(job, begin, end);
    if (DensityOutputs::holds(job.output)) return eval_densities_range(job, begin, end);
    if (GradientOutputs::holds(job.output)) return eval_gradients_range(job, begin, end);
    if (DirectionOutputs::holds(job.output)) return eval_directions_range(job, begin, end);
    return -1;  // (not reached: each_output_in_one_family)
}

std::int64_t sample_range(const SampleJob& job, std::int64_t begin, std::int64_t end) {
    return job.uniform_material() ? sample_uniform_range(job, begin, end) : sample_per_element_range(job, begin, end);
}
#endif
