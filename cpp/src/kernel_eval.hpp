// Part of kernel.hpp, included inside the per-arch namespace: the evaluation
// loop (f, the lobes, or the sampling pdf) over a range of elements.
#pragma once  // (per translation unit)

// What a batch needs of its material: the lobes' constants and, for the
// Jacobian in the parameters, their partials, or for the derivatives in the
// directions, the constants over dual numbers of double (nothing otherwise).
struct NoPartials {};

// The outputs that take derivatives in the parameters: the Jacobian and the vector-Jacobian product.
constexpr bool in_parameters(Output output) { return output == Output::kGradient || output == Output::kVjp; }
// The outputs with a Jacobian or a product in `jacobian` (in the parameters or in the directions).
constexpr bool has_jacobian(Output output) { return in_parameters(output) || in_directions(output); }
// The outputs that read a cotangent.
constexpr bool is_vjp(Output output) { return output == Output::kVjp || output == Output::kDirectionVjp; }

template <Output output>
struct Prepared {
    Shading<Floats> shading;
    std::conditional_t<in_parameters(output), MaterialPartials<Floats>, NoPartials> partials;
    std::conditional_t<in_directions(output), DirectionShading, NoPartials> directions;
};

template <Output output>
PB_KERNEL_INLINE Prepared<output> prepare(const RawMaterial& m) {
    // built in place: assigning into a default-constructed one would copy the whole Shading per batch
    if constexpr (in_parameters(output)) {
        return {shading_of(m), material_partials_of(m.slot), NoPartials{}};
    } else if constexpr (in_directions(output)) {
        return {shading_of(m), NoPartials{}, halves_of(m, [](const Doubles* p) {
                    return with_zero_tangents<DirectionDual<Doubles>>(shading_of(p));
                })};
    } else {
        return {shading_of(m), NoPartials{}, NoPartials{}};
    }
}

// The f values an element of `output` writes to job.out (0 to kLobeCount).
constexpr int value_outputs(Output output) {
    return output == Output::kLobes ? kLobeCount : output == Output::kPdf || is_vjp(output) ? 0 : 1;
}

// With the energy compensation (model/energy.hpp): the multiple-scattering
// lobe's constants as well (its own type, so that the loops without the
// option hold none of its code).
template <Output output>
struct CompensatedPrepared : Prepared<output> {
    MultipleScatteringLobe<Floats> ms;
};

// The 2015 models' (model/bsdf2015.hpp): their constants, over dual numbers for
// the derivatives in the parameters (with their tangents) or, for those in
// the directions, over dual numbers of double without tangents as well.
template <Model model>
struct DirectionShading2015 {
    Shading2015<model, Floats> shading;
    Halves<Shading2015<model, PassDual<Doubles>>> directions;
};

template <Model model, Output output>
using Prepared2015 = std::conditional_t<
        in_parameters(output), GradientShading2015<Shading2015<model, PassDual<Floats>>>,
        std::conditional_t<in_directions(output), DirectionShading2015<model>, Shading2015<model, Floats>>>;

// What a batch of `model` needs of its material.
template <Model model, Output output, bool compensated>
using PreparedOf = std::conditional_t<is_bsdf(model), Prepared2015<model, output>,
                                      std::conditional_t<compensated, CompensatedPrepared<output>, Prepared<output>>>;

// (`compensated` a template parameter: the BRDFs' energy compensation, a type of
// its own; `bsdf_compensated` the 2015 solid's, a value of its constants.)
template <Model model, Output output, bool compensated>
PB_KERNEL_INLINE PreparedOf<model, output, compensated> prepare_for(const RawMaterial& m, bool bsdf_compensated = false) {
    static_assert(!compensated || has_energy_table(model), "the energy compensation needs the model's table");
    if constexpr (is_bsdf(model) && in_parameters(output)) {
        return gradient_shading2015_of<Shading2015<model, PassDual<Floats>>>(m.slot, bsdf_compensated);
    } else if constexpr (is_bsdf(model) && in_directions(output)) {
        return DirectionShading2015<model>{model_shading_of<model>(m, bsdf_compensated), halves_of(m, [&](const Doubles* p) {
                                               return constant_shading2015_of<Shading2015<model, PassDual<Doubles>>>(p, bsdf_compensated);
                                           })};
    } else if constexpr (is_bsdf(model)) {
        return model_shading_of<model>(m, bsdf_compensated);
    } else if constexpr (compensated) {
        Shading<Floats> s = shading_of(m);
        return {{s, NoPartials{}, NoPartials{}}, multiple_scattering_of(m.slot, s, model)};
    } else {
        return prepare<output>(m);
    }
}

