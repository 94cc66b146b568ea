// Part of kernel.hpp, included inside the per-arch namespace: the sampling
// loop. Per element: uniforms (given or counter-based), lobe, wi, the mixture
// pdf at (wi, wo) and weight = f cos θl / pdf, 0 below the horizon.
#pragma once  // (per translation unit)

// A batch goes through three stages, each a function of the previous one's
// result: choose (wo, the uniforms, FV, the lobe), draw (wi and the Smith
// denominator of wo) and weigh (f, pdf, weight; the stores). What passes
// between stages is kept small: the rest of what depends on wo alone is
// recomputed, which is cheaper than holding it in registers across the other
// batches' work (see sample_loop).

struct Chosen {
    Vec3<Floats> wo;
    Uniforms<Floats> u;
    LobeWeights<Floats> weights;
    LobeChoice<Floats> lobe;
    Floats fv;
};

// The 2015 models' first stage (model/bsdf2015.hpp's choose2015).
struct Chosen2015Batch {
    Vec3<Floats> wo;
    Uniforms<Floats> u;
    Chosen2015<Floats> chosen;
};

// What passes between the stages of a batch of `model`, and the material's constants.
template <Model model>
using ChosenOf = std::conditional_t<is_bsdf(model), Chosen2015Batch, Chosen>;
template <Model model>
using DrawnOf = std::conditional_t<is_bsdf(model), Drawn2015<Floats>, Direction<Floats>>;
template <Model model>
using SamplingShading = decltype(model_shading_of<model>(std::declval<const RawMaterial&>()));

// wo and the uniforms (given or counter-based); false, with nothing loaded,
// when the fast direction test does not accept wo
template <Layouts layouts, class Batch>
PB_KERNEL_INLINE bool load_inputs(const SampleJob& job, std::int64_t i, const CounterSeed& seed, Batch& c) {
    c.wo = load_vec3<layouts>(job.wo, i);
    if (job.check.enabled && !all(surely_unit_length(c.wo, job.check))) return false;
    if (job.u.data != nullptr) {
        Vec3<Floats> given = load_vec3<layouts>(job.u, i);
        c.u = {given.x, given.y, given.z};
    } else {
        c.u = counter_uniforms(static_cast<std::uint64_t>(job.first_index) + static_cast<std::uint64_t>(i), seed);
    }
    return true;
}

PB_KERNEL_INLINE void choose_lobe_for(Chosen& c, const Shading<Floats>& s) {
    c.fv = schlick_weight(c.wo.z);
    c.weights = lobe_weights(c.fv, s);
    c.lobe = choose_lobe(c.u.u0, s, c.weights);
}

// false, with nothing computed, when the fast direction test does not accept wo
template <Model model, Layouts layouts>
PB_KERNEL_INLINE bool choose(const SampleJob& job, std::int64_t i, const SamplingShading<model>& s, const CounterSeed& seed,
                             ChosenOf<model>& c) {
    if (!load_inputs<layouts>(job, i, seed, c)) return false;
    if constexpr (is_bsdf(model)) {
        c.chosen = choose2015(c.wo, c.u.u0, s);
    } else {
        choose_lobe_for(c, s);
    }
    return true;
}

template <Model model>
PB_KERNEL_INLINE DrawnOf<model> draw(const SampleJob& job, const ChosenOf<model>& c, const SamplingShading<model>& s) {
    if constexpr (is_bsdf(model)) {
        return draw2015(c.wo, c.u, c.chosen, s, job.sampler);
    } else {
        return sample_direction(c.wo, c.u, c.lobe, s, job.sampler);
    }
}

