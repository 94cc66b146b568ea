// Part of kernel.hpp, included inside the per-arch namespace: the 2015
// models' evaluation loop, the solid's and the thin sheet's
// (model/bsdf2015.hpp): f, its lobes, the sampling
// pdf, f with the pdf, the Jacobian in the parameter slots and its product
// with a cotangent (model/bsdf2015_gradient.hpp), over the whole sphere, in
// any layout.
#pragma once  // (per translation unit)

// The derivatives in the directions: the constants for f, and over dual numbers of double without tangents.
struct DirectionShading2015 {
    Shading2015<Floats> shading;
    Halves<Shading2015<PassDual<Doubles>>> directions;
};

// What a batch needs of its material: the constants, over dual numbers for the
// derivatives in the parameters (with their tangents).
template <Output output>
using Prepared2015 = std::conditional_t<differentiates(output), GradientShading2015<Floats>,
                                        std::conditional_t<in_directions(output), DirectionShading2015, Shading2015<Floats>>>;

template <Output output>
PB_KERNEL_INLINE Prepared2015<output> prepare2015(const RawMaterial& m, bool thin) {
    if constexpr (differentiates(output)) {
        return gradient_shading2015_of(m.slot, thin);
    } else if constexpr (in_directions(output)) {
        return DirectionShading2015{shading2015_of(m.slot, thin),
                                    halves_of(m, [&](const Doubles* p) { return constant_shading2015_of(p, thin); })};
    } else {
        return shading2015_of(m.slot, thin);
    }
}

PB_KERNEL_INLINE Floats absolute(Floats x) { return xsimd::abs(x); }

template <Output output, Layouts layouts>
PB_KERNEL_INLINE void eval2015_batch(const EvalJob& job, std::int64_t i, const Vec3<Floats>& wi, const Vec3<Floats>& wo,
                                     const Prepared2015<output>& s) {
    auto weighted = [&](const Rgb<Floats>& c) { return job.cosine ? absolute(wi.z) * c : c; };
    if constexpr (differentiates(output)) {
        derivative_batch<output == Output::kGradient, JacobianStore<layouts>, VjpSink<layouts>, layouts>(
                job, i, [&](auto& target) { return eval_gradient2015(wi, wo, s, job.mode, job.cosine, target); });
    } else if constexpr (in_directions(output)) {
        auto differentiate = [&](int half, const Vec3<Doubles>& w_i, const Vec3<Doubles>& w_o, auto& jacobian) {
            return eval_direction_gradient2015(w_i, w_o, s.directions[half], job.mode, job.cosine, jacobian);
        };
        auto value = [&] { return weighted(eval_lobes2015(wi, wo, s.shading, job.mode).total()); };  // as f alone
        direction_batch<output, layouts>(job, i, wi, wo, differentiate, value);
    } else if constexpr (output == Output::kPdf) {
        pdf2015(wi, wo, s, job.sampler).store_unaligned(job.pdf + i);
    } else if constexpr (output == Output::kLobes) {
        Lobes2015<Floats> lobes = eval_lobes2015(wi, wo, s, job.mode);
        Rgb<Floats> zero{Floats(0.0f), Floats(0.0f), Floats(0.0f)};
        store_rgb<layouts>(job.out[0], i, weighted(lobes.diffuse));
        store_rgb<layouts>(job.out[1], i, weighted(lobes.sheen));
        store_rgb<layouts>(job.out[2], i, weighted(lobes.specular));
        store_rgb<layouts>(job.out[3], i, weighted(lobes.clearcoat));
        store_rgb<layouts>(job.out[4], i, zero);
        store_rgb<layouts>(job.out[5], i, weighted(lobes.transmission));
        store_rgb<layouts>(job.out[6], i, weighted(lobes.diffuse_transmission));
    } else {
        if constexpr (output == Output::kValuePdf) pdf2015(wi, wo, s, job.sampler).store_unaligned(job.pdf + i);
        store_rgb<layouts>(job.out[0], i, weighted(eval_lobes2015(wi, wo, s, job.mode).total()));
    }
}

