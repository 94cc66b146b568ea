// Part of kernel.hpp, included inside the per-arch namespace: the derivatives
// of f in the directions (model/direction_gradient.hpp) over a range of
// elements. The directions are taken as they are: the caller has checked them
// (eval_grad checks them in its pass for f), and with the check off a pair
// whose H is not finite gets 0, as f does.
#pragma once  // (per translation unit)

// ∂f_c/∂w_k per element: 3 channels by the 6 direction components.
inline constexpr int kDirectionJacobianWidth = 3 * kDirectionSlots;

using DirectionShading = Shading<DirectionDual<Floats>>;

// One batch at i, its Jacobian straight to memory by rows ((3, 6, N)) or
// through the stack, transposed to element-major order ((N, 3, 6)).
template <Model model, bool per_element>
PB_KERNEL_INLINE void direction_gradient_batch(const EvalJob& job, std::int64_t i, const DirectionShading& uniform) {
    Vec3<Floats> wi = load_vec3(job.wi, i);
    Vec3<Floats> wo = load_vec3(job.wo, i);
    alignas(64) float lanes[padded_rows(kDirectionJacobianWidth)][kLanes];
    const bool by_rows = job.jacobian_row_stride > 0;
    auto put = [&](int c, int k, Floats x) {
        const int r = kDirectionSlots * c + k;
        if (by_rows) {
            x.store_unaligned(job.jacobian + r * job.jacobian_row_stride + i);
        } else {
            x.store_aligned(lanes[r]);
        }
    };
    if constexpr (per_element) {
        RawMaterial m = load_material(job.params, i);
        eval_direction_gradient<model>(wi, wo, direction_shading_of(m.slot), job.cosine, put);
    } else {
        eval_direction_gradient<model>(wi, wo, uniform, job.cosine, put);
    }
    if (by_rows) return;
    for (int r = kDirectionJacobianWidth; r < padded_rows(kDirectionJacobianWidth); ++r) Floats(0.0f).store_aligned(lanes[r]);
    store_rows_by_element<kDirectionJacobianWidth>(lanes, job.jacobian + kDirectionJacobianWidth * i);
}

// The last pad.count < kLanes elements, as one padded batch.
template <Model model, bool per_element>
void direction_gradient_tail(const EvalJob& job, const Padding& pad, const DirectionShading& uniform) {
    alignas(64) PadBuffer wi, wo, params[kParamSlots];
    alignas(64) float jacobian[kDirectionJacobianWidth * kLanes];
    EvalJob padded = job;
    padded.wi = pad_vec3(job.wi, pad, wi);
    padded.wo = pad_vec3(job.wo, pad, wo);
    pad_params(job.params, padded.params, pad, params);
    padded.jacobian = jacobian;
    padded.jacobian_row_stride = 0;
    direction_gradient_batch<model, per_element>(padded, 0, uniform);
    for (std::int64_t j = 0; j < pad.count; ++j)
        for (int r = 0; r < kDirectionJacobianWidth; ++r) {
            const std::int64_t e = pad.begin + j;
            const std::int64_t index = job.jacobian_row_stride > 0 ? r * job.jacobian_row_stride + e : kDirectionJacobianWidth * e + r;
            job.jacobian[index] = jacobian[kDirectionJacobianWidth * j + r];
        }
}

template <Model model, bool per_element>
void direction_gradient_batches(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    DirectionShading uniform;
    if constexpr (!per_element) uniform = direction_shading_of(load_material(job.params, 0).slot);
    std::int64_t i = begin;
    for (; i + kLanes <= end; i += kLanes) direction_gradient_batch<model, per_element>(job, i, uniform);
    if (i < end) direction_gradient_tail<model, per_element>(job, Padding{i, end - i}, uniform);
}

template <Model model>
void direction_gradient_for(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    if (job.uniform_material()) {
        direction_gradient_batches<model, false>(job, begin, end);
    } else {
        direction_gradient_batches<model, true>(job, begin, end);
    }
}

// ∂f/∂(wi, wo) of elements [begin, end) into job.jacobian (EvalJob's layouts with 6 columns).
inline void direction_gradient_range(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    if (job.model == Model::kDisney2012) {
        direction_gradient_for<Model::kDisney2012>(job, begin, end);
    } else {
        direction_gradient_for<Model::kDisney2014>(job, begin, end);
    }
}