// `width` rows of kLanes values as kLanes elements of `width` values each,
// Where a batch's Jacobian goes (eval_gradient's sink), row r = P c + k
// holding ∂f_c/∂p of every lane for the k-th of the P wanted slots: straight
// to memory by rows (the (3, P, N) layout), or through the stack, transposed
// to element-major order when the batch is done (finish).
template <Layouts layouts>
struct JacobianStore {
    const EvalJob& job;
    std::int64_t i;
    alignas(64) float lanes[padded_rows(kMaxJacobianWidth)][kLanes];

    // lanes left uninitialised: brace-initialising the aggregate zeroed 1.3 KB per batch
    JacobianStore(const EvalJob& job_, std::int64_t i_) : job(job_), i(i_) {}

    bool by_rows() const {
        return layouts == Layouts::kRows || (layouts == Layouts::kMixed && job.jacobian_row_stride > 0);
    }

    bool wants(int p) const { return job.columns.wants(p); }

    PB_KERNEL_INLINE void operator()(int c, int p, Floats value) {
        const int r = job.columns.count * c + job.columns.position[p];
        if (by_rows()) {
            value.store_unaligned(job.jacobian + r * job.jacobian_row_stride + i);
        } else {
            value.store_aligned(lanes[r]);
        }
    }

    PB_KERNEL_INLINE void finish() {
        if (by_rows()) return;
        if (!job.columns.all()) {
            store_lanes_by_element(lanes, 3 * job.columns.count, job.jacobian + 3 * job.columns.count * i);
            return;
        }
        for (int r = kJacobianWidth; r < padded_rows(kJacobianWidth); ++r) Floats(0.0f).store_aligned(lanes[r]);
        store_rows_by_element<kJacobianWidth>(lanes, job.jacobian + kJacobianWidth * i);
    }
};

// The vector-Jacobian product's sink: Σ_c g_c ∂f_c/∂p for the wanted slots,
// the channels summed in order as they come, stored by rows (the (P, N)
// layout) or by element when the batch is done.
template <Layouts layouts>
struct VjpSink {
    const EvalJob& job;
    std::int64_t i;
    Rgb<Floats> cotangent;
    alignas(64) float lanes[kParamSlots][kLanes];

    VjpSink(const EvalJob& job_, std::int64_t i_, const Vec3<Floats>& g) : job(job_), i(i_), cotangent{g.x, g.y, g.z} {}

    bool by_rows() const {
        return layouts == Layouts::kRows || (layouts == Layouts::kMixed && job.jacobian_row_stride > 0);
    }

    bool wants(int p) const { return job.columns.wants(p); }

    PB_KERNEL_INLINE void operator()(int c, int p, Floats value) {
        float* sum = lanes[job.columns.position[p]];
        Floats term = channel_of(cotangent, c);
        if (c == 0) {
            (term * value).store_aligned(sum);
        } else {
            mul_add(term, value, Floats::load_aligned(sum)).store_aligned(sum);
        }
    }

    PB_KERNEL_INLINE void finish() {
        if (by_rows()) {
            for (int k = 0; k < job.columns.count; ++k)
                Floats::load_aligned(lanes[k]).store_unaligned(job.jacobian + k * job.jacobian_row_stride + i);
        } else {
            store_lanes_by_element(lanes, job.columns.count, job.jacobian + job.columns.count * i);
        }
    }
};

