// Part of kernel.hpp, included inside the per-arch namespace: the normal
// equations of least-squares fits (NormalEquationsJob in batch.hpp;
// docs/fitting.md). Each problem's material is prepared once; its pairs go
// through eval_gradient a batch of lanes at a time, and a sink keeps the
// wanted columns of the batch on the stack, where they are scaled by the
// loss's derivative and summed into per-lane sums (JᵀJ, Jᵀr and the cost).
// The lanes are added up in float64, in lane order, when the problem is done.
#pragma once  // (per translation unit)

// eval_gradient's sink: the batch's wanted columns, by channel and column.
struct NormalSink {
    const Columns& columns;
    alignas(64) float column[3][kParamSlots][kLanes];

    explicit NormalSink(const Columns& c) : columns(c) {}

    bool wants(int p) const { return columns.wants(p); }

    PB_KERNEL_INLINE void operator()(int c, int p, Floats value) { value.store_aligned(column[c][columns.position[p]]); }
};

// One problem's per-lane sums.
struct NormalSums {
    alignas(64) float normal[kNormalWidth][kLanes];
    alignas(64) float gradient[kParamSlots][kLanes];
    alignas(64) double cost[kLanes];

    explicit NormalSums(int width) {
        for (int k = 0; k < width * (width + 1) / 2; ++k) Floats(0.0f).store_aligned(normal[k]);
        for (int k = 0; k < width; ++k) Floats(0.0f).store_aligned(gradient[k]);
        for (std::int64_t lane = 0; lane < kLanes; ++lane) cost[lane] = 0.0;
    }
};

// r = (u(f) - t) s and ∂r/∂f = u'(f) s for one channel of a batch.
struct ChannelResidual {
    Floats residual, slope;
};

PB_KERNEL_INLINE ChannelResidual channel_residual(Loss loss, Floats f, Floats target, Floats scale) {
    if (loss == Loss::kLog) return {(xsimd::log1p(f) - target) * scale, scale / (Floats(1.0f) + f)};
    return {(f - target) * scale, scale};
}

// One batch of kLanes pairs of a problem into its sums: wi, wo, target and
// scale point at the batch's first pair ((kLanes, 3) each).
template <Model model>
PB_KERNEL_INLINE void add_normal_batch(const NormalEquationsJob& job, const Prepared<Output::kGradient>& material,
                                       const float* wi_data, const float* wo_data, const float* target_data,
                                       const float* scale_data, NormalSums& sums) {
    Vec3<Floats> wi, wo;
    load_interleaved(wi_data, wi.x, wi.y, wi.z);
    load_interleaved(wo_data, wo.x, wo.y, wo.z);
    const Shading<Floats>& s = material.shading;
    Geometry<Floats> g = geometry_of(wi, wo);
    Mask above = above_surface(g);
    View<Floats> view = view_of<model>(wo, s);
    // as eval_grad's: x cos θl or x times 1, then 0 below the surface
    Floats cosine_weight = job.cosine ? wi.z : Floats(1.0f);
    auto masked = [&](Floats x) { return select(above, cosine_weight * x, Floats(0.0f)); };
    NormalSink sink{job.columns};
    Rgb<Floats> f = eval_gradient<model>(g, s, view, material.partials, masked, sink);
    Rgb<Floats> target, scale;
    load_interleaved(target_data, target.r, target.g, target.b);
    load_interleaved(scale_data, scale.r, scale.g, scale.b);
    ChannelResidual channel[3];
    for (int c = 0; c < 3; ++c)
        channel[c] = channel_residual(job.loss, masked(channel_of(f, c)), channel_of(target, c), channel_of(scale, c));

    alignas(64) float squares[kLanes];
    mul_add(channel[0].residual, channel[0].residual,
            mul_add(channel[1].residual, channel[1].residual, channel[2].residual * channel[2].residual))
            .store_aligned(squares);
    for (std::int64_t lane = 0; lane < kLanes; ++lane) sums.cost[lane] += squares[lane];

    // ∂r_c/∂p_k = u'(f_c) s_c ∂f_c/∂p_k, in place
    const int width = job.columns.count;
    for (int c = 0; c < 3; ++c)
        for (int k = 0; k < width; ++k)
            (channel[c].slope * Floats::load_aligned(sink.column[c][k])).store_aligned(sink.column[c][k]);
    int entry = 0;
    for (int k = 0; k < width; ++k) {
        Floats a0 = Floats::load_aligned(sink.column[0][k]), a1 = Floats::load_aligned(sink.column[1][k]),
               a2 = Floats::load_aligned(sink.column[2][k]);
        Floats gradient = Floats::load_aligned(sums.gradient[k]);
        gradient = mul_add(a0, channel[0].residual, mul_add(a1, channel[1].residual, mul_add(a2, channel[2].residual, gradient)));
        gradient.store_aligned(sums.gradient[k]);
        for (int l = k; l < width; ++l, ++entry) {
            Floats sum = Floats::load_aligned(sums.normal[entry]);
            sum = mul_add(a0, Floats::load_aligned(sink.column[0][l]),
                          mul_add(a1, Floats::load_aligned(sink.column[1][l]),
                                  mul_add(a2, Floats::load_aligned(sink.column[2][l]), sum)));
            sum.store_aligned(sums.normal[entry]);
        }
    }
}

