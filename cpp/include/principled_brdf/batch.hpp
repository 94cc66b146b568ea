// The batched API the bindings call: views of float32 arrays in, views out.
// The caller (the bindings) has validated shapes, domains and directions and
// allocated the outputs; nothing here allocates per element or throws in the
// hot path.
#pragma once

#include <array>
#include <cstdint>
#include <type_traits>
#include <string>
#include <vector>

#include "model_table.hpp"

namespace principled_brdf {

// Three float32 components per element.
enum class Vec3Layout : int {
    kInterleaved = 0,  // x y z x y z ...: an (N, 3) array
    kRows = 1,         // three rows x..., y..., z... row_stride apart: a (3, N) array
    kSingle = 2,       // one vector for every element
};

struct Vec3Array {
    const float* data = nullptr;
    Vec3Layout layout = Vec3Layout::kInterleaved;
    std::int64_t row_stride = 0;  // kRows only
};

struct MutableVec3Array {
    float* data = nullptr;
    Vec3Layout layout = Vec3Layout::kInterleaved;  // kInterleaved or kRows
    std::int64_t row_stride = 0;
    // written past the caches by non-temporal stores (kInterleaved; eval's f
    // of a call larger than the last-level cache, which the batch layer decides)
    bool streaming = false;
};

// One material parameter slot: a value for the whole batch, or one value per
// element read at data[i * stride]. stride is 1, or 3 for an interleaved
// per-element base_color, whose G and B slots then point at R + 1 and R + 2.
struct ParamSlot {
    float value = 0.0f;
    const float* data = nullptr;
    int stride = 1;
    bool per_element() const { return data != nullptr; }
};

enum class Output : int {
    kTotal = 0,  // f
    kLobes = 1,  // the kLobeCount lobes of kLobeNames (params.hpp), in its order
    kPdf = 2,    // the sampling pdf of (wi, wo)
    kGradient = 3,  // f and its Jacobian in the parameter slots
    kValuePdf = 4,  // f and the sampling pdf of (wi, wo), in one pass
    kVjp = 5,       // Σ_c g_c ∂f_c/∂p per element for a cotangent g (no f, no Jacobian)
    // f and its Jacobian in the directions' components wi_x, wi_y, wi_z, wo_x,
    // wo_y, wo_z (docs/gradients.md, "Derivatives in the directions")
    kDirectionGradient = 6,
    kDirectionVjp = 7,  // Σ_c g_c ∂f_c/∂w per element for the six components (no f, no Jacobian)
};

// A list of outputs (the kernels' parts compile one list each): holds(output),
// and with(output, body), body(output) with the output as a compile-time
// constant (std::integral_constant) for an output of the list.
template <Output... outputs>
struct OutputList {
    static constexpr Output kFirst = std::array<Output, sizeof...(outputs)>{outputs...}[0];

    static constexpr bool holds(Output output) { return ((output == outputs) || ...); }

    template <class Body>
    static auto with(Output output, Body&& body) {
        using Result = decltype(body(std::integral_constant<Output, kFirst>{}));
        Result result{};
        ((output == outputs && (result = body(std::integral_constant<Output, outputs>{}), true)) || ...);
        return result;
    }
};

// The direction components the derivatives in the directions are taken by:
// wi_x, wi_y, wi_z, wo_x, wo_y, wo_z.
inline constexpr int kDirectionComponents = 6;

// The parameter slots a derivative is taken by (of the model's
// gradient_slots), in the table's order: column k of the outputs is the k-th
// wanted slot; position[p] is slot p's column, or -1.
struct Columns {
    int count = kGradientSlots;
    std::int8_t position[kParamSlots];