// Stores a batch's sample; with_lobes also each lobe's share of the weight,
// the fifth (the multiple-scattering lobe's) given.
template <Layouts layouts, bool with_lobes>
PB_KERNEL_INLINE void store_sample(const SampleJob& job, std::int64_t i, const LobeChoice<Floats>& lobe,
                                   const Weighed<Floats>& w, const Shading<Floats>& s,
                                   const Rgb<Floats>& multiple_scattering_share) {
    store_rgb<layouts>(job.wi, i, Rgb<Floats>{w.wi.x, w.wi.y, w.wi.z});
    w.pdf.store_unaligned(job.pdf + i);
    store_rgb<layouts>(job.weight, i, w.weight);
    if constexpr (with_lobes) {
        LobeColors<Floats> shares = w.lobes.colors(s, Rgb<Floats>{Floats(0.0f), Floats(0.0f), Floats(0.0f)});
        for (Rgb<Floats>& share : shares) share = w.share(share);
        lobe_of(shares, Lobe::kMultipleScattering) = multiple_scattering_share;
        store_lobes<layouts>(job.lobe_weight, i, shares, [](const Rgb<Floats>& share) { return share; });
    }
    // the indices' int32 bit patterns selected as floats: no conversion
    auto index_bits = [](std::int32_t index) { return xsimd::bitwise_cast<Floats>(Ints(index)); };
    Floats lobe_index = select(lobe.cosine, index_bits(0), select(lobe.specular, index_bits(1), index_bits(2)));
    xsimd::bitwise_cast<Ints>(lobe_index).store_unaligned(job.lobe + i);
}

// The 2015 models' sample, stored as store_sample's.
template <Layouts layouts, bool with_lobes, class S>
PB_KERNEL_INLINE void store_sample2015(const SampleJob& job, std::int64_t i, const Sample2015<Floats>& drawn, const S& s) {
    store_rgb<layouts>(job.wi, i, Rgb<Floats>{drawn.wi.x, drawn.wi.y, drawn.wi.z});
    drawn.pdf.store_unaligned(job.pdf + i);
    store_rgb<layouts>(job.weight, i, drawn.weight);
    if constexpr (with_lobes) {
        auto share = [&](const Rgb<Floats>& lobe) { return drawn.scale * lobe; };  // (scale is 0 where no sample)
        store_lobes<layouts>(job.lobe_weight, i, drawn.lobes.rgb(s).colors(), share);
    }
    // the indices' int32 bit patterns selected as floats: no conversion
    auto index_bits = [](std::int32_t index) { return xsimd::bitwise_cast<Floats>(Ints(index)); };
    const LobeChoice<Floats>& reflected = drawn.choice.reflected;
    Floats reflected_index = select(reflected.cosine, index_bits(0), select(reflected.specular, index_bits(1), index_bits(2)));
    Floats lobe_index = select(drawn.choice.transmission, index_bits(3),
                               select(drawn.choice.diffuse_transmission, index_bits(4), reflected_index));
    xsimd::bitwise_cast<Ints>(lobe_index).store_unaligned(job.lobe + i);
}

template <Model model, Layouts layouts, bool with_lobes, LobeSet lobes = LobeSet::kAll>
PB_KERNEL_INLINE void weigh(const SampleJob& job, std::int64_t i, const ChosenOf<model>& c, const DrawnOf<model>& d,
                            const SamplingShading<model>& s) {
    static_assert(!with_lobes || lobes == LobeSet::kAll, "each lobe's share needs every lobe's value");
    if constexpr (is_bsdf(model)) {
        store_sample2015<layouts, with_lobes>(job, i, weigh2015<lobes>(c.wo, c.chosen, d, s, job.sampler, job.mode), s);
    } else {
        Rgb<Floats> zero{Floats(0.0f), Floats(0.0f), Floats(0.0f)};
        store_sample<layouts, with_lobes>(job, i, c.lobe, weigh<model, lobes>(c.wo, c.fv, c.weights, d, s, job.sampler), s, zero);
    }
}

// The energy compensation's batch (model/energy.hpp): the multiple-scattering
// lobe's weight w3 at wo joins the cosine lobe's, f_ms the weight (and the
// lobe shares, as the fifth). Batch after batch, not pipelined.
template <Model model, bool per_element, Layouts layouts, bool with_lobes>
PB_KERNEL_INLINE bool sample_compensated_batch(const SampleJob& job, std::int64_t i, const Shading<Floats>& uniform,
                                               const MultipleScatteringLobe<Floats>& uniform_ms, const CounterSeed& seed) {
    Shading<Floats> per_batch;
    MultipleScatteringLobe<Floats> per_batch_ms;
    if constexpr (per_element) {
        RawMaterial m = load_material(job.params, i);
        per_batch = shading_of(m);
        per_batch_ms = multiple_scattering_of(m.slot, per_batch, model);
    }
    const Shading<Floats>& material = per_element ? per_batch : uniform;
    const MultipleScatteringLobe<Floats>& ms = per_element ? per_batch_ms : uniform_ms;
    Chosen c;
    if (!load_inputs<layouts>(job, i, seed, c)) return false;
    Floats missing_wo = ms.missing_energy(c.wo.z);
    Shading<Floats> s = with_multiple_scattering_weight(material, ms.weight(missing_wo));
    choose_lobe_for(c, s);
    CompensatedWeighed<Floats> cw =
            weigh_compensated<model>(c.wo, c.fv, c.weights, draw<model>(job, c, s), s, ms, missing_wo, job.sampler);
    store_sample<layouts, with_lobes>(job, i, c.lobe, cw.weighed, s, cw.weighed.share(cw.multiple_scattering));
    return true;
}