// eval_batch with the energy compensation: f_ms joins f (and is its own lobe),
// its weight w3 the cosine lobe's in the pdf (model/energy.hpp).
template <Model model, Output output, Layouts layouts, LobeSet lobes = LobeSet::kAll>
PB_KERNEL_INLINE void eval_compensated_batch(const EvalJob& job, std::int64_t i, const Vec3<Floats>& wi,
                                             const Vec3<Floats>& wo, const Shading<Floats>& s,
                                             const MultipleScatteringLobe<Floats>& ms) {
    static_assert(!has_jacobian(output), "the energy compensation has no derivatives");
    Geometry<Floats> g = geometry_of(wi, wo);
    Mask above = above_surface(g);
    View<Floats> view = view_of<model, lobes>(wo, s);
    Floats missing_wo = ms.missing_energy(wo.z);
    // (1 - E(μl)) (1 - E(μo)): both lookups first, f_ms joins f by one FMA a channel (added_to)
    Floats multiple_scattering = ms.missing_energy(wi.z) * missing_wo;
    Rgb<Floats> zero{Floats(0.0f), Floats(0.0f), Floats(0.0f)};
    auto masked = [&](Rgb<Floats> c) { return select(above, job.cosine ? wi.z * c : c, zero); };
    if constexpr (output == Output::kPdf || output == Output::kValuePdf) {
        Shading<Floats> mixture = with_multiple_scattering_weight(s, ms.weight(missing_wo));
        Floats pdf = mixture_pdf<lobes>(g, mixture, view, lobe_weights(view.fv, mixture), job.sampler);
        select(above, pdf, Floats(0.0f)).store_unaligned(job.pdf + i);
    }
    if constexpr (output == Output::kPdf) return;
    LobeValues<Floats> values = eval_lobes<model, lobes>(g, s, view);
    if constexpr (output == Output::kLobes) {
        store_lobes<layouts>(job.out, i, values.colors(s, ms.rgb(multiple_scattering)), masked);
    } else if constexpr (output != Output::kPdf) {
        store_rgb<layouts, true>(job.out[0], i, masked(ms.added_to(values.template total<lobes>(s), multiple_scattering)));
    }
}

template <Model model, Output output, Layouts layouts, bool compensated, LobeSet lobes = LobeSet::kAll>
PB_KERNEL_INLINE void eval_values_batch(const EvalJob& job, std::int64_t i, const Vec3<Floats>& wi, const Vec3<Floats>& wo,
                                        const PreparedOf<model, output, compensated>& material) {
    if constexpr (compensated) {
        eval_compensated_batch<model, output, layouts, lobes>(job, i, wi, wo, material.shading, material.ms);
        return;
    }
    const Shading<Floats>& s = material.shading;
    Geometry<Floats> g = geometry_of(wi, wo);
    // select discards whatever the formulas gave below the surface (H may be 0)
    Mask above = above_surface(g);
    View<Floats> view = view_of<model, lobes>(wo, s);
    if constexpr (in_parameters(output)) {
        // x cos θl or x times 1 (the same bits), then 0 below the surface
        Floats cosine_weight = job.cosine ? wi.z : Floats(1.0f);
        auto masked = [&](Floats x) { return select(above, cosine_weight * x, Floats(0.0f)); };
        derivative_batch<output == Output::kGradient, JacobianStore<layouts>, VjpSink<layouts>, layouts>(
                job, i, [&](auto& target) {
                    Rgb<Floats> f = eval_gradient<model>(g, s, view, material.partials, masked, target);
                    return Rgb<Floats>{masked(f.r), masked(f.g), masked(f.b)};
                });
    } else if constexpr (output == Output::kPdf) {
        Floats pdf = mixture_pdf(g, s, view, lobe_weights(view.fv, s), job.sampler);
        select(above, pdf, Floats(0.0f)).store_unaligned(job.pdf + i);
    } else if constexpr (output == Output::kValuePdf) {
        Floats pdf = mixture_pdf<lobes>(g, s, view, lobe_weights(view.fv, s), job.sampler);
        select(above, pdf, Floats(0.0f)).store_unaligned(job.pdf + i);
        Rgb<Floats> f = eval_lobes<model, lobes>(g, s, view).template total<lobes>(s);
        auto masked = [&](Floats x) { return select(above, job.cosine ? wi.z * x : x, Floats(0.0f)); };
        store_rgb<layouts>(job.out[0], i, {masked(f.r), masked(f.g), masked(f.b)});
    } else {
        LobeValues<Floats> values = eval_lobes<model, lobes>(g, s, view);
        Rgb<Floats> zero{Floats(0.0f), Floats(0.0f), Floats(0.0f)};
        auto masked = [&](Rgb<Floats> c) { return select(above, job.cosine ? wi.z * c : c, zero); };
        if constexpr (output == Output::kLobes) {
            store_lobes<layouts>(job.out, i, values.colors(s, zero), masked);
        } else {
            store_rgb<layouts, true>(job.out[0], i, masked(values.template total<lobes>(s)));
        }
    }
}

