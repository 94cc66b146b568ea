// Part of kernel.hpp, included inside the per-arch namespace: one batch of the
// derivatives of f in the directions (model/direction_gradient.hpp), for the
// evaluation loop of kernel_eval.hpp: the Jacobian's
// 18 values an element (Output::kDirectionGradient) or their products with a
// cotangent (Output::kDirectionVjp).
//
// The model runs over double batches here (simd_double_ops.hpp), a half batch
// at a time, and every output is rounded to float once: a derivative in a
// direction sums terms of opposite signs (the Fresnel weights' and cos θd's in
// a z column, say) whose sum can be a thousandth of the element's largest
// column, and float sums would leave it a few roundings of that column wrong
// (docs/gradients.md, "Derivatives in the directions").
#pragma once  // (per translation unit)

static_assert(kDirectionSlots == kDirectionComponents, "the model's direction slots are batch.hpp's components");

// ∂f_c/∂w_k per element: 3 channels by the 6 direction components.
inline constexpr int kDirectionJacobianWidth = 3 * kDirectionSlots;

constexpr bool in_directions(Output output) {
    return output == Output::kDirectionGradient || output == Output::kDirectionVjp;
}

// A batch's material constants over dual numbers, one set a half batch.
template <class Shading>
using Halves = std::array<Shading, kHalves>;
using DirectionShading = Halves<Shading<DirectionDual<Doubles>>>;

PB_KERNEL_INLINE std::array<Doubles, kParamSlots> half_of(const RawMaterial& m, int half) {
    std::array<Doubles, kParamSlots> slots;
    for (int k = 0; k < kParamSlots; ++k) slots[k] = half_of(m.slot[k], half);
    return slots;
}

PB_KERNEL_INLINE Vec3<Doubles> half_of(const Vec3<Floats>& w, int half) {
    return {half_of(w.x, half), half_of(w.y, half), half_of(w.z, half)};
}

// The constants `c` over dual numbers with zero tangents: what
// direction_shading_of gives (shading_of over the dual numbers, whose values
// are the same operations on F), without its work on the zero tangents (most
// of a batch's for per-element materials). Constants<F> holds F's and nothing
// else (the sizes assert it), so its k-th F is the k-th Dual's value.
template <class Dual, class F, template <class> class Constants>
PB_KERNEL_INLINE Constants<Dual> with_zero_tangents(const Constants<F>& c) {
    constexpr std::size_t count = sizeof(Constants<F>) / sizeof(F);
    static_assert(sizeof(Constants<F>) == count * sizeof(F) && sizeof(Constants<Dual>) == count * sizeof(Dual),
                  "the constants are F's alone");
    Constants<Dual> lifted;
    for (std::size_t k = 0; k < count; ++k) {
        F value;
        std::memcpy(&value, reinterpret_cast<const char*>(&c) + k * sizeof(F), sizeof(F));
        Dual constant(value);
        std::memcpy(reinterpret_cast<char*>(&lifted) + k * sizeof(Dual), &constant, sizeof(Dual));
    }
    return lifted;
}

// The constants of both halves, by shading_of(slots) (a model's or the 2015 solid's).
template <class ShadingOf>
PB_KERNEL_INLINE auto halves_of(const RawMaterial& m, ShadingOf&& shading_of) {
    std::array<Doubles, kParamSlots> low = half_of(m, 0), high = half_of(m, 1);
    return Halves<decltype(shading_of(low.data()))>{shading_of(low.data()), shading_of(high.data())};
}

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

// One batch at i of a direction output: `differentiate(half, wi, wo, jacobian)`
// runs the forward pass of half a batch in double, gives its derivatives to
// `jacobian(c, k, value)` and returns f; both halves are then rounded to float
// and given to the Jacobian's store or the product's sink. The Jacobian's f
// beside them is `value()`: eval's own float operations, so the same bits.
template <Output output, Layouts layouts, class Differentiate, class Value>
PB_KERNEL_INLINE void direction_batch(const EvalJob& job, std::int64_t i, const Vec3<Floats>& wi, const Vec3<Floats>& wo,
                                      Differentiate&& differentiate, Value&& value) {
    derivative_batch<output == Output::kDirectionGradient, DirectionJacobianStore<layouts>, DirectionVjpSink<layouts>,
                     layouts>(job, i, [&](auto& target) {
        alignas(64) double rows[kDirectionJacobianWidth][kLanes];
        for (int half = 0; half < kHalves; ++half) {
            int at = half * kHalfLanes;
            auto jacobian = [&](int c, int k, Doubles d) { d.store_aligned(rows[kDirectionSlots * c + k] + at); };
            differentiate(half, half_of(wi, half), half_of(wo, half), jacobian);
        }
        for (int c = 0; c < 3; ++c)
            for (int k = 0; k < kDirectionSlots; ++k) target(c, k, rounded_to_floats(rows[kDirectionSlots * c + k]));
        if constexpr (output == Output::kDirectionGradient) {
            return value();
        } else {
            return Rgb<Floats>{};
        }
    });
}

// One batch at i of a direction output of the 2012 and 2014 models.
template <Model model, Output output, Layouts layouts>
PB_KERNEL_INLINE void eval_direction_batch(const EvalJob& job, std::int64_t i, const Vec3<Floats>& wi, const Vec3<Floats>& wo,
                                           const Shading<Floats>& s, const DirectionShading& directions) {
    auto differentiate = [&](int half, const Vec3<Doubles>& w_i, const Vec3<Doubles>& w_o, auto& jacobian) {
        return eval_direction_gradient<model>(w_i, w_o, directions[half], job.cosine, jacobian);
    };
    auto value = [&] {  // as eval_values_batch's f
        Geometry<Floats> g = geometry_of(wi, wo);
        Mask above = above_surface(g);
        Rgb<Floats> f = eval_lobes<model>(g, s, view_of<model>(wo, s)).total(s);
        Rgb<Floats> zero{Floats(0.0f), Floats(0.0f), Floats(0.0f)};
        return select(above, job.cosine ? wi.z * f : f, zero);
    };
    direction_batch<output, layouts>(job, i, wi, wo, differentiate, value);
}