    // the 2012 and 2014 models' kGradientSlots
    Columns() {
        for (int p = 0; p < kParamSlots; ++p) position[p] = p < kGradientSlots ? static_cast<std::int8_t>(p) : -1;
    }
    // `slots`: count distinct slot indices in increasing order (the caller checked them)
    Columns(const int* slots, int slot_count) : count(slot_count) {
        for (int p = 0; p < kParamSlots; ++p) position[p] = -1;
        for (int k = 0; k < slot_count; ++k) position[slots[k]] = static_cast<std::int8_t>(k);
    }
    bool wants(int p) const { return position[p] >= 0; }
    bool all() const { return count == kGradientSlots; }
};

// The Jacobian's values per element: ∂f_c/∂p for the 3 channels c and the
// kGradientSlots slots p of the 2012 and 2014 models; at most kMaxJacobianWidth (the 2015 models').
inline constexpr int kJacobianWidth = 3 * kGradientSlots;
inline constexpr int kMaxJacobianWidth = 3 * kParamSlots;

inline bool uniform_material(const ParamSlot* params) {
    for (int s = 0; s < kParamSlots; ++s)
        if (params[s].per_element()) return false;
    return true;
}

// The direction check of docs/bad-input.md: a direction w passes when
//     (1 - tolerance)² <= wx² + wy² + wz² <= (1 + tolerance)²,
// the squares and sums taken in float64 in this order. The squares of floats
// are exact in float64, so the result does not depend on contraction into
// fused multiply-adds, and the Python side (numpy, float64) reaches the same
// decision for every vector: a direction passes everywhere or fails everywhere.
// The kernels first test the float32 squared length against bounds narrowed
// by far more than its rounding error (fast_lowest, fast_highest), which only
// accepts what the rule accepts, and decide any batch it does not accept
// element by element by the rule itself (run_checked in kernel_memory.hpp).
struct DirectionCheck {
    bool enabled = false;
    double length2_lowest = 0.0, length2_highest = 0.0;
    float fast_lowest = 0.0f, fast_highest = 0.0f;
};

DirectionCheck direction_check(double tolerance);

// The rule (scalar). `static`: one copy per translation unit, so a copy
// compiled with AVX-512 flags is never linked into baseline code.
static inline bool unit_length(float x, float y, float z, const DirectionCheck& check) {
    const double length2 = static_cast<double>(x) * x + static_cast<double>(y) * y + static_cast<double>(z) * z;
    return length2 >= check.length2_lowest && length2 <= check.length2_highest;  // false for NaN
}

struct EvalJob {
    Vec3Array wi, wo;
    ParamSlot params[kParamSlots];
    Model model = Model::kDisney2014;
    Output output = Output::kTotal;
    bool cosine = false;  // multiply by |cos θl|
    TransportMode mode = TransportMode::kRadiance;  // the 2015 solid's transmission (params.hpp)
    // the multiple-scattering energy compensation (model/energy.hpp); not with Output::kGradient
    bool energy_compensation = false;
    // out[0] is f; with Output::kLobes, out[0 .. kLobeCount - 1] are the lobes of kLobeNames.
    MutableVec3Array out[kLobeCount];
    // Output::kGradient: out[0] is f, and element i's ∂f_c/∂p for the P =
    // columns.count wanted slots p is at jacobian[3 P i + P c + k] (an (N, 3, P)
    // array, k = columns.position[p]) or, with jacobian_row_stride > 0, at
    // jacobian[(P c + k) jacobian_row_stride + i] (a (3, P, N) array).
    // Output::kVjp: element i's Σ_c g_c ∂f_c/∂p, g the cotangent's element i,
    // is at jacobian[P i + k] (an (N, P) array) or, with jacobian_row_stride > 0,
    // at jacobian[k jacobian_row_stride + i] (a (P, N) array).
    // Output::kDirectionGradient and kDirectionVjp: as kGradient and kVjp with
    // the P = 6 direction components wi_x, wi_y, wi_z, wo_x, wo_y, wo_z for
    // columns (`columns` is not read).
    float* jacobian = nullptr;
    std::int64_t jacobian_row_stride = 0;
    Columns columns;
    Vec3Array cotangent;  // Output::kVjp and kDirectionVjp
    // Output::kPdf and kValuePdf: one float per element, for this specular sampler.
    float* pdf = nullptr;
    SpecularSampler sampler = SpecularSampler::kVisibleNormals;
    // The direction check, fused into the evaluation. On a bad direction the
    // outputs hold the results of some other elements only.
    DirectionCheck check;
    // read the parameters per batch even where every slot holds one value
    // (a segment of a per-element call: Segments below)
    bool per_element_material = false;