PB_KERNEL_INLINE Floats absolute(Floats x) { return xsimd::abs(x); }

// A batch of the 2015 models (model/bsdf2015.hpp): every output over the whole
// sphere, the cosine as |cos θl|.
template <Model model, Output output, Layouts layouts, LobeSet lobes>
PB_KERNEL_INLINE void eval_bsdf_batch(const EvalJob& job, std::int64_t i, const Vec3<Floats>& wi, const Vec3<Floats>& wo,
                                      const Prepared2015<model, output>& s) {
    auto weighted = [&](const Rgb<Floats>& c) { return job.cosine ? absolute(wi.z) * c : c; };
    if constexpr (in_parameters(output)) {
        derivative_batch<output == Output::kGradient, JacobianStore<layouts>, VjpSink<layouts>, layouts>(
                job, i, [&](auto& target) { return eval_gradient2015(wi, wo, s, job.mode, job.cosine, target); });
    } else if constexpr (in_directions(output)) {
        auto differentiate = [&](int half, const Vec3<Doubles>& w_i, const Vec3<Doubles>& w_o, auto& jacobian) {
            return eval_direction_gradient2015(w_i, w_o, s.directions[half], job.mode, job.cosine, jacobian);
        };
        auto value = [&] { return weighted(eval2015(wi, wo, s.shading, job.mode)); };  // as f alone
        direction_batch<output, layouts>(job, i, wi, wo, differentiate, value);
    } else if constexpr (output == Output::kLobes) {
        store_lobes<layouts>(job.out, i, eval_lobes2015(wi, wo, s, job.mode).colors(), weighted);
    } else if constexpr (output == Output::kPdf) {
        pdf2015(wi, wo, s, job.sampler).store_unaligned(job.pdf + i);
    } else if constexpr (output == Output::kValuePdf) {
        ValuePdf2015<Floats> both = eval_pdf2015<lobes>(wi, wo, s, job.mode, job.sampler);
        both.pdf.store_unaligned(job.pdf + i);
        store_rgb<layouts, true>(job.out[0], i, weighted(both.f));
    } else {
        store_rgb<layouts, true>(job.out[0], i, weighted(eval2015<lobes>(wi, wo, s, job.mode)));
    }
}

// One batch at i of any output.
template <Model model, Output output, Layouts layouts, bool compensated, LobeSet lobes = LobeSet::kAll>
PB_KERNEL_INLINE void eval_batch(const EvalJob& job, std::int64_t i, const Vec3<Floats>& wi, const Vec3<Floats>& wo,
                                 const PreparedOf<model, output, compensated>& material) {
    if constexpr (is_bsdf(model)) {
        eval_bsdf_batch<model, output, layouts, lobes>(job, i, wi, wo, material);
    } else if constexpr (in_directions(output)) {
        eval_direction_batch<model, output, layouts>(job, i, wi, wo, material.shading, material.directions);
    } else {
        eval_values_batch<model, output, layouts, compensated, lobes>(job, i, wi, wo, material);
    }
}

