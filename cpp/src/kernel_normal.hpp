// Part of kernel.hpp, included inside the per-arch namespace: the normal
// equations of least-squares fits (NormalEquationsJob in batch.hpp;
// docs/fitting.md). Each problem's material is prepared once; its pairs go
// through eval_gradient a batch of lanes at a time, and a sink keeps the
// wanted columns of a tile of batches on the stack, where they are scaled by
// the loss's derivative; JᵀJ's per-lane sums take a tile at a time, a few
// entries held in registers over the tile's batches (the sums are the same
// as batch by batch: each entry adds its batches in order). The lanes are
// added up in float64, in lane order, when the problem is done. The 2012 and
// 2014 models take eval_gradient's columns (kGradientSlots of them), the 2015
// models eval_gradient2015's (every slot of the table).
#pragma once  // (per translation unit)

// Batches whose columns are kept before JᵀJ's sums take them.
constexpr int kNormalTile = 4;

// A batch's wanted columns, by channel and column (eval_gradient's sink writes them).
using BatchColumns = float[3][kParamSlots][kLanes];

struct NormalSink {
    const Columns& columns;
    BatchColumns& column;

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

// r = (u(x) - t) s and ∂r/∂x = u'(x) s for one channel of a batch.
struct ChannelResidual {
    Floats residual, slope;
};

PB_KERNEL_INLINE ChannelResidual channel_residual(Loss loss, Floats x, Floats target, Floats scale) {
    if (loss == Loss::kLog) return {(xsimd::log1p(x) - target) * scale, scale / (Floats(1.0f) + x)};
    return {(x - target) * scale, scale};
}

// A problem's material, prepared for its derivatives: the 2015 models' pass
// by pass (model/bsdf2015_gradient.hpp), the others' with their partials.
template <Model model>
using NormalMaterial = std::conditional_t<is_bsdf(model), GradientShading2015<Shading2015<model, PassDual<Floats>>>,
                                          Prepared<Output::kGradient>>;

template <Model model>
PB_KERNEL_INLINE NormalMaterial<model> prepare_normal(const RawMaterial& m) {
    if constexpr (is_bsdf(model)) {
        return gradient_shading2015_of<Shading2015<model, PassDual<Floats>>>(m.slot);
    } else {
        return prepare<Output::kGradient>(m);
    }
}

// f of one batch, as eval_grad gives it (times cos θl with job.cosine, |cos θl|
// for the 2015 models; the BRDFs 0 below the surface), its wanted columns to `sink`.
template <Model model>
PB_KERNEL_INLINE Rgb<Floats> normal_batch_gradient(const NormalEquationsJob& job, const NormalMaterial<model>& material,
                                                   const Vec3<Floats>& wi, const Vec3<Floats>& wo, NormalSink& sink) {
    if constexpr (is_bsdf(model)) {
        return eval_gradient2015(wi, wo, material, TransportMode::kRadiance, job.cosine, sink);
    } else {
        const Shading<Floats>& s = material.shading;
        Geometry<Floats> g = geometry_of(wi, wo);
        Mask above = above_surface(g);
        View<Floats> view = view_of<model>(wo, s);
        // as eval_grad's: x cos θl or x times 1, then 0 below the surface
        Floats cosine_weight = job.cosine ? wi.z : Floats(1.0f);
        auto masked = [&](Floats x) { return select(above, cosine_weight * x, Floats(0.0f)); };
        Rgb<Floats> f = eval_gradient<model>(g, s, view, material.partials, masked, sink);
        return {masked(f.r), masked(f.g), masked(f.b)};
    }
}

// One batch of kLanes pairs of a problem: its cost and Jᵀr into the sums, its
// scaled columns ∂r_c/∂p_k into `column` for JᵀJ (add_normal_tile). wi, wo,
// target and scale point at the batch's first pair ((kLanes, 3) each), gain
// is the problem's g.
template <Model model>
PB_KERNEL_INLINE void add_normal_batch(const NormalEquationsJob& job, const NormalMaterial<model>& material,
                                       const float* wi_data, const float* wo_data, const float* target_data,
                                       const float* scale_data, Floats gain, BatchColumns& column, NormalSums& sums) {
    Vec3<Floats> wi, wo;
    load_interleaved(wi_data, wi.x, wi.y, wi.z);
    load_interleaved(wo_data, wo.x, wo.y, wo.z);
    NormalSink sink{job.columns, column};
    Rgb<Floats> f = normal_batch_gradient<model>(job, material, wi, wo, sink);
    Rgb<Floats> target, scale;
    load_interleaved(target_data, target.r, target.g, target.b);
    load_interleaved(scale_data, scale.r, scale.g, scale.b);
    ChannelResidual channel[3];
    for (int c = 0; c < 3; ++c) {
        channel[c] = channel_residual(job.loss, gain * channel_of(f, c), channel_of(target, c), channel_of(scale, c));
        channel[c].slope *= gain;  // ∂r/∂f = u'(g f) g s
    }

    alignas(64) float squares[kLanes];
    mul_add(channel[0].residual, channel[0].residual,
            mul_add(channel[1].residual, channel[1].residual, channel[2].residual * channel[2].residual))
            .store_aligned(squares);
    for (std::int64_t lane = 0; lane < kLanes; ++lane) sums.cost[lane] += squares[lane];

    // ∂r_c/∂p_k = u'(f_c) s_c ∂f_c/∂p_k, in place, and Jᵀr
    const int width = job.columns.count;
    for (int k = 0; k < width; ++k) {
        Floats a0 = channel[0].slope * Floats::load_aligned(column[0][k]);
        Floats a1 = channel[1].slope * Floats::load_aligned(column[1][k]);
        Floats a2 = channel[2].slope * Floats::load_aligned(column[2][k]);
        a0.store_aligned(column[0][k]);
        a1.store_aligned(column[1][k]);
        a2.store_aligned(column[2][k]);
        Floats gradient = Floats::load_aligned(sums.gradient[k]);
        gradient = mul_add(a0, channel[0].residual, mul_add(a1, channel[1].residual, mul_add(a2, channel[2].residual, gradient)));
        gradient.store_aligned(sums.gradient[k]);
    }
}

// Σ over channels of column k times column l of one batch, added to sum.
PB_KERNEL_INLINE Floats add_product(const BatchColumns& column, int k, int l, Floats sum) {
    return mul_add(Floats::load_aligned(column[0][k]), Floats::load_aligned(column[0][l]),
                   mul_add(Floats::load_aligned(column[1][k]), Floats::load_aligned(column[1][l]),
                           mul_add(Floats::load_aligned(column[2][k]), Floats::load_aligned(column[2][l]), sum)));
}

// JᵀJ's per-lane sums (upper triangle by rows) over the first `batches` of a
// tile, four entries of a row at a time kept in registers over the batches.
PB_KERNEL_INLINE void add_normal_tile(const BatchColumns* tile, int batches, int width, NormalSums& sums) {
    for (int k = 0; k < width; ++k) {
        float(*row)[kLanes] = sums.normal + (k * width - k * (k - 1) / 2) - k;  // row[l] is entry (k, l)
        int l = k;
        for (; l + 4 <= width; l += 4) {
            Floats s0 = Floats::load_aligned(row[l]), s1 = Floats::load_aligned(row[l + 1]);
            Floats s2 = Floats::load_aligned(row[l + 2]), s3 = Floats::load_aligned(row[l + 3]);
            for (int t = 0; t < batches; ++t) {
                s0 = add_product(tile[t], k, l, s0);
                s1 = add_product(tile[t], k, l + 1, s1);
                s2 = add_product(tile[t], k, l + 2, s2);
                s3 = add_product(tile[t], k, l + 3, s3);
            }
            s0.store_aligned(row[l]);
            s1.store_aligned(row[l + 1]);
            s2.store_aligned(row[l + 2]);
            s3.store_aligned(row[l + 3]);
        }
        for (; l < width; ++l) {
            Floats sum = Floats::load_aligned(row[l]);
            for (int t = 0; t < batches; ++t) sum = add_product(tile[t], k, l, sum);
            sum.store_aligned(row[l]);
        }
    }
}

// Problem job.problems[j]'s sums, written to its rows of the outputs.
template <Model model>
void normal_equations_of(const NormalEquationsJob& job, std::int64_t j) {
    const std::int64_t b = job.problems[j];
    const std::int64_t n = job.pairs;
    constexpr int stored = gradient_slots(model);  // a row of job.slots
    RawMaterial m;
    for (int s = 0; s < stored; ++s) m.slot[s] = Floats(job.slots[b * stored + s]);
    for (int s = stored; s < kParamSlots; ++s) m.slot[s] = Floats(static_cast<float>(default_of(Param(s))));
    NormalMaterial<model> material = prepare_normal<model>(m);
    Floats gain(job.gain != nullptr ? job.gain[b] : 1.0f);
    const std::int64_t directions = job.per_problem_directions ? 3 * n * b : 0;
    const float* wi = job.wi + directions;
    const float* wo = job.wo + directions;
    const float* target = job.target + 3 * n * b;
    const float* scale = job.scale + 3 * n * b;
    const int width = job.columns.count;
    NormalSums sums(width);
    alignas(64) BatchColumns tile[kNormalTile];
    int batches = 0;  // in the tile
    std::int64_t i = 0;
    for (; i + kLanes <= n; i += kLanes) {
        add_normal_batch<model>(job, material, wi + 3 * i, wo + 3 * i, target + 3 * i, scale + 3 * i, gain, tile[batches], sums);
        if (++batches == kNormalTile) {
            add_normal_tile(tile, batches, width, sums);
            batches = 0;
        }
    }
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
        add_normal_batch<model>(job, material, wi_pad, wo_pad, target_pad, scale_pad, gain, tile[batches], sums);
        ++batches;
    }
    if (batches > 0) add_normal_tile(tile, batches, width, sums);
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
    with_model(job.model, [&](auto model) {
        for (std::int64_t j = begin; j < end; ++j) normal_equations_of<model()>(job, j);
        return 0;
    });
}