    bool uniform_material() const { return !per_element_material && principled_brdf::uniform_material(params); }
    // The floats an element of this job's output writes to `jacobian`.
    int jacobian_width() const {
        switch (output) {
            case Output::kGradient: return 3 * columns.count;
            case Output::kVjp: return columns.count;
            case Output::kDirectionGradient: return 3 * kDirectionComponents;
            case Output::kDirectionVjp: return kDirectionComponents;
            default: return 0;
        }
    }
};

// The normal equations of least-squares problems (docs/fitting.md), for the
// fitting solver: problem b's residuals over its pairs n and channels c are
//     r = (u(g f) - t) s,  u(x) = x (Loss::kLinear) or log(1 + x) (Loss::kLog),
// with f = f_c(wi_n, wo_n) of the problem's material (times cos θl with
// `cosine`, |cos θl| for the 2015 models), g = gain[b] (1 without gains), t = target[b, n, c] and
// s = scale[b, n, c] (the caller folds the loss, its per-problem level, the
// weights and missing samples, s = 0, into g, t and s). Per problem,
// over the wanted columns k <= l (P = columns.count of them):
//     cost = Σ r²,  gradient_k = Σ r ∂r/∂p_k,  normal_kl = Σ ∂r/∂p_k ∂r/∂p_l,
// the upper triangle by rows, P (P + 1) / 2 numbers; no per-pair value is
// written. Each problem is summed by one thread in one order, so its sums do
// not depend on the other problems of the call nor on the thread count.
enum class Loss : int { kLinear = 0, kLog = 1 };

inline constexpr int kNormalWidth = kParamSlots * (kParamSlots + 1) / 2;  // the most entries (the 2015 models')

struct NormalEquationsJob {
    const float* wi = nullptr;  // (N, 3) shared by every problem, or (B, N, 3) with per_problem_directions
    const float* wo = nullptr;
    bool per_problem_directions = false;
    std::int64_t pairs = 0;               // N
    const float* slots = nullptr;         // (B, gradient_slots(model)): each problem's material
    const float* target = nullptr;        // (B, N, 3)
    const float* scale = nullptr;         // (B, N, 3)
    const float* gain = nullptr;          // (B,), or null for 1
    const std::int64_t* problems = nullptr;  // the `count` problems b to sum, result j for problems[j]
    Model model = Model::kDisney2014;
    Loss loss = Loss::kLinear;
    bool cosine = false;
    Columns columns;
    double* normal = nullptr;    // (count, P (P + 1) / 2)
    double* gradient = nullptr;  // (count, P)
    double* cost = nullptr;      // (count,)
};

// sample(material, wo, u): wi, pdf, weight = f |cos θl| / pdf and lobe per element.
struct SampleJob {
    Vec3Array wo;
    Vec3Array u;  // three uniforms per element, or data == nullptr for the counter-based generator
    std::uint64_t seed = 0;
    std::int64_t first_index = 0;  // generator index of element 0
    ParamSlot params[kParamSlots];
    Model model = Model::kDisney2014;
    SpecularSampler sampler = SpecularSampler::kVisibleNormals;
    bool energy_compensation = false;  // as in EvalJob
    TransportMode mode = TransportMode::kRadiance;  // as in EvalJob
    MutableVec3Array wi, weight;  // outputs, (N, 3) or (3, N)
    float* pdf = nullptr;         // output, N
    std::int32_t* lobe = nullptr; // output, N: an index into kSampledLobeNames (0 to 4; 3 and 4 the 2015 models')
    // optional outputs, (N, 3) or (3, N) each: every lobe's share of the weight
    // (the lobe's value |cos θl| / pdf, in kLobeNames' order); unused when the first is null
    MutableVec3Array lobe_weight[kLobeCount];
    DirectionCheck check;  // of wo, as in EvalJob
    bool per_element_material = false;  // as in EvalJob