// The outputs compiled per LobeSet: f alone, and f with the pdf (which needs no
// lobe's value; the mixture's weights come from the material).
constexpr bool has_lobe_sets(Output output) { return output == Output::kTotal || output == Output::kValuePdf; }

// The lobes a material needs, from its values (LobeSet's conditions): a
// uniform one's once per call, a batch's when all its lanes agree. The
// clearcoat first: a batch of random materials is done after one test. In
// the 2015 models the diffuse, the sheen and the diffuse transmission are 0
// for a metal and for a material whose light all meets the interface
// (spec_trans 1), and the subsurface is not read.
template <Model model, class Value, class Condition>
PB_KERNEL_INLINE LobeSet lobe_set_where(Value value, Condition holds) {
    if (!holds(value(kClearcoat) == 0.0f)) return LobeSet::kAll;
    if constexpr (is_bsdf(model)) {
        if (holds((value(kMetallic) == 1.0f) | (value(kSpecTrans) == 1.0f))) return LobeSet::kSpecular;
        if (holds(value(kSheen) == 0.0f)) return LobeSet::kPlain;
        return LobeSet::kAll;
    }
    if (holds(value(kMetallic) == 1.0f)) return LobeSet::kSpecular;
    if (holds((value(kSheen) == 0.0f) & (value(kSubsurface) == 0.0f))) return LobeSet::kPlain;
    return LobeSet::kAll;
}

template <Model model>
LobeSet lobe_set_of(const ParamSlot* params) {
    return lobe_set_where<model>([&](Param slot) { return params[slot].value; }, [](bool b) { return b; });
}

template <Model model>
PB_KERNEL_INLINE LobeSet lobe_set_of(const RawMaterial& m) {
    return lobe_set_where<model>([&](Param slot) { return m.slot[slot]; }, [](const Mask& b) { return all(b); });
}

// true unless the direction check is on and its fast test does not accept every lane
PB_KERNEL_INLINE bool accepted(const EvalJob& job, const Vec3<Floats>& wi, const Vec3<Floats>& wo) {
    return !job.check.enabled || all(surely_unit_length(wi, job.check) & surely_unit_length(wo, job.check));
}

// One batch at i; false, with nothing stored, when the fast direction test
// does not accept it.
template <Model model, Output output, bool per_element, Layouts layouts, bool compensated, LobeSet lobes>
PB_KERNEL_INLINE bool eval_one_batch(const EvalJob& job, std::int64_t i, const PreparedOf<model, output, compensated>& uniform) {
    Vec3<Floats> wi = load_vec3<layouts>(job.wi, i);
    Vec3<Floats> wo = load_vec3<layouts>(job.wo, i);
    if (!accepted(job, wi, wo)) return false;
    if constexpr (per_element && compensated) {
        // the lobes' constants as locals: a CompensatedPrepared built per batch would be copied whole (rep movs)
        RawMaterial m = load_material(job.params, i);
        Shading<Floats> s = shading_of(m);
        MultipleScatteringLobe<Floats> ms = multiple_scattering_of(m.slot, s, model);
        if constexpr (has_lobe_sets(output)) {  // the batch's LobeSet, as below
            switch (lobe_set_of<model>(m)) {
                case LobeSet::kSpecular:
                    eval_compensated_batch<model, output, layouts, LobeSet::kSpecular>(job, i, wi, wo, s, ms);
                    return true;
                case LobeSet::kPlain:
                    eval_compensated_batch<model, output, layouts, LobeSet::kPlain>(job, i, wi, wo, s, ms);
                    return true;
                default:
                    break;
            }
        }
        eval_compensated_batch<model, output, layouts>(job, i, wi, wo, s, ms);
    } else if constexpr (per_element && has_lobe_sets(output)) {
        // the batch's LobeSet, when all its lanes agree (a texture's metal or plastic regions)
        RawMaterial m = load_material(job.params, i);
        switch (lobe_set_of<model>(m)) {
            case LobeSet::kSpecular:
                eval_batch<model, output, layouts, false, LobeSet::kSpecular>(job, i, wi, wo,
                                                                              prepare_for<model, output, false>(m, job.energy_compensation));
                break;
            case LobeSet::kPlain:
                eval_batch<model, output, layouts, false, LobeSet::kPlain>(job, i, wi, wo,
                                                                           prepare_for<model, output, false>(m, job.energy_compensation));
                break;
            default:
                eval_batch<model, output, layouts, false>(job, i, wi, wo, prepare_for<model, output, false>(m, job.energy_compensation));
        }
    } else if constexpr (per_element) {
        eval_batch<model, output, layouts, compensated>(job, i, wi, wo,
                                                        prepare_for<model, output, false>(load_material(job.params, i), job.energy_compensation));
    } else {
        eval_batch<model, output, layouts, compensated, lobes>(job, i, wi, wo, uniform);
    }
    return true;
}

