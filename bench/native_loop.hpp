// A plain C++ loop of the kernel's float32 math for a uniform material, built
// with -O3 -march=native -ffast-math: what the compiler alone achieves.
#pragma once

#include <cstdint>

namespace principled_brdf::bench {

struct NativeMaterial {
    float base_color[3], metallic, subsurface, specular, specular_tint, roughness, anisotropic, sheen, sheen_tint,
        clearcoat, clearcoat_gloss;
};

// wi, wo, out interleaved (N, 3)
void native_eval_interleaved(const NativeMaterial& m, const float* wi, const float* wo, float* out, std::int64_t n);
// wi, wo, out as three rows of n
void native_eval_rows(const NativeMaterial& m, const float* wi, const float* wo, float* out, std::int64_t n);

}  // namespace principled_brdf::bench
