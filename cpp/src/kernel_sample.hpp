// Part of kernel.hpp, included inside the per-arch namespace: the sampling
// loop. Per element: uniforms (given or counter-based), lobe, wi, the mixture
// pdf at (wi, wo) and weight = f cos θl / pdf, 0 below the horizon.
#pragma once  // (per translation unit)

template <Model model, bool per_element, Layouts layouts>
PB_KERNEL_INLINE bool sample_one_batch(const SampleJob& job, std::int64_t i, const Shading& uniform, const CounterKeys& keys) {
    const Vec3 wo = load_vec3<layouts>(job.wo, i);
    if (job.check_directions && !xsimd::all(unit_length(wo, job.length2_lowest, job.length2_highest))) return false;
    Shading per_batch;
    if constexpr (per_element) per_batch = shading_of(load_material(job.params, i));
    const Shading& s = per_element ? per_batch : uniform;

    Uniforms u;
    if (job.u.data != nullptr) {
        const Vec3 given = load_vec3<layouts>(job.u, i);
        u = {given.x, given.y, given.z};
    } else {
        u = counter_uniforms(static_cast<std::uint64_t>(job.first_index + i), keys);
    }
    const LobeProbabilities probabilities = lobe_probabilities(wo.z, s);
    const LobeChoice lobe = choose_lobe(u.u0, probabilities);
    const Vec3 wi = sample_direction(wo, u, lobe, s, job.sampler);

    const Geometry g = geometry_of(wi, wo);
    const Floats pdf = mixture_pdf(g, s, probabilities, job.sampler);
    const Mask valid = (wi.z > Floats(0.0f)) & (wo.z > Floats(0.0f)) & g.finite & (pdf > Floats(0.0f));
    const Rgb f = eval_lobes<model>(g, s).total(s);
    const Floats scale = wi.z * reciprocal(pdf);  // cos θl / pdf
    // select after multiplying: below the horizon f may be infinite or NaN
    auto weight = [&](Floats value) { return xsimd::select(valid, scale * value, Floats(0.0f)); };

    store_rgb<layouts>(job.wi, i, Rgb{wi.x, wi.y, wi.z});
    xsimd::select(valid, pdf, Floats(0.0f)).store_unaligned(job.pdf + i);
    store_rgb<layouts>(job.weight, i, Rgb{weight(f.r), weight(f.g), weight(f.b)});
    const Floats lobe_index = xsimd::select(lobe.cosine, Floats(0.0f), xsimd::select(lobe.specular, Floats(1.0f), Floats(2.0f)));
    xsimd::to_int(lobe_index).store_unaligned(job.lobe + i);
    return true;
}

inline std::int64_t first_bad_view(const SampleJob& job, std::int64_t begin, std::int64_t end) {
    return first_bad_direction(job.wo, begin, end, job.length2_lowest, job.length2_highest);
}

template <Model model, bool per_element>
bool sample_tail(const SampleJob& job, const Padding& pad, const Shading& uniform, const CounterKeys& keys) {
    alignas(64) PadBuffer wo, u, params[kParamSlots], wi, weight;
    alignas(64) float pdf[kLanes];
    alignas(64) std::int32_t lobe[kLanes];
    SampleJob padded = job;
    padded.wo = pad_vec3(job.wo, pad, wo);
    if (job.u.data != nullptr) padded.u = pad_vec3(job.u, pad, u);
    pad_params(job.params, padded.params, pad, params);
    padded.wi = MutableVec3Array{wi, Vec3Layout::kInterleaved, 0};
    padded.weight = MutableVec3Array{weight, Vec3Layout::kInterleaved, 0};
    padded.pdf = pdf;
    padded.lobe = lobe;
    padded.first_index = job.first_index + pad.begin;  // the generator sees the true element indices

    if (!sample_one_batch<model, per_element, Layouts::kMixed>(padded, 0, uniform, keys)) return false;

    unpad_vec3(job.wi, pad, wi);
    unpad_vec3(job.weight, pad, weight);
    unpad_scalars(job.pdf, pad, pdf);
    unpad_scalars(job.lobe, pad, lobe);
    return true;
}

template <Model model, bool per_element, Layouts layouts>
std::int64_t sample_loop(const SampleJob& job, std::int64_t begin, std::int64_t end) {
    Shading uniform{};
    if constexpr (!per_element) uniform = shading_of(load_material(job.params, 0));
    const CounterKeys keys = counter_keys(job.seed);
    std::int64_t i = begin;
    for (; i + kLanes <= end; i += kLanes)
        if (!sample_one_batch<model, per_element, layouts>(job, i, uniform, keys)) return first_bad_view(job, i, i + kLanes);
    if (i < end && !sample_tail<model, per_element>(job, Padding{i, end - i}, uniform, keys))
        return first_bad_view(job, i, end);
    return -1;
}

template <Model model, bool per_element>
std::int64_t sample_range_for(const SampleJob& job, std::int64_t begin, std::int64_t end) {
    const Vec3Layout layout = job.wo.layout;
    const bool uniform_layout = (layout == Vec3Layout::kInterleaved || layout == Vec3Layout::kRows) &&
                                job.wi.layout == layout && job.weight.layout == layout &&
                                (job.u.data == nullptr || job.u.layout == layout);
    if (uniform_layout && layout == Vec3Layout::kInterleaved)
        return sample_loop<model, per_element, Layouts::kInterleaved>(job, begin, end);
    if (uniform_layout && layout == Vec3Layout::kRows)
        return sample_loop<model, per_element, Layouts::kRows>(job, begin, end);
    return sample_loop<model, per_element, Layouts::kMixed>(job, begin, end);
}

inline std::int64_t sample_range(const SampleJob& job, std::int64_t begin, std::int64_t end) {
    const bool per_element = !uniform_material(job.params);
    if (job.model == Model::kDisney2012)
        return per_element ? sample_range_for<Model::kDisney2012, true>(job, begin, end)
                           : sample_range_for<Model::kDisney2012, false>(job, begin, end);
    return per_element ? sample_range_for<Model::kDisney2014, true>(job, begin, end)
                       : sample_range_for<Model::kDisney2014, false>(job, begin, end);
}