// The batches at i and i + kLanes of a uniform material, in one step: -1, or
// the start of the first one the fast direction test does not accept (every
// element before it written). The two batches' loads come first and their
// work is independent: one batch's chain of dependent operations (square
// roots and divisions among them) is longer than the out-of-order window
// can cover with the next batch's work when the batches come one per step.
template <Model model, Output output, Layouts layouts, bool compensated, LobeSet lobes>
PB_KERNEL_INLINE std::int64_t eval_two_batches(const EvalJob& job, std::int64_t i, const PreparedOf<model, output, compensated>& uniform) {
    Vec3<Floats> wi = load_vec3<layouts>(job.wi, i), wo = load_vec3<layouts>(job.wo, i);
    Vec3<Floats> next_wi = load_vec3<layouts>(job.wi, i + kLanes), next_wo = load_vec3<layouts>(job.wo, i + kLanes);
    if (!accepted(job, wi, wo)) return i;
    eval_batch<model, output, layouts, compensated, lobes>(job, i, wi, wo, uniform);
    if (!accepted(job, next_wi, next_wo)) return i + kLanes;
    eval_batch<model, output, layouts, compensated, lobes>(job, i + kLanes, next_wi, next_wo, uniform);
    return -1;
}

// The last pad.count < kLanes elements, as one batch: one_batch(padded job)
// runs the batch at element 0 of a job over padded copies (Layouts::kMixed).
template <Output output, class OneBatch>
bool eval_tail(const EvalJob& job, const Padding& pad, const OneBatch& one_batch) {
    alignas(64) PadBuffer wi, wo, cotangent, params[kParamSlots], out[kLobeCount];
    alignas(64) float pdf[kLanes];
    alignas(64) float jacobian[has_jacobian(output) ? kMaxJacobianWidth * kLanes : 1];
    static_assert(kMaxJacobianWidth >= kDirectionJacobianWidth, "the directions' Jacobian fits the buffer");
    EvalJob padded = job;
    padded.wi = pad_vec3(job.wi, pad, wi);
    padded.wo = pad_vec3(job.wo, pad, wo);
    if constexpr (is_vjp(output)) padded.cotangent = pad_vec3(job.cotangent, pad, cotangent);
    pad_params(job.params, padded.params, pad, params);
    constexpr int outputs = value_outputs(output);
    for (int k = 0; k < outputs; ++k) padded.out[k] = MutableVec3Array{out[k], Vec3Layout::kInterleaved, 0};
    padded.pdf = pdf;
    padded.jacobian = jacobian;
    padded.jacobian_row_stride = 0;

    if (!one_batch(padded)) return false;

    for (int k = 0; k < outputs; ++k) unpad_vec3(job.out[k], pad, out[k]);
    if (output == Output::kPdf || output == Output::kValuePdf) unpad_scalars(job.pdf, pad, pdf);
    if constexpr (has_jacobian(output)) {
        const int width = job.jacobian_width();  // values an element
        for (std::int64_t j = 0; j < pad.count; ++j)
            for (int r = 0; r < width; ++r) {
                const std::int64_t e = pad.begin + j;
                const std::int64_t index = job.jacobian_row_stride > 0 ? r * job.jacobian_row_stride + e : width * e + r;
                job.jacobian[index] = jacobian[width * j + r];
            }
    }
    return true;
}

