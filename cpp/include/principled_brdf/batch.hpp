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

enum class Output : int { kTotal = 0, kLobes = 1 };
inline constexpr int kLobeCount = 4;  // diffuse, sheen, specular, clearcoat

struct EvalJob {
    Vec3Array wi, wo;
    ParamSlot params[kParamSlots];
    Model model = Model::kDisney2014;
    Output output = Output::kTotal;
    bool cosine = false;  // multiply by cos θl
    // out[0] is f; with Output::kLobes, out[0..3] are the four lobes.
    MutableVec3Array out[kLobeCount];
    // Direction check fused into the evaluation: squared lengths must lie in
    // [length2_lowest, length2_highest]. Outputs are then written up to the
    // first bad element only, so use it on outputs nobody else sees yet.
    bool check_directions = false;
    float length2_lowest = 0.0f, length2_highest = 0.0f;

    bool uniform_material() const {
        for (const ParamSlot& slot : params)
            if (slot.per_element()) return false;
        return true;
    }
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

// Squared-length bounds for directions within `tolerance` of unit length.
void set_direction_check(EvalJob& job, float tolerance);

// Index of the first element whose length differs from 1 by more than
// `tolerance` or which is not finite, or -1 if there is none.
std::int64_t first_bad_direction(const Vec3Array& directions, std::int64_t n, float tolerance, int threads);

int hardware_threads();

// The memory roofline: out[i] = wi[i] + wo[i] over 3 n floats each, moving
// the bytes an (N, 3) eval moves (reads 24, writes 12 per pair).
void add_pairs(const float* wi, const float* wo, float* out, std::int64_t n, int threads);

}  // namespace principled_brdf