    bool uniform_material() const { return !per_element_material && principled_brdf::uniform_material(params); }
};

// A call as `count` segments of `length` elements, element j of segment s
// being the call's element s length + j: the inputs that broadcast along the
// segments' axes are read in place (numpy's stride-0 views), never expanded.
// Segment s runs the call's job with each input's data advanced by its own
// offsets[input][s] floats (null: 0 for every segment) and every output's by
// s length elements; within a segment each input is contiguous, or one vector
// (Vec3Layout::kSingle), or with single[slot] one value of a parameter slot,
// read as a number (the segment's job then keeps per_element_material when the
// call has per-element slots, so every segment runs the call's loop).
enum SegmentInput : int { kSegmentWi = 0, kSegmentWo = 1, kSegmentThird = 2, kSegmentSlots = 3 };  // third: cotangent or u
inline constexpr int kSegmentInputs = kSegmentSlots + kParamSlots;

struct Segments {
    std::int64_t count = 1;
    std::int64_t length = 0;
    const std::int64_t* offsets[kSegmentInputs] = {};
    bool single[kParamSlots] = {};
};

// Instruction sets compiled into this build and supported by this CPU, best
// last; "sse2", "avx2", "avx512" on x86-64, "neon" on aarch64.
std::vector<std::string> available_isas();
// The one in use: the best available, or PRINCIPLED_BRDF_ISA if set (an
// unknown or unsupported value throws std::runtime_error on first use).
std::string active_isa();
int float_lanes(const std::string& isa);

// Evaluates elements [0, n) with `threads` threads (0: all cores) on `isa`
// ("" for the active one). Results are bit-identical for every thread count.
// Returns -1 when every element was written, or with job.check enabled the
// first element whose wi or wo fails it (then some elements are unwritten).
std::int64_t eval(const EvalJob& job, std::int64_t n, int threads, const std::string& isa = "");
// The same over segments.count * segments.length elements in segments
// (element indices the call's); threads share the segments' elements as eval's.
std::int64_t eval(const EvalJob& job, const Segments& segments, int threads, const std::string& isa = "");

// The normal equations of job.problems[0 .. count - 1] (directions unchecked:
// the caller checked them), on `threads` threads and `isa` as eval.
void normal_equations(const NormalEquationsJob& job, std::int64_t count, int threads, const std::string& isa = "");

// As eval, for sampling; returns -1 or an element whose wo is bad.
std::int64_t sample(const SampleJob& job, std::int64_t n, int threads, const std::string& isa = "");
// The same in segments (the generator's indices the call's elements').
std::int64_t sample(const SampleJob& job, const Segments& segments, int threads, const std::string& isa = "");

// The counter-based uniforms sample() uses for elements first .. first + n - 1,
// written as (n, 3) interleaved into out (scalar code, bit-identical to the kernels').
void counter_uniforms(std::uint64_t seed, std::int64_t first, std::int64_t n, float* out);

int hardware_threads();

// An (N, 3) float32 output of at least this many bytes is written by
// non-temporal stores (eval's f, and the roofline copy below): it would not
// stay in the last-level cache (32 MB on this project's machine kind), and a
// store that bypasses the caches does not first read its line from memory.
inline constexpr std::int64_t kStreamingBytes = std::int64_t{32} << 20;
inline bool streaming_output(std::int64_t pairs) { return pairs * 3 * static_cast<std::int64_t>(sizeof(float)) >= kStreamingBytes; }

// The memory roofline: out[i] = wi[i] + wo[i] over 3 n floats each, moving
// the bytes an (N, 3) eval moves (reads 24, writes 12 per pair); streaming:
// out written by non-temporal stores, as eval writes a large call's f.
void add_pairs(const float* wi, const float* wo, float* out, std::int64_t n, int threads, bool streaming = false);

}  // namespace principled_brdf