template <Model model, bool per_element, Layouts layouts, bool with_lobes, bool compensated = false,
          LobeSet lobes = LobeSet::kAll>
PB_KERNEL_INLINE bool sample_one_batch(const SampleJob& job, std::int64_t i, const SamplingShading<model>& uniform,
                                       const MultipleScatteringLobe<Floats>& uniform_ms, const CounterSeed& seed) {
    if constexpr (compensated) {
        return sample_compensated_batch<model, per_element, layouts, with_lobes>(job, i, uniform, uniform_ms, seed);
    }
    RawMaterial m;  // (per element only)
    SamplingShading<model> per_batch;
    if constexpr (per_element) {
        m = load_material(job.params, i);
        per_batch = model_shading_of<model>(m, job.energy_compensation);
    }
    const SamplingShading<model>& s = per_element ? per_batch : uniform;
    ChosenOf<model> chosen;
    if (!choose<model, layouts>(job, i, s, seed, chosen)) return false;
    DrawnOf<model> drawn = draw<model>(job, chosen, s);
    if constexpr (per_element && !with_lobes) {  // the batch's LobeSet, when all its lanes agree (as eval's)
        switch (lobe_set_of<model>(m)) {
            case LobeSet::kSpecular: weigh<model, layouts, false, LobeSet::kSpecular>(job, i, chosen, drawn, s); return true;
            case LobeSet::kPlain: weigh<model, layouts, false, LobeSet::kPlain>(job, i, chosen, drawn, s); return true;
            default: break;
        }
    }
    weigh<model, layouts, with_lobes, lobes>(job, i, chosen, drawn, s);
    return true;
}

// The last pad.count < kLanes elements as one batch: one_batch(padded job)
// runs the batch at element 0 of a job over padded copies (Layouts::kMixed).
template <bool with_lobes, class OneBatch>
bool sample_tail(const SampleJob& job, const Padding& pad, const OneBatch& one_batch) {
    alignas(64) PadBuffer wo, u, params[kParamSlots], wi, weight, lobe_weight[kLobeCount];
    alignas(64) float pdf[kLanes];
    alignas(64) std::int32_t lobe[kLanes];
    SampleJob padded = job;
    padded.wo = pad_vec3(job.wo, pad, wo);
    if (job.u.data != nullptr) padded.u = pad_vec3(job.u, pad, u);
    pad_params(job.params, padded.params, pad, params);
    padded.wi = MutableVec3Array{wi, Vec3Layout::kInterleaved, 0};
    padded.weight = MutableVec3Array{weight, Vec3Layout::kInterleaved, 0};
    if (with_lobes)
        for (int k = 0; k < kLobeCount; ++k) padded.lobe_weight[k] = MutableVec3Array{lobe_weight[k], Vec3Layout::kInterleaved, 0};
    padded.pdf = pdf;
    padded.lobe = lobe;
    padded.first_index = job.first_index + pad.begin;  // the generator sees the true element indices

    if (!one_batch(padded)) return false;

    unpad_vec3(job.wi, pad, wi);
    unpad_vec3(job.weight, pad, weight);
    if (with_lobes)
        for (int k = 0; k < kLobeCount; ++k) unpad_vec3(job.lobe_weight[k], pad, lobe_weight[k]);
    unpad_scalars(job.pdf, pad, pdf);
    unpad_scalars(job.lobe, pad, lobe);
    return true;
}

// One batch between its stages: chosen, then drawn.
template <Model model>
struct InFlight {
    ChosenOf<model> chosen;
    DrawnOf<model> drawn;
};