// Problem job.problems[j]'s sums, written to its rows of the outputs.
template <Model model>
void normal_equations_of(const NormalEquationsJob& job, std::int64_t j) {
    const std::int64_t b = job.problems[j];
    const std::int64_t n = job.pairs;
    RawMaterial m;
    for (int s = 0; s < kParamSlots; ++s) m.slot[s] = Floats(job.slots[b * kParamSlots + s]);
    const Prepared<Output::kGradient> material = prepare<Output::kGradient>(m);
    const std::int64_t directions = job.per_problem_directions ? 3 * n * b : 0;
    const float* wi = job.wi + directions;
    const float* wo = job.wo + directions;
    const float* target = job.target + 3 * n * b;
    const float* scale = job.scale + 3 * n * b;
    const int width = job.columns.count;
    NormalSums sums(width);
    std::int64_t i = 0;
    for (; i + kLanes <= n; i += kLanes)
        add_normal_batch<model>(job, material, wi + 3 * i, wo + 3 * i, target + 3 * i, scale + 3 * i, sums);
    if (i < n) {  // the last pairs, padded by the last one with scale 0 (no residual, no derivative)
        alignas(64) PadBuffer wi_pad, wo_pad, target_pad, scale_pad;
        for (std::int64_t lane = 0; lane < kLanes; ++lane) {
            const std::int64_t e = std::min(i + lane, n - 1);
            for (int c = 0; c < 3; ++c) {
                wi_pad[3 * lane + c] = wi[3 * e + c];
                wo_pad[3 * lane + c] = wo[3 * e + c];
                target_pad[3 * lane + c] = target[3 * e + c];
                scale_pad[3 * lane + c] = i + lane < n ? scale[3 * e + c] : 0.0f;
            }
        }
        add_normal_batch<model>(job, material, wi_pad, wo_pad, target_pad, scale_pad, sums);
    }
    auto lane_sum = [](const float* lanes) {
        double total = 0.0;
        for (std::int64_t lane = 0; lane < kLanes; ++lane) total += lanes[lane];
        return total;
    };
    const int entries = width * (width + 1) / 2;
    for (int k = 0; k < entries; ++k) job.normal[j * entries + k] = lane_sum(sums.normal[k]);
    for (int k = 0; k < width; ++k) job.gradient[j * width + k] = lane_sum(sums.gradient[k]);
    double cost = 0.0;
    for (std::int64_t lane = 0; lane < kLanes; ++lane) cost += sums.cost[lane];
    job.cost[j] = cost;
}

inline void normal_equations_range(const NormalEquationsJob& job, std::int64_t begin, std::int64_t end) {
    for (std::int64_t j = begin; j < end; ++j) {
        if (job.model == Model::kDisney2012) {
            normal_equations_of<Model::kDisney2012>(job, j);
        } else {
            normal_equations_of<Model::kDisney2014>(job, j);
        }
    }
}
