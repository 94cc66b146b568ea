// Bindings for the batched SIMD path. The Python side (principled_brdf/_batch.py)
// validates, converts and allocates; these functions re-check sizes so that no
// call can read or write out of bounds, then release the GIL around the work.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "bindings.hpp"
#include "principled_brdf/batch.hpp"

namespace py = pybind11;

namespace principled_brdf::bindings {
namespace {

using Float32Array = py::array_t<float, py::array::c_style>;

// The kernels read and write whole floats only (docs/bad-input.md:
// the Python side copies a misaligned input and refuses a misaligned out=).
template <class T>
void require_aligned(const T* data, const char* name) {
    if (reinterpret_cast<std::uintptr_t>(data) % alignof(T) != 0)
        throw std::invalid_argument(std::string(name) + ": array data is not aligned to its element size");
}

// A (N, 3), (3, N) or (3,) float32 array as a Vec3Array of n elements.
Vec3Array vec3_view(const Float32Array& a, int layout, std::int64_t n, const char* name) {
    const auto kind = static_cast<Vec3Layout>(layout);
    const bool ok = (kind == Vec3Layout::kInterleaved && a.ndim() == 2 && a.shape(0) == n && a.shape(1) == 3) ||
                    (kind == Vec3Layout::kRows && a.ndim() == 2 && a.shape(0) == 3 && a.shape(1) == n) ||
                    (kind == Vec3Layout::kSingle && a.ndim() == 1 && a.shape(0) == 3);
    if (!ok) throw std::invalid_argument(std::string(name) + ": array shape does not match its layout and length");
    require_aligned(a.data(), name);
    return {a.data(), kind, kind == Vec3Layout::kRows ? n : 0};
}

MutableVec3Array output_view(Float32Array& a, int layout, std::int64_t n, const char* name) {
    if (layout == static_cast<int>(Vec3Layout::kSingle))
        throw std::invalid_argument(std::string(name) + ": outputs are (N, 3) or (3, N)");
    const Vec3Array view = vec3_view(a, layout, n, name);
    if (!a.writeable()) throw std::invalid_argument(std::string(name) + ": array is read-only");
    return {a.mutable_data(), view.layout, view.row_stride};
}

// `count` output arrays, each C-contiguous float32 in the same layout, as views;
// `keep` holds the arrays while the views are used.
void output_views(const py::sequence& arrays, int count, int layout, std::int64_t n, const char* name,
                  MutableVec3Array* views, std::vector<Float32Array>& keep) {
    if (py::len(arrays) != static_cast<std::size_t>(count))
        throw std::invalid_argument(std::string(name) + ": expected " + std::to_string(count) + " arrays");
    for (int k = 0; k < count; ++k) {
        keep.push_back(py::cast<Float32Array>(arrays[k]));
        if (!keep.back().is(arrays[k])) throw std::invalid_argument(std::string(name) + ": expected C-contiguous float32 arrays");
        views[k] = output_view(keep.back(), layout, n, name);
    }
}

// The segments of a call (Segments in batch.hpp), from Python: None, one
// segment of n elements; or (count, length, offsets, single) with count
// length = n, offsets 3 + one entry a parameter (wi, wo, the cotangent or u, then the
// parameters in the order of kParams), each None or `count` non-negative
// int64 offsets in floats, and single one flag a parameter: the parameter is one value a
// segment. The inputs are then checked against their own sizes: every
// segment's elements lie within them.
struct SegmentTables {
    bool given = false;
    Segments segments;
    std::int64_t largest[3 + kParams.size()] = {};  // each input's largest offset
    bool single[kParams.size()] = {};
    std::vector<py::array_t<std::int64_t, py::array::c_style>> keep;
};

constexpr int kTableInputs = 3 + static_cast<int>(kParams.size());

SegmentTables segments_from(const py::object& value, std::int64_t n) {
    SegmentTables tables;
    tables.segments.length = n;
    if (value.is_none()) return tables;
    tables.given = true;
    auto entries = value.cast<py::tuple>();
    if (entries.size() != 4) throw std::invalid_argument("segments: expected (count, length, offsets, single)");
    Segments& segments = tables.segments;
    segments.count = entries[0].cast<std::int64_t>();
    segments.length = entries[1].cast<std::int64_t>();
    if (segments.count < 0 || segments.length < 0 ||
        (segments.length > 0 && segments.count > std::numeric_limits<std::int64_t>::max() / segments.length) ||
        segments.count * segments.length != n)
        throw std::invalid_argument("segments: expected count * length == n");
    auto offsets = entries[2].cast<py::sequence>();
    auto single = entries[3].cast<std::vector<bool>>();
    if (py::len(offsets) != static_cast<std::size_t>(kTableInputs) || single.size() != kParams.size())
        throw std::invalid_argument("segments: expected " + std::to_string(kTableInputs) + " offset tables and " +
                                    std::to_string(kParams.size()) + " flags");
    for (int input = 0; input < kTableInputs; ++input) {
        if (offsets[input].is_none()) continue;
        tables.keep.push_back(py::cast<py::array_t<std::int64_t, py::array::c_style>>(offsets[input]));
        const auto& table = tables.keep.back();
        if (!table.is(offsets[input]) || table.ndim() != 1 || table.shape(0) != segments.count)
            throw std::invalid_argument("segments: an offset table is not `count` C-contiguous int64 values");
        const std::int64_t* data = table.data();
        for (std::int64_t s = 0; s < segments.count; ++s) {
            if (data[s] < 0) throw std::invalid_argument("segments: negative offset");
            tables.largest[input] = std::max(tables.largest[input], data[s]);
        }
        if (input < kSegmentSlots) {
            segments.offsets[input] = data;
        } else {
            const ParamInfo& info = kParams[input - kSegmentSlots];
            for (int k = 0; k < info.slots; ++k) segments.offsets[kSegmentSlots + info.first_slot + k] = data;
        }
    }
    for (std::size_t p = 0; p < kParams.size(); ++p) {
        tables.single[p] = single[p];
        for (int k = 0; k < kParams[p].slots; ++k) segments.single[kParams[p].first_slot + k] = single[p];
    }
    return tables;
}

void require_within(bool ok, const char* name) {
    if (!ok) throw std::invalid_argument(std::string(name) + ": a segment reaches past the array");
}

// A direction input: vec3_view for one segment; with segments, any length of
// its own that every segment's elements fit in.
Vec3Array input_view(const Float32Array& a, int layout, std::int64_t n, const char* name, const SegmentTables& tables,
                     int input) {
    if (!tables.given) return vec3_view(a, layout, n, name);
    const auto kind = static_cast<Vec3Layout>(layout);
    const std::int64_t largest = tables.largest[input], length = tables.segments.length;
    require_aligned(a.data(), name);
    switch (kind) {
        case Vec3Layout::kInterleaved:
            if (a.ndim() != 2 || a.shape(1) != 3) throw std::invalid_argument(std::string(name) + ": expected (M, 3)");
            require_within(largest + 3 * length <= 3 * a.shape(0), name);
            return {a.data(), kind, 0};
        case Vec3Layout::kRows:
            if (a.ndim() != 2 || a.shape(0) != 3) throw std::invalid_argument(std::string(name) + ": expected (3, M)");
            require_within(largest + length <= a.shape(1), name);
            return {a.data(), kind, a.shape(1)};
        case Vec3Layout::kSingle:
            require_within(largest + 3 <= a.size(), name);
            return {a.data(), kind, 0};
    }
    throw std::invalid_argument(std::string(name) + ": unknown layout");
}

// params: 11 entries in the order of kParams, each a number (base_color: a
// 3-sequence) or a float32 array of n values ((n, 3) for base_color).
void fill_params(const py::sequence& params, std::int64_t n, ParamSlot* slots, py::list& keep_alive,
                 const SegmentTables& tables = SegmentTables{}) {
    if (static_cast<std::size_t>(py::len(params)) != kParams.size())
        throw std::invalid_argument("params: expected one entry per parameter");
    for (std::size_t p = 0; p < kParams.size(); ++p) {
        const ParamInfo& info = kParams[p];
        py::object value = params[p];
        if (py::isinstance<py::array>(value)) {
            auto array = py::cast<Float32Array>(value);
            keep_alive.append(array);
            bool ok = info.slots == 3 ? (array.ndim() == 2 && array.shape(1) == 3) : array.ndim() == 1;
            if (!tables.given) {
                ok = ok && array.shape(0) == n;
            } else {  // offsets and extents in floats
                const std::int64_t extent = tables.single[p] ? info.slots : info.slots * tables.segments.length;
                require_within(tables.largest[kSegmentSlots + p] + extent <= array.size(), info.name);
            }
            if (!ok) throw std::invalid_argument(std::string(info.name) + ": per-element array of the wrong shape");
            require_aligned(array.data(), info.name);
            for (int s = 0; s < info.slots; ++s)
                slots[info.first_slot + s] = ParamSlot{0.0f, array.data() + s, info.slots};
        } else if (info.slots == 3) {
            auto rgb = py::cast<std::vector<float>>(value);
            if (rgb.size() != 3) throw std::invalid_argument(std::string(info.name) + ": expected 3 values");
            for (int s = 0; s < 3; ++s) slots[info.first_slot + s].value = rgb[s];
        } else {
            slots[info.first_slot].value = py::cast<float>(value);
        }
    }
}

// The options of the batched calls, by name: the scalar fields of EvalJob and
// SampleJob (batch.hpp) and the threads and isa of eval() and sample().
// EvalOptions (batch_eval, batch_eval_grad), PdfOptions (batch_pdf) and
// SampleOptions (batch_sample) are Python classes with read-write fields; the
// Python side (principled_brdf/_batch.py) validated the values, and the
// indices are checked again here. The functions below take them by value: the
// work reads a copy, whatever Python code assigns to the caller's object once
// the GIL is released.
struct BatchOptions {
    int model = 0;                     // index into kModelNames
    bool energy_compensation = false;  // the multiple-scattering lobe
    int mode = 0;                      // index into kTransportModeNames
    double check_tolerance = 0.0;      // > 0: the direction check of docs/bad-input.md
    int threads = 0;                   // 0: all cores
    std::string isa;                   // "": the active instruction set
};

struct EvalOptions : BatchOptions {
    bool cosine = false;  // multiply by cos θl
};

struct PdfOptions : EvalOptions {
    int sampler = 0;  // index into kSpecularSamplerNames
};

struct SampleOptions : BatchOptions {
    int sampler = 0;         // index into kSpecularSamplerNames
    std::uint64_t seed = 0;  // of the counter-based uniforms, without u
};

// The inputs of an evaluation: directions, parameters and options.
EvalJob eval_job(const Float32Array& wi, int wi_layout, const Float32Array& wo, int wo_layout, const py::sequence& params,
                 std::int64_t n, Output output, const EvalOptions& options, py::list& keep_alive,
                 const SegmentTables& tables) {
    EvalJob job;
    job.wi = input_view(wi, wi_layout, n, "wi", tables, kSegmentWi);
    job.wo = input_view(wo, wo_layout, n, "wo", tables, kSegmentWo);
    fill_params(params, n, job.params, keep_alive, tables);
    job.model = model_from(options.model);
    job.output = output;
    job.cosine = options.cosine;
    job.energy_compensation = options.energy_compensation;
    job.mode = mode_from(options.mode);
    if (options.check_tolerance > 0.0) job.check = direction_check(options.check_tolerance);
    return job;
}

// Returns -1, or with check_tolerance > 0 the index of an element whose wi or
// wo is not a unit vector (the outputs then hold the results of some elements only).
std::int64_t batch_eval(const Float32Array& wi, int wi_layout, const Float32Array& wo, int wo_layout,
                        const py::sequence& params, const py::sequence& outputs, int out_layout, std::int64_t n,
                        bool lobes, const EvalOptions options, const py::object& segments) {
    py::list keep_alive;
    const SegmentTables tables = segments_from(segments, n);
    EvalJob job = eval_job(wi, wi_layout, wo, wo_layout, params, n, lobes ? Output::kLobes : Output::kTotal, options,
                           keep_alive, tables);
    std::vector<Float32Array> keep_outputs;
    output_views(outputs, lobes ? kLobeCount : 1, out_layout, n, "out", job.out, keep_outputs);
    if (n == 0) return -1;
    py::gil_scoped_release release;
    return eval(job, tables.segments, options.threads, options.isa);
}

}  // namespace

// The parameter slots of a derivative: None for all of them, or distinct slot
// indices in increasing order.
Columns columns_from(const py::object& slots, Model model) {
    const int limit = gradient_slots(model);
    if (slots.is_none()) {
        if (is_bsdf(model)) throw std::invalid_argument("columns: the 2015 models take their slot indices");
        return Columns{};
    }
    auto list = py::cast<std::vector<int>>(slots);
    if (list.empty() || static_cast<int>(list.size()) > limit)
        throw std::invalid_argument("columns: expected 1 to " + std::to_string(limit) + " slot indices");
    for (std::size_t k = 0; k < list.size(); ++k)
        if (list[k] < 0 || list[k] >= limit || (k > 0 && list[k] <= list[k - 1]))
            throw std::invalid_argument("columns: expected increasing slot indices below " + std::to_string(limit));
    return Columns(list.data(), static_cast<int>(list.size()));
}

namespace {

// A derivative's output: (N, width...) by element, or (width..., N) by rows.
float* derivative_output(Float32Array& a, const std::vector<py::ssize_t>& width, bool rows, std::int64_t n,
                         const char* name, const char* expected) {
    bool ok = a.ndim() == static_cast<py::ssize_t>(width.size()) + 1 && a.writeable();
    for (std::size_t k = 0; ok && k < width.size(); ++k) ok = a.shape(rows ? k : k + 1) == width[k];
    ok = ok && a.shape(rows ? a.ndim() - 1 : 0) == n;
    if (!ok) throw std::invalid_argument(std::string(name) + ": expected " + expected);
    require_aligned(a.data(), name);
    return a.mutable_data();
}

// The BRDFs' energy compensation has no derivatives (the 2015 solid's has).
void refuse_compensated_derivative(const EvalOptions& options) {
    if (options.energy_compensation && !is_bsdf(model_from(options.model)))
        throw std::invalid_argument("energy_compensation: not with the gradient of the BRDFs (their lobe's derivative is not implemented)");
}

// f (out) and its Jacobian in the P slots of `columns` (None: all): (N, 3) and
// (N, 3, P) arrays, or (3, N) and (3, P, N) with out_layout rows.
std::int64_t batch_eval_grad(const Float32Array& wi, int wi_layout, const Float32Array& wo, int wo_layout,
                             const py::sequence& params, Float32Array out, Float32Array jacobian, int out_layout,
                             std::int64_t n, const EvalOptions options, const py::object& columns,
                             const py::object& segments) {
    refuse_compensated_derivative(options);
    py::list keep_alive;
    const SegmentTables tables = segments_from(segments, n);
    EvalJob job = eval_job(wi, wi_layout, wo, wo_layout, params, n, Output::kGradient, options, keep_alive, tables);
    job.columns = columns_from(columns, job.model);
    job.out[0] = output_view(out, out_layout, n, "out");
    const bool rows = out_layout == static_cast<int>(Vec3Layout::kRows);
    job.jacobian = derivative_output(jacobian, {3, job.columns.count}, rows, n, "jacobian",
                                     "a writeable (N, 3, P) array, or (3, P, N) for the rows layout");
    job.jacobian_row_stride = rows ? n : 0;
    if (n == 0) return -1;
    py::gil_scoped_release release;
    return eval(job, tables.segments, options.threads, options.isa);
}

// Σ_c g_c ∂f_c/∂p per element for the cotangent g ((N, 3), (3, N) or one
// (3,) vector) and the P slots of `columns`: into vjp, (N, P), or (P, N) with out_layout rows.
std::int64_t batch_eval_vjp(const Float32Array& wi, int wi_layout, const Float32Array& wo, int wo_layout,
                            const py::sequence& params, const Float32Array& cotangent, int cotangent_layout,
                            Float32Array vjp, int out_layout, std::int64_t n, const EvalOptions options,
                            const py::object& columns, const py::object& segments) {
    refuse_compensated_derivative(options);
    py::list keep_alive;
    const SegmentTables tables = segments_from(segments, n);
    EvalJob job = eval_job(wi, wi_layout, wo, wo_layout, params, n, Output::kVjp, options, keep_alive, tables);
    job.columns = columns_from(columns, job.model);
    job.cotangent = input_view(cotangent, cotangent_layout, n, "cotangent", tables, kSegmentThird);
    const bool rows = out_layout == static_cast<int>(Vec3Layout::kRows);
    job.jacobian = derivative_output(vjp, {job.columns.count}, rows, n, "vjp",
                                     "a writeable (N, P) array, or (P, N) for the rows layout");
    job.jacobian_row_stride = rows ? n : 0;
    if (n == 0) return -1;
    py::gil_scoped_release release;
    return eval(job, tables.segments, options.threads, options.isa);
}

// f (out) and its Jacobian in the six direction components wi_x ... wo_z:
// (N, 3) and (N, 3, 6) arrays, or (3, N) and (3, 6, N) with out_layout rows.
std::int64_t batch_eval_direction_grad(const Float32Array& wi, int wi_layout, const Float32Array& wo, int wo_layout,
                                       const py::sequence& params, Float32Array out, Float32Array jacobian,
                                       int out_layout, std::int64_t n, const EvalOptions options,
                                       const py::object& segments) {
    refuse_compensated_derivative(options);
    py::list keep_alive;
    const SegmentTables tables = segments_from(segments, n);
    EvalJob job = eval_job(wi, wi_layout, wo, wo_layout, params, n, Output::kDirectionGradient, options, keep_alive,
                           tables);
    job.out[0] = output_view(out, out_layout, n, "out");
    const bool rows = out_layout == static_cast<int>(Vec3Layout::kRows);
    job.jacobian = derivative_output(jacobian, {3, kDirectionComponents}, rows, n, "jacobian",
                                     "a writeable (N, 3, 6) array, or (3, 6, N) for the rows layout");
    job.jacobian_row_stride = rows ? n : 0;
    if (n == 0) return -1;
    py::gil_scoped_release release;
    return eval(job, tables.segments, options.threads, options.isa);
}

// Σ_c g_c ∂f_c/∂w per element for the cotangent g (as batch_eval_vjp's) and
// the six direction components: into vjp, (N, 6), or (6, N) with out_layout rows.
std::int64_t batch_eval_direction_vjp(const Float32Array& wi, int wi_layout, const Float32Array& wo, int wo_layout,
                                      const py::sequence& params, const Float32Array& cotangent, int cotangent_layout,
                                      Float32Array vjp, int out_layout, std::int64_t n, const EvalOptions options,
                                      const py::object& segments) {
    refuse_compensated_derivative(options);
    py::list keep_alive;
    const SegmentTables tables = segments_from(segments, n);
    EvalJob job = eval_job(wi, wi_layout, wo, wo_layout, params, n, Output::kDirectionVjp, options, keep_alive, tables);
    job.cotangent = input_view(cotangent, cotangent_layout, n, "cotangent", tables, kSegmentThird);
    const bool rows = out_layout == static_cast<int>(Vec3Layout::kRows);
    job.jacobian = derivative_output(vjp, {kDirectionComponents}, rows, n, "vjp",
                                     "a writeable (N, 6) array, or (6, N) for the rows layout");
    job.jacobian_row_stride = rows ? n : 0;
    if (n == 0) return -1;
    py::gil_scoped_release release;
    return eval(job, tables.segments, options.threads, options.isa);
}

template <class T>
T* scalar_output(py::array_t<T, py::array::c_style>& a, std::int64_t n, const char* name) {
    if (a.ndim() != 1 || a.shape(0) != n || !a.writeable())
        throw std::invalid_argument(std::string(name) + ": expected a writeable array of N elements");
    require_aligned(a.data(), name);
    return a.mutable_data();
}

// The sampling pdf alone (out is None) or with f into out, in one pass.
std::int64_t batch_pdf(const Float32Array& wi, int wi_layout, const Float32Array& wo, int wo_layout,
                       const py::sequence& params, Float32Array pdf, const py::object& out, int out_layout,
                       std::int64_t n, const PdfOptions options, const py::object& segments) {
    py::list keep_alive;
    const bool with_value = !out.is_none();
    const SegmentTables tables = segments_from(segments, n);
    EvalJob job = eval_job(wi, wi_layout, wo, wo_layout, params, n, with_value ? Output::kValuePdf : Output::kPdf,
                           options, keep_alive, tables);
    job.sampler = sampler_from(options.sampler);
    job.pdf = scalar_output(pdf, n, "pdf");
    Float32Array value;
    if (with_value) {
        value = py::cast<Float32Array>(out);
        if (!value.is(out)) throw std::invalid_argument("out: expected a C-contiguous float32 array");
        job.out[0] = output_view(value, out_layout, n, "out");
    }
    if (n == 0) return -1;
    py::gil_scoped_release release;
    return eval(job, tables.segments, options.threads, options.isa);
}

std::int64_t batch_sample(const Float32Array& wo, int wo_layout, const py::object& u, int u_layout,
                          const py::sequence& params, Float32Array wi, Float32Array weight, Float32Array pdf,
                          py::array_t<std::int32_t, py::array::c_style> lobe, const py::object& lobe_weights,
                          int out_layout, std::int64_t n, const SampleOptions options, const py::object& segments) {
    SampleJob job;
    const SegmentTables tables = segments_from(segments, n);
    job.wo = input_view(wo, wo_layout, n, "wo", tables, kSegmentWo);
    Float32Array u_array;
    if (!u.is_none()) {
        u_array = py::cast<Float32Array>(u);
        job.u = input_view(u_array, u_layout, n, "u", tables, kSegmentThird);
    }
    job.seed = options.seed;
    py::list keep_alive;
    fill_params(params, n, job.params, keep_alive, tables);
    job.model = model_from(options.model);
    job.sampler = sampler_from(options.sampler);
    job.energy_compensation = options.energy_compensation;
    job.mode = mode_from(options.mode);
    job.wi = output_view(wi, out_layout, n, "wi");
    job.weight = output_view(weight, out_layout, n, "weight");
    job.pdf = scalar_output(pdf, n, "pdf");
    job.lobe = scalar_output(lobe, n, "lobe");
    std::vector<Float32Array> keep_outputs;
    if (!lobe_weights.is_none())
        output_views(lobe_weights.cast<py::sequence>(), kLobeCount, out_layout, n, "lobe_weights", job.lobe_weight,
                     keep_outputs);
    if (options.check_tolerance > 0.0) job.check = direction_check(options.check_tolerance);
    if (n == 0) return -1;
    py::gil_scoped_release release;
    return sample(job, tables.segments, options.threads, options.isa);
}

py::array_t<float> uniforms(std::uint64_t seed, std::int64_t first, std::int64_t n) {
    if (n < 0 || first < 0 || n > std::numeric_limits<std::int64_t>::max() - first)
        throw std::invalid_argument("first, n: expected first >= 0, n >= 0 and first + n <= 2**63 - 1");
    py::array_t<float> out({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(3)});
    float* data = out.mutable_data();
    py::gil_scoped_release release;
    counter_uniforms(seed, first, n, data);
    return out;
}

// The squared-length bounds of the direction check for this tolerance.
py::tuple direction_length2_bounds(double tolerance) {
    const DirectionCheck check = direction_check(tolerance);
    return py::make_tuple(check.length2_lowest, check.length2_highest);
}

void memory_roofline(const Float32Array& wi, const Float32Array& wo, Float32Array& out, int threads) {
    const std::int64_t n = wi.ndim() == 2 ? wi.shape(0) : -1;
    vec3_view(wi, 0, n, "wi");
    vec3_view(wo, 0, n, "wo");
    output_view(out, 0, n, "out");
    float* out_data = out.mutable_data();
    py::gil_scoped_release release;
    add_pairs(wi.data(), wo.data(), out_data, n, threads, streaming_output(n));  // the stores eval would use
}

py::dict cpu_info() {
    py::dict info;
    const std::string isa = active_isa();
    info["isa"] = isa;
    info["float_lanes"] = float_lanes(isa);
    info["available"] = available_isas();
    info["threads"] = hardware_threads();
    return info;
}

// The fields every options class has, read-write, and a repr that names them all.
template <class Options>
py::class_<Options> options_class(py::module_& m, const char* name, const char* doc, std::vector<const char*> fields) {
    py::class_<Options> options(m, name, doc);
    options.def_readwrite("model", &Options::model, "Index into MODEL_NAMES.")
        .def_readwrite("energy_compensation", &Options::energy_compensation,
                       "Include the multiple-scattering energy compensation.")
        .def_readwrite("check_tolerance", &Options::check_tolerance,
                       "Above 0: check that directions are unit vectors within this tolerance.")
        .def_readwrite("mode", &Options::mode, "Index into MODE_NAMES (the 2015 models' transport mode).")
        .def_readwrite("threads", &Options::threads, "Threads to use (0: all cores).")
        .def_readwrite("isa", &Options::isa,
                       "Instruction set: \"\" (the CPU's choice) or one of cpu_info()[\"available\"].")
        .def("__repr__", [name, fields](const py::object& self) {
            std::string text = std::string(name) + "(";
            for (std::size_t k = 0; k < fields.size(); ++k)
                text += std::string(k ? ", " : "") + fields[k] + "=" +
                        py::repr(self.attr(fields[k])).cast<std::string>();
            return text + ")";
        });
    return options;
}

}  // namespace

void bind_batch(py::module_& m) {
    options_class<EvalOptions>(m, "EvalOptions", "The options of batch_eval and batch_eval_grad.",
                               {"model", "cosine", "energy_compensation", "mode", "check_tolerance", "threads", "isa"})
        .def(py::init([](int model, bool cosine, bool energy_compensation, int mode, double check_tolerance, int threads,
                         std::string isa) {
                 EvalOptions options;
                 options.model = model;
                 options.cosine = cosine;
                 options.energy_compensation = energy_compensation;
                 options.mode = mode;
                 options.check_tolerance = check_tolerance;
                 options.threads = threads;
                 options.isa = std::move(isa);
                 return options;
             }),
             py::kw_only(), py::arg("model") = 0, py::arg("cosine") = false, py::arg("energy_compensation") = false, py::arg("mode") = 0,
             py::arg("check_tolerance") = 0.0, py::arg("threads") = 0, py::arg("isa") = "")
        .def_readwrite("cosine", &EvalOptions::cosine, "Multiply by cos θl.");
    options_class<PdfOptions>(m, "PdfOptions", "The options of batch_pdf (model and cosine: of the value, if any).",
                              {"model", "sampler", "cosine", "energy_compensation", "mode", "check_tolerance", "threads", "isa"})
        .def(py::init([](int model, int sampler, bool cosine, bool energy_compensation, int mode, double check_tolerance,
                         int threads, std::string isa) {
                 PdfOptions options;
                 options.model = model;
                 options.sampler = sampler;
                 options.cosine = cosine;
                 options.energy_compensation = energy_compensation;
                 options.mode = mode;
                 options.check_tolerance = check_tolerance;
                 options.threads = threads;
                 options.isa = std::move(isa);
                 return options;
             }),
             py::kw_only(), py::arg("model") = 0, py::arg("sampler") = 0, py::arg("cosine") = false,
             py::arg("energy_compensation") = false, py::arg("mode") = 0, py::arg("check_tolerance") = 0.0, py::arg("threads") = 0,
             py::arg("isa") = "")
        .def_readwrite("sampler", &PdfOptions::sampler, "Index into SAMPLER_NAMES.")
        .def_readwrite("cosine", &PdfOptions::cosine, "Multiply the value by cos θl.");
    options_class<SampleOptions>(m, "SampleOptions", "The options of batch_sample.",
                                 {"model", "sampler", "energy_compensation", "mode", "seed", "check_tolerance", "threads", "isa"})
        .def(py::init([](int model, int sampler, bool energy_compensation, int mode, std::uint64_t seed, double check_tolerance,
                         int threads, std::string isa) {
                 SampleOptions options;
                 options.model = model;
                 options.sampler = sampler;
                 options.energy_compensation = energy_compensation;
                 options.mode = mode;
                 options.seed = seed;
                 options.check_tolerance = check_tolerance;
                 options.threads = threads;
                 options.isa = std::move(isa);
                 return options;
             }),
             py::kw_only(), py::arg("model") = 0, py::arg("sampler") = 0, py::arg("energy_compensation") = false, py::arg("mode") = 0,
             py::arg("seed") = 0, py::arg("check_tolerance") = 0.0, py::arg("threads") = 0, py::arg("isa") = "")
        .def_readwrite("sampler", &SampleOptions::sampler, "Index into SAMPLER_NAMES.")
        .def_readwrite("seed", &SampleOptions::seed, "Seed of the counter-based uniforms (without u).");

    // Every argument by keyword: the arrays with their layout codes, and the options.
    m.def("batch_eval", &batch_eval, py::kw_only(), py::arg("wi"), py::arg("wi_layout"), py::arg("wo"),
          py::arg("wo_layout"), py::arg("params"), py::arg("outputs"), py::arg("out_layout"), py::arg("n"),
          py::arg("lobes"), py::arg("options"), py::arg("segments") = py::none(),
          "SIMD evaluation (f, or the lobes) into preallocated float32 outputs (validated by the caller); "
          "segments: (count, length, offsets, single), inputs read in place per segment.");
    m.def("batch_eval_grad", &batch_eval_grad, py::kw_only(), py::arg("wi"), py::arg("wi_layout"), py::arg("wo"),
          py::arg("wo_layout"), py::arg("params"), py::arg("out"), py::arg("jacobian"), py::arg("out_layout"),
          py::arg("n"), py::arg("options"), py::arg("columns") = py::none(), py::arg("segments") = py::none(),
          "SIMD f and its Jacobian over the parameter slots (columns: their indices, None for all) into "
          "preallocated float32 outputs.");
    m.def("batch_eval_vjp", &batch_eval_vjp, py::kw_only(), py::arg("wi"), py::arg("wi_layout"), py::arg("wo"),
          py::arg("wo_layout"), py::arg("params"), py::arg("cotangent"), py::arg("cotangent_layout"), py::arg("vjp"),
          py::arg("out_layout"), py::arg("n"), py::arg("options"), py::arg("columns") = py::none(),
          py::arg("segments") = py::none(), "SIMD vector-Jacobian product Σ_c g_c ∂f_c/∂p per element into a preallocated float32 output.");
    m.def("batch_eval_direction_grad", &batch_eval_direction_grad, py::kw_only(), py::arg("wi"), py::arg("wi_layout"),
          py::arg("wo"), py::arg("wo_layout"), py::arg("params"), py::arg("out"), py::arg("jacobian"),
          py::arg("out_layout"), py::arg("n"), py::arg("options"), py::arg("segments") = py::none(),
          "SIMD f and its Jacobian in wi_x, wi_y, wi_z, wo_x, wo_y, wo_z into preallocated float32 outputs.");
    m.def("batch_eval_direction_vjp", &batch_eval_direction_vjp, py::kw_only(), py::arg("wi"), py::arg("wi_layout"),
          py::arg("wo"), py::arg("wo_layout"), py::arg("params"), py::arg("cotangent"), py::arg("cotangent_layout"),
          py::arg("vjp"), py::arg("out_layout"), py::arg("n"), py::arg("options"), py::arg("segments") = py::none(),
          "SIMD Σ_c g_c ∂f_c/∂w per element for the six direction components into a preallocated float32 output.");
    m.def("batch_pdf", &batch_pdf, py::kw_only(), py::arg("wi"), py::arg("wi_layout"), py::arg("wo"),
          py::arg("wo_layout"), py::arg("params"), py::arg("pdf"), py::arg("out") = py::none(),
          py::arg("out_layout") = 0, py::arg("n"), py::arg("options"), py::arg("segments") = py::none(),
          "SIMD sampling pdf into a preallocated float32 array (and f into out, in the same pass, if given).");
    m.def("batch_sample", &batch_sample, py::kw_only(), py::arg("wo"), py::arg("wo_layout"), py::arg("u"),
          py::arg("u_layout"), py::arg("params"), py::arg("wi"), py::arg("weight"), py::arg("pdf"), py::arg("lobe"),
          py::arg("lobe_weights") = py::none(), py::arg("out_layout"), py::arg("n"), py::arg("options"),
          py::arg("segments") = py::none(), "SIMD sampling into preallocated outputs (and each lobe's share of the weight, if given).");
    m.def("counter_uniforms", &uniforms, py::arg("seed"), py::arg("first"), py::arg("n"),
          "The counter-based uniforms (n, 3) that sampling uses for elements first .. first + n - 1.");
    m.def("direction_length2_bounds", &direction_length2_bounds, py::arg("tolerance"),
          "(lowest, highest): a direction passes the check when its float64 squared length lies within.");
    m.def("memory_roofline", &memory_roofline, py::arg("wi"), py::arg("wo"), py::arg("out"), py::arg("threads"),
          "out = wi + wo over (N, 3) float32 arrays: the bytes eval moves, by the stores eval uses, at memory speed.");
    m.def("cpu_info", &cpu_info, "Instruction set in use, the available ones, SIMD width, hardware threads.");
    m.def("float_lanes", &float_lanes, py::arg("isa"));
}

}  // namespace principled_brdf::bindings