// One step of the pipeline: weigh the batch at i, draw the next one, choose
// the one after it at i + 2 kLanes (false when the fast direction test does
// not accept that one's wo).
template <Model model, Layouts layouts, LobeSet lobes>
PB_KERNEL_INLINE bool pipeline_step(const SampleJob& job, std::int64_t i, const SamplingShading<model>& s,
                                    const CounterSeed& seed, InFlight<model>& weighed, InFlight<model>& drawn,
                                    InFlight<model>& chosen) {
    weigh<model, layouts, false, lobes>(job, i, weighed.chosen, weighed.drawn, s);
    drawn.drawn = draw<model>(job, drawn.chosen, s);
    return choose<model, layouts>(job, i + 2 * kLanes, s, seed, chosen.chosen);
}

// Software-pipelined over batches: while batch b is weighed, batch b + 1
// draws its direction and batch b + 2 chooses its lobe. The stages of one
// batch are one long dependency chain (uniforms, lobe, direction, f and pdf)
// longer than the out-of-order window, so batches run one after another
// barely overlap; interleaved, the independent work of three batches fills
// the wait. Each batch stays in one of three slots from its choice to its
// weight, the slots' roles rotating through a loop unrolled three times, so
// nothing is copied from variable to variable (a copy of the spilled part of
// a batch's state through the stack, every batch, is what the rotation
// avoids). The batches before and after the loop run the same operations in
// other copies of the code, to the same bits (no contraction, see
// simd_ops.hpp). Uniform materials only: with per-element materials each
// batch's Shading in flight would not fit in the registers, so their batches
// run one after another. Returns -1 with
// every element of [begin, end) written, or the start of the first batch the
// fast direction test did not accept, every element before it written (see
// run_checked).
template <Model model, bool per_element, Layouts layouts, bool with_lobes, bool compensated, LobeSet lobes>
std::int64_t sample_loop(const SampleJob& job, std::int64_t begin, std::int64_t end) {
    SamplingShading<model> uniform{};
    MultipleScatteringLobe<Floats> uniform_ms{};
    BlendedEnergyRow row;  // (left uninitialised; the loops without the compensation never touch it)
    if constexpr (!per_element) {
        RawMaterial m = load_material(job.params, 0);
        uniform = model_shading_of<model>(m, job.energy_compensation);
        if constexpr (compensated) {
            uniform_ms = multiple_scattering_of(m.slot, uniform, model);
            row.template use_for<model>(uniform_ms);
        }
    }
    CounterSeed seed = counter_seed(job.seed);
    const std::int64_t batches = (end - begin) / kLanes;
    auto at = [&](std::int64_t b) { return begin + b * kLanes; };
    std::int64_t b = 0;
    if constexpr (!per_element && !with_lobes && !compensated) {
        if (batches >= 5) {
            InFlight<model> slot0, slot1, slot2;
            // a stop at a batch first weighs the one drawn before it, so that
            // every element before the returned batch is written
            if (!choose<model, layouts>(job, at(0), uniform, seed, slot0.chosen)) return at(0);
            if (!choose<model, layouts>(job, at(1), uniform, seed, slot1.chosen)) {
                weigh<model, layouts, false, lobes>(job, at(0), slot0.chosen, draw<model>(job, slot0.chosen, uniform), uniform);
                return at(1);
            }
            slot0.drawn = draw<model>(job, slot0.chosen, uniform);
            // here and after each step: slot0 holds batch b, drawn, and slot1 batch b + 1, chosen
            for (; b + 4 < batches; b += 3) {
                if (!pipeline_step<model, layouts, lobes>(job, at(b), uniform, seed, slot0, slot1, slot2))
                    { weigh<model, layouts, false, lobes>(job, at(b + 1), slot1.chosen, slot1.drawn, uniform); return at(b + 2); }
                if (!pipeline_step<model, layouts, lobes>(job, at(b + 1), uniform, seed, slot1, slot2, slot0))
                    { weigh<model, layouts, false, lobes>(job, at(b + 2), slot2.chosen, slot2.drawn, uniform); return at(b + 3); }
                if (!pipeline_step<model, layouts, lobes>(job, at(b + 2), uniform, seed, slot2, slot0, slot1))
                    { weigh<model, layouts, false, lobes>(job, at(b + 3), slot0.chosen, slot0.drawn, uniform); return at(b + 4); }
            }
            weigh<model, layouts, false, lobes>(job, at(b), slot0.chosen, slot0.drawn, uniform);
            weigh<model, layouts, false, lobes>(job, at(b + 1), slot1.chosen, draw<model>(job, slot1.chosen, uniform), uniform);
            b += 2;
        }
    }
    for (; b < batches; ++b)
        if (!sample_one_batch<model, per_element, layouts, with_lobes, compensated, lobes>(job, at(b), uniform, uniform_ms, seed))
            return at(b);
    const std::int64_t i = begin + batches * kLanes;
    auto one_batch = [&](const SampleJob& padded) {
        return sample_one_batch<model, per_element, Layouts::kMixed, with_lobes, compensated, lobes>(padded, 0, uniform, uniform_ms, seed);
    };
    if (i < end && !sample_tail<with_lobes>(job, Padding{i, end - i}, one_batch)) return i;
    return -1;
}

