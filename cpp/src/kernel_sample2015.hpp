// Part of kernel.hpp, included inside the per-arch namespace: the 2015
// models' sampling loop (model/bsdf2015.hpp), batch after batch, any layout.
#pragma once  // (per translation unit)

template <bool with_lobes>
PB_KERNEL_INLINE void store_sample2015(const SampleJob& job, std::int64_t i, const Sample2015<Floats>& drawn) {
    store_rgb(job.wi, i, Rgb<Floats>{drawn.wi.x, drawn.wi.y, drawn.wi.z});
    drawn.pdf.store_unaligned(job.pdf + i);
    store_rgb(job.weight, i, drawn.weight);
    if constexpr (with_lobes) {
        Rgb<Floats> zero{Floats(0.0f), Floats(0.0f), Floats(0.0f)};
        auto share = [&](const Rgb<Floats>& lobe) { return drawn.scale * lobe; };  // (scale is 0 where no sample)
        store_rgb(job.lobe_weight[0], i, share(drawn.lobes.diffuse));
        store_rgb(job.lobe_weight[1], i, share(drawn.lobes.sheen));
        store_rgb(job.lobe_weight[2], i, share(drawn.lobes.specular));
        store_rgb(job.lobe_weight[3], i, share(drawn.lobes.clearcoat));
        store_rgb(job.lobe_weight[4], i, zero);
        store_rgb(job.lobe_weight[5], i, share(drawn.lobes.transmission));
        store_rgb(job.lobe_weight[6], i, share(drawn.lobes.diffuse_transmission));
    }
    // the indices' int32 bit patterns selected as floats: no conversion
    auto index_bits = [](std::int32_t index) { return xsimd::bitwise_cast<Floats>(Ints(index)); };
    const LobeChoice<Floats>& reflected = drawn.choice.reflected;
    Floats reflected_index = select(reflected.cosine, index_bits(0), select(reflected.specular, index_bits(1), index_bits(2)));
    Floats lobe_index = select(drawn.choice.transmission, index_bits(3),
                               select(drawn.choice.diffuse_transmission, index_bits(4), reflected_index));
    xsimd::bitwise_cast<Ints>(lobe_index).store_unaligned(job.lobe + i);
}

template <bool per_element, bool with_lobes>
PB_KERNEL_INLINE bool sample2015_one_batch(const SampleJob& job, std::int64_t i, const Shading2015<Floats>& uniform,
                                           const CounterSeed& seed) {
    Chosen c;
    if (!load_inputs<Layouts::kMixed>(job, i, seed, c)) return false;
    if constexpr (per_element) {
        store_sample2015<with_lobes>(job, i, sample2015(c.wo, c.u, shading2015_of(load_material(job.params, i).slot, job.thin()), job.sampler, job.mode));
    } else {
        store_sample2015<with_lobes>(job, i, sample2015(c.wo, c.u, uniform, job.sampler, job.mode));
    }
    return true;
}

template <bool per_element, bool with_lobes>
std::int64_t sample2015_loop(const SampleJob& job, std::int64_t begin, std::int64_t end) {
    Shading2015<Floats> uniform{};
    if constexpr (!per_element) uniform = shading2015_of(load_material(job.params, 0).slot, job.thin());
    CounterSeed seed = counter_seed(job.seed);
    std::int64_t i = begin;
    for (; i + kLanes <= end; i += kLanes)
        if (!sample2015_one_batch<per_element, with_lobes>(job, i, uniform, seed)) return i;
    auto one_batch = [&](const SampleJob& padded) { return sample2015_one_batch<per_element, with_lobes>(padded, 0, uniform, seed); };
    if (i < end && !sample_tail<with_lobes>(job, Padding{i, end - i}, one_batch)) return i;
    return -1;
}

// -1 with every element written, or the first element whose wo fails the direction check.
template <bool per_element>
std::int64_t sample2015_checked(const SampleJob& job, std::int64_t begin, std::int64_t end) {
    auto rejected = [&](std::int64_t i) { return !unit_length_at(job.wo, i, job.check); };
    return job.lobe_weight[0].data != nullptr ? run_checked(job, begin, end, sample2015_loop<per_element, true>, rejected)
                                              : run_checked(job, begin, end, sample2015_loop<per_element, false>, rejected);
}