// -1 with every element of [begin, end) written, or the start of the first
// batch the fast direction test did not accept (see run_checked).
template <Model model, Output output, bool per_element, Layouts layouts, bool compensated, LobeSet lobes>
std::int64_t eval_batches(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    PreparedOf<model, output, compensated> uniform{};
    BlendedEnergyRow row;  // (left uninitialised; the loops without the compensation never touch it)
    if constexpr (!per_element) {
        uniform = prepare_for<model, output, compensated>(load_material(job.params, 0), job.energy_compensation);
        if constexpr (compensated) row.template use_for<model>(uniform.ms);
    }
    std::int64_t i = begin;
    if constexpr (!per_element && !in_directions(output)) {  // (the directions' batches are long enough alone)
        for (; i + 2 * kLanes <= end; i += 2 * kLanes) {
            const std::int64_t stopped = eval_two_batches<model, output, layouts, compensated, lobes>(job, i, uniform);
            if (stopped >= 0) return stopped;
        }
    }
    for (; i + kLanes <= end; i += kLanes)
        if (!eval_one_batch<model, output, per_element, layouts, compensated, lobes>(job, i, uniform)) return i;
    auto one_batch = [&](const EvalJob& padded) {
        return eval_one_batch<model, output, per_element, Layouts::kMixed, compensated, lobes>(padded, 0, uniform);
    };
    if (i < end && !eval_tail<output>(job, Padding{i, end - i}, one_batch)) return i;
    return -1;
}

// The elements before the first whose (N, 3) output starts at a register-aligned
// address: k in [0, kLanes), since kLanes elements fill three registers and
// 12 k takes every multiple of 4 modulo a register's bytes; -1 for an address
// that is not a float's.
inline std::int64_t elements_to_register_alignment(const float* p) {
    const auto address = reinterpret_cast<std::uintptr_t>(p);
    for (std::int64_t k = 0; k < kLanes; ++k)
        if ((address + 3 * sizeof(float) * k) % sizeof(Floats) == 0) return k;
    return -1;
}

// eval_batches, f written by non-temporal stores when the batch layer asks
// for them: the elements before the first register-aligned output as a padded
// batch with ordinary stores, then every batch from there aligned.
template <Model model, Output output, bool per_element, Layouts layouts, bool compensated, LobeSet lobes>
std::int64_t eval_loop(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    if (!job.out[0].streaming) return eval_batches<model, output, per_element, layouts, compensated, lobes>(job, begin, end);
    EvalJob plain = job;
    plain.out[0].streaming = false;
    const std::int64_t head = elements_to_register_alignment(job.out[0].data + 3 * begin);
    if (head < 0) return eval_batches<model, output, per_element, layouts, compensated, lobes>(plain, begin, end);
    if (head > 0) {
        const std::int64_t stopped =
                eval_batches<model, output, per_element, layouts, compensated, lobes>(plain, begin, std::min(end, begin + head));
        if (stopped >= 0 || begin + head >= end) return stopped;
    }
    const std::int64_t stopped = eval_batches<model, output, per_element, layouts, compensated, lobes>(job, begin + head, end);
    streaming_fence();
    return stopped;
}

inline Layouts layouts_of(const EvalJob& job) {
    int outputs = value_outputs(job.output);
    for (Vec3Layout layout : {Vec3Layout::kInterleaved, Vec3Layout::kRows}) {
        bool all = job.wi.layout == layout && job.wo.layout == layout;
        for (int k = 0; k < outputs; ++k) all = all && job.out[k].layout == layout;
        if (is_vjp(job.output)) all = all && job.cotangent.layout == layout;
        if (has_jacobian(job.output)) all = all && (job.jacobian_row_stride > 0) == (layout == Vec3Layout::kRows);
        if (all) return layout == Vec3Layout::kInterleaved ? Layouts::kInterleaved : Layouts::kRows;
    }
    return Layouts::kMixed;
}