template <Output output, bool per_element, Layouts layouts>
PB_KERNEL_INLINE bool eval2015_one_batch(const EvalJob& job, std::int64_t i, const Prepared2015<output>& uniform) {
    Vec3<Floats> wi = load_vec3<layouts>(job.wi, i);
    Vec3<Floats> wo = load_vec3<layouts>(job.wo, i);
    if (!accepted(job, wi, wo)) return false;
    if constexpr (per_element) {
        eval2015_batch<output, layouts>(job, i, wi, wo, prepare2015<output>(load_material(job.params, i), job.thin()));
    } else {
        eval2015_batch<output, layouts>(job, i, wi, wo, uniform);
    }
    return true;
}

// -1 with every element of [begin, end) written, or the start of the first
// batch the fast direction test did not accept (see run_checked).
template <Output output, bool per_element, Layouts layouts>
std::int64_t eval2015_batches(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    Prepared2015<output> uniform{};
    if constexpr (!per_element) uniform = prepare2015<output>(load_material(job.params, 0), job.thin());
    std::int64_t i = begin;
    if constexpr (!per_element && (output == Output::kTotal || output == Output::kValuePdf)) {
        // two batches a step, as eval_two_batches: the second's work fills the first's chain of divisions
        for (; i + 2 * kLanes <= end; i += 2 * kLanes) {
            Vec3<Floats> wi = load_vec3<layouts>(job.wi, i), wo = load_vec3<layouts>(job.wo, i);
            Vec3<Floats> next_wi = load_vec3<layouts>(job.wi, i + kLanes), next_wo = load_vec3<layouts>(job.wo, i + kLanes);
            if (!accepted(job, wi, wo)) return i;
            eval2015_batch<output, layouts>(job, i, wi, wo, uniform);
            if (!accepted(job, next_wi, next_wo)) return i + kLanes;
            eval2015_batch<output, layouts>(job, i + kLanes, next_wi, next_wo, uniform);
        }
    }
    for (; i + kLanes <= end; i += kLanes)
        if (!eval2015_one_batch<output, per_element, layouts>(job, i, uniform)) return i;
    auto one_batch = [&](const EvalJob& padded) { return eval2015_one_batch<output, per_element, Layouts::kMixed>(padded, 0, uniform); };
    if (i < end && !eval_tail<output>(job, Padding{i, end - i}, one_batch)) return i;
    return -1;
}

template <Output output, bool per_element>
std::int64_t eval2015_range_for(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    auto rejected = [&](std::int64_t i) { return !unit_length_at(job.wi, i, job.check) || !unit_length_at(job.wo, i, job.check); };
    // f alone gets a loop per layout; the other outputs one loop for every layout (the lobes, the pdf and
    // the derivatives' dual numbers outweigh the loads; and the fewer loops, the shorter the build)
    if constexpr (output != Output::kTotal) return run_checked(job, begin, end, eval2015_batches<output, per_element, Layouts::kMixed>, rejected);
    switch (layouts_of(job)) {
        case Layouts::kInterleaved: return run_checked(job, begin, end, eval2015_batches<output, per_element, Layouts::kInterleaved>, rejected);
        case Layouts::kRows: return run_checked(job, begin, end, eval2015_batches<output, per_element, Layouts::kRows>, rejected);
        default: return run_checked(job, begin, end, eval2015_batches<output, per_element, Layouts::kMixed>, rejected);
    }
}

template <Output output>
std::int64_t eval2015_range_of(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    return job.uniform_material() ? eval2015_range_for<output, false>(job, begin, end)
                                  : eval2015_range_for<output, true>(job, begin, end);
}

inline std::int64_t eval2015_range(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    switch (job.output) {
        case Output::kDirectionGradient: return eval2015_range_of<Output::kDirectionGradient>(job, begin, end);
        case Output::kDirectionVjp: return eval2015_range_of<Output::kDirectionVjp>(job, begin, end);
        case Output::kGradient: return eval2015_range_of<Output::kGradient>(job, begin, end);
        case Output::kVjp: return eval2015_range_of<Output::kVjp>(job, begin, end);
        case Output::kLobes: return eval2015_range_of<Output::kLobes>(job, begin, end);
        case Output::kPdf: return eval2015_range_of<Output::kPdf>(job, begin, end);
        case Output::kValuePdf: return eval2015_range_of<Output::kValuePdf>(job, begin, end);
        default: return eval2015_range_of<Output::kTotal>(job, begin, end);
    }
}