template <Model model, bool per_element, Layouts layouts, bool with_lobes = false, bool compensated = false,
          LobeSet lobes = LobeSet::kAll>
std::int64_t sample_checked(const SampleJob& job, std::int64_t begin, std::int64_t end) {
    auto rejected = [&](std::int64_t i) { return !unit_length_at(job.wo, i, job.check); };
    return run_checked(job, begin, end, sample_loop<model, per_element, layouts, with_lobes, compensated, lobes>, rejected);
}

// A uniform material's pipelined loop for its LobeSet, as eval's (a
// per-element batch's weight takes its LobeSet in sample_one_batch; the draw
// already skips the parts of the lobes no lane chose).
template <Model model, bool per_element, Layouts layouts>
std::int64_t sample_checked_for_lobes(const SampleJob& job, std::int64_t begin, std::int64_t end) {
    if constexpr (!per_element) {
        switch (lobe_set_of<model>(job.params)) {
            case LobeSet::kSpecular: return sample_checked<model, false, layouts, false, false, LobeSet::kSpecular>(job, begin, end);
            case LobeSet::kPlain: return sample_checked<model, false, layouts, false, false, LobeSet::kPlain>(job, begin, end);
            default: break;
        }
    }
    return sample_checked<model, per_element, layouts>(job, begin, end);
}

// -1 with every element written, or the first element whose wo fails the direction check.
template <Model model, bool per_element>
std::int64_t sample_range_for(const SampleJob& job, std::int64_t begin, std::int64_t end) {
    // the energy compensation: batch after batch, any layout (model/energy.hpp)
    if constexpr (has_energy_table(model)) {
        if (job.energy_compensation)
            return job.lobe_weight[0].data != nullptr
                           ? sample_checked<model, per_element, Layouts::kMixed, true, true>(job, begin, end)
                           : sample_checked<model, per_element, Layouts::kMixed, false, true>(job, begin, end);
    }
    // each lobe's share as well (the albedo's split): batch after batch, any layout
    if (job.lobe_weight[0].data != nullptr) return sample_checked<model, per_element, Layouts::kMixed, true>(job, begin, end);
    Vec3Layout layout = job.wo.layout;
    const bool uniform_layout = (layout == Vec3Layout::kInterleaved || layout == Vec3Layout::kRows) &&
                                job.wi.layout == layout && job.weight.layout == layout &&
                                (job.u.data == nullptr || job.u.layout == layout);
    if (uniform_layout && layout == Vec3Layout::kInterleaved)
        return sample_checked_for_lobes<model, per_element, Layouts::kInterleaved>(job, begin, end);
    if (uniform_layout && layout == Vec3Layout::kRows && !is_bsdf(model))  // (the 2015 models' (3, N): the mixed loop)
        return sample_checked_for_lobes<model, per_element, Layouts::kRows>(job, begin, end);
    return sample_checked<model, per_element, Layouts::kMixed>(job, begin, end);
}

// The job's model's sampling loops, for a uniform material or per-element ones.
template <bool per_element>
std::int64_t sample_job_range(const SampleJob& job, std::int64_t begin, std::int64_t end) {
    return with_model(job.model, [&](auto model) { return sample_range_for<model(), per_element>(job, begin, end); });
}
