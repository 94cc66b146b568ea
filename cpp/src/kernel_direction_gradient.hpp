// Part of kernel.hpp, included inside the per-arch namespace: one batch of the
// derivatives of f in the directions (model/direction_gradient.hpp), for the
// evaluation loop of kernel_eval.hpp: the Jacobian's 18 values an element
// (Output::kDirectionGradient) or their products with a cotangent
// (Output::kDirectionVjp).
#pragma once  // (per translation unit)

static_assert(kDirectionSlots == kDirectionComponents, "the model's direction slots are batch.hpp's components");

// ∂f_c/∂w_k per element: 3 channels by the 6 direction components.
inline constexpr int kDirectionJacobianWidth = 3 * kDirectionSlots;

constexpr bool in_directions(Output output) {
    return output == Output::kDirectionGradient || output == Output::kDirectionVjp;
}

using DirectionShading = Shading<DirectionDual<Floats>>;

template <Layouts layouts>
PB_KERNEL_INLINE bool jacobian_by_rows(const EvalJob& job) {
    return layouts == Layouts::kRows || (layouts == Layouts::kMixed && job.jacobian_row_stride > 0);
}

// The Jacobian's sink: row r = 6 c + k holds ∂f_c/∂w_k of every lane, stored
// straight to memory by rows (the (3, 6, N) layout) or through the stack,
// transposed to element-major order when the batch is done (finish).
template <Layouts layouts>
struct DirectionJacobianStore {
    const EvalJob& job;
    std::int64_t i;
    alignas(64) float lanes[padded_rows(kDirectionJacobianWidth)][kLanes];

    DirectionJacobianStore(const EvalJob& job_, std::int64_t i_) : job(job_), i(i_) {}

    PB_KERNEL_INLINE void operator()(int c, int k, Floats value) {
        int r = kDirectionSlots * c + k;
        if (jacobian_by_rows<layouts>(job)) {
            value.store_unaligned(job.jacobian + r * job.jacobian_row_stride + i);
        } else {
            value.store_aligned(lanes[r]);
        }
    }

    PB_KERNEL_INLINE void finish() {
        if (jacobian_by_rows<layouts>(job)) return;
        for (int r = kDirectionJacobianWidth; r < padded_rows(kDirectionJacobianWidth); ++r) Floats(0.0f).store_aligned(lanes[r]);
        store_rows_by_element<kDirectionJacobianWidth>(lanes, job.jacobian + kDirectionJacobianWidth * i);
    }
};

// The vector-Jacobian product's sink: Σ_c g_c ∂f_c/∂w_k, the channels summed
// in order as they come, stored by rows (the (6, N) layout) or by element.
template <Layouts layouts>
struct DirectionVjpSink {
    const EvalJob& job;
    std::int64_t i;
    Rgb<Floats> cotangent;
    Floats sum[kDirectionSlots];

    DirectionVjpSink(const EvalJob& job_, std::int64_t i_, const Vec3<Floats>& g) : job(job_), i(i_), cotangent{g.x, g.y, g.z} {}

    PB_KERNEL_INLINE void operator()(int c, int k, Floats value) {
        sum[k] = c == 0 ? channel_of(cotangent, c) * value : mul_add(channel_of(cotangent, c), value, sum[k]);
    }

    PB_KERNEL_INLINE void finish() {
        if (jacobian_by_rows<layouts>(job)) {
            for (int k = 0; k < kDirectionSlots; ++k) sum[k].store_unaligned(job.jacobian + k * job.jacobian_row_stride + i);
            return;
        }
        alignas(64) float lanes[kDirectionSlots][kLanes];
        for (int k = 0; k < kDirectionSlots; ++k) sum[k].store_aligned(lanes[k]);
        store_lanes_by_element(lanes, kDirectionSlots, job.jacobian + kDirectionSlots * i);
    }
};

// One batch at i of a direction output, its material's constants over dual numbers.
template <Model model, Output output, Layouts layouts>
PB_KERNEL_INLINE void eval_direction_batch(const EvalJob& job, std::int64_t i, const Vec3<Floats>& wi, const Vec3<Floats>& wo,
                                           const DirectionShading& s) {
    derivative_batch<output == Output::kDirectionGradient, DirectionJacobianStore<layouts>, DirectionVjpSink<layouts>,
                     layouts>(job, i, [&](auto& target) { return eval_direction_gradient<model>(wi, wo, s, job.cosine, target); });
}
