// The batched API the bindings call: views of float32 arrays in, views out.
// The caller (the bindings) has validated shapes, domains and directions and
// allocated the outputs; nothing here allocates per element or throws in the
// hot path.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "params.hpp"

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
    kLobes = 1,  // diffuse, sheen, specular, clearcoat
    kPdf = 2,    // the sampling pdf of (wi, wo)
};
inline constexpr int kLobeCount = 4;

// How the primary specular lobe is sampled (README "Sampling and pdf").
enum class SpecularSampler : int {
    kVisibleNormals = 0,  // Dupuy & Benyoub 2023 spherical caps; pdf G1(wo) Ds / (4 cos θv)
    kDistribution = 1,    // the paper's eq. 14-15; pdf Ds cos θh / (4 cos θd)
};

inline bool uniform_material(const ParamSlot* params) {
    for (int s = 0; s < kParamSlots; ++s)
        if (params[s].per_element()) return false;
    return true;
}

struct EvalJob {
    Vec3Array wi, wo;
    ParamSlot params[kParamSlots];
    Model model = Model::kDisney2014;
    Output output = Output::kTotal;
    bool cosine = false;  // multiply by cos θl
    // out[0] is f; with Output::kLobes, out[0..3] are the four lobes.
    MutableVec3Array out[kLobeCount];
    // Output::kPdf: one float per element, for this specular sampler.
    float* pdf = nullptr;
    SpecularSampler sampler = SpecularSampler::kVisibleNormals;
    // Direction check fused into the evaluation: squared lengths must lie in
    // [length2_lowest, length2_highest]. Outputs are then written up to the
    // first bad element only, so use it on outputs nobody else sees yet.
    bool check_directions = false;
    float length2_lowest = 0.0f, length2_highest = 0.0f;

    bool uniform_material() const { return principled_brdf::uniform_material(params); }
};

// sample(material, wo, u): wi, pdf, weight = f cos θl / pdf and lobe per element.
struct SampleJob {
    Vec3Array wo;
    Vec3Array u;  // three uniforms per element, or data == nullptr for the counter-based generator
    std::uint64_t seed = 0;
    std::int64_t first_index = 0;  // generator index of element 0
    ParamSlot params[kParamSlots];
    Model model = Model::kDisney2014;
    SpecularSampler sampler = SpecularSampler::kVisibleNormals;
    MutableVec3Array wi, weight;  // outputs, (N, 3) or (3, N)
    float* pdf = nullptr;         // output, N
    std::int32_t* lobe = nullptr; // output, N: 0 cosine, 1 specular, 2 clearcoat
    bool check_directions = false;  // wo, as in EvalJob
    float length2_lowest = 0.0f, length2_highest = 0.0f;
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
// Returns -1, or with job.check_directions an element with a bad direction.
std::int64_t eval(const EvalJob& job, std::int64_t n, int threads, const std::string& isa = "");

// As eval, for sampling; returns -1 or an element whose wo is bad.
std::int64_t sample(const SampleJob& job, std::int64_t n, int threads, const std::string& isa = "");

// Squared-length bounds for directions within `tolerance` of unit length.
template <class Job>
void set_direction_check(Job& job, float tolerance) {
    // |w| within [1 - tol, 1 + tol]  <=>  |w|² within [(1 - tol)², (1 + tol)²]
    job.check_directions = true;
    job.length2_lowest = (1.0f - tolerance) * (1.0f - tolerance);
    job.length2_highest = (1.0f + tolerance) * (1.0f + tolerance);
}

// The counter-based uniforms sample() uses for elements first .. first + n - 1,
// written as (n, 3) interleaved into out (scalar code, bit-identical to the kernels').
void counter_uniforms(std::uint64_t seed, std::int64_t first, std::int64_t n, float* out);

// Index of the first element whose length differs from 1 by more than
// `tolerance` or which is not finite, or -1 if there is none.
std::int64_t first_bad_direction(const Vec3Array& directions, std::int64_t n, float tolerance, int threads);

int hardware_threads();

// The memory roofline: out[i] = wi[i] + wo[i] over 3 n floats each, moving
// the bytes an (N, 3) eval moves (reads 24, writes 12 per pair).
void add_pairs(const float* wi, const float* wo, float* out, std::int64_t n, int threads);

}  // namespace principled_brdf