template <Model model, Output output, bool per_element, Layouts layouts, bool compensated, LobeSet lobes = LobeSet::kAll>
std::int64_t eval_checked(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    auto rejected = [&](std::int64_t i) { return !unit_length_at(job.wi, i, job.check) || !unit_length_at(job.wo, i, job.check); };
    return run_checked(job, begin, end, eval_loop<model, output, per_element, layouts, compensated, lobes>, rejected);
}

// -1 with every element written, or the first element whose wi or wo fails the direction check.
template <Model model, Output output, bool per_element, bool compensated, LobeSet lobes = LobeSet::kAll>
std::int64_t eval_range_for(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    if constexpr (compensated) {  // (N, 3) arrays, or any layout through the mixed loads and stores
        return layouts_of(job) == Layouts::kInterleaved
                       ? eval_checked<model, output, per_element, Layouts::kInterleaved, true, lobes>(job, begin, end)
                       : eval_checked<model, output, per_element, Layouts::kMixed, true, lobes>(job, begin, end);
    }
    // one loop for every layout where the loads are a small part of a batch: the derivatives in the
    // directions, and the 2015 models' outputs but f alone (the fewer loops, the shorter the build)
    if constexpr (in_directions(output) || (is_bsdf(model) && output != Output::kTotal)) {
        return eval_checked<model, output, per_element, Layouts::kMixed, false, lobes>(job, begin, end);
    }
    switch (layouts_of(job)) {
        case Layouts::kInterleaved:
            return eval_checked<model, output, per_element, Layouts::kInterleaved, compensated, lobes>(job, begin, end);
        case Layouts::kRows:
            return eval_checked<model, output, per_element, Layouts::kRows, compensated, lobes>(job, begin, end);
        default:
            return eval_checked<model, output, per_element, Layouts::kMixed, compensated, lobes>(job, begin, end);
    }
}

// f alone and f with the pdf of a uniform material get the loop of its LobeSet
// (with the energy compensation or without).
template <Model model, Output output, bool compensated = false>
std::int64_t eval_range_for(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    if (!job.uniform_material()) return eval_range_for<model, output, true, compensated>(job, begin, end);
    if constexpr (has_lobe_sets(output)) {
        switch (lobe_set_of<model>(job.params)) {
            case LobeSet::kSpecular: return eval_range_for<model, output, false, compensated, LobeSet::kSpecular>(job, begin, end);
            case LobeSet::kPlain: return eval_range_for<model, output, false, compensated, LobeSet::kPlain>(job, begin, end);
            default: break;
        }
    }
    return eval_range_for<model, output, false, compensated>(job, begin, end);
}

// One model's loops for one output: with the energy compensation where the
// model has its table and the output is not a derivative (the bindings refuse
// those), else the plain ones. The BRDFs' sampling pdf does not depend on
// their masking term: one loop serves both.
template <Model model, Output output>
std::int64_t eval_model_range(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    if constexpr (has_energy_table(model) && !has_jacobian(output)) {
        if (job.energy_compensation) return eval_range_for<model, output, true>(job, begin, end);
    }
    if constexpr (output == Output::kPdf && !is_bsdf(model)) {
        return eval_range_for<Model::kDisney2014, output>(job, begin, end);
    } else {
        return eval_range_for<model, output>(job, begin, end);
    }
}

// The job's model's loops for its output, one of the list's (the kernel's parts, kernel_parts.hpp).
template <class Outputs>
std::int64_t eval_job_range(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    return with_model(job.model, [&](auto model) {
        return Outputs::with(job.output, [&](auto output) { return eval_model_range<model(), output()>(job, begin, end); });
    });
}
