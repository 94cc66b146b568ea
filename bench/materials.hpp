// The benchmark's material set: the benchmark material (every lobe on), the
// ten presets of python/principled_brdf/presets.py
// (tests/repository/test_bench_materials_are_the_presets.py keeps the two in
// step), each a uniform material in params.hpp's slot order
// with the defaults elsewhere; random per-element materials are made in
// bench_eval.cpp.
#pragma once

#include <array>

#include "principled_brdf/params.hpp"

namespace bench {

struct NamedMaterial {
    const char* name;
    std::array<float, principled_brdf::kParamSlots> slots;
};

// slots: base_color r g b, metallic, subsurface, specular, specular_tint,
// roughness, anisotropic, sheen, sheen_tint, clearcoat, clearcoat_gloss
inline constexpr NamedMaterial kMaterials[] = {
    {"benchmark", {0.82f, 0.67f, 0.16f, 0.2f, 0.3f, 0.5f, 0.1f, 0.4f, 0.3f, 0.2f, 0.5f, 0.5f, 0.7f}},
    {"gold", {1.0f, 0.766f, 0.336f, 1.0f, 0.0f, 0.5f, 0.0f, 0.3f, 0.0f, 0.0f, 0.5f, 0.0f, 1.0f}},
    {"copper", {0.955f, 0.638f, 0.538f, 1.0f, 0.0f, 0.5f, 0.0f, 0.35f, 0.0f, 0.0f, 0.5f, 0.0f, 1.0f}},
    {"chrome", {0.55f, 0.556f, 0.554f, 1.0f, 0.0f, 0.5f, 0.0f, 0.08f, 0.0f, 0.0f, 0.5f, 0.0f, 1.0f}},
    {"brushed_metal", {0.91f, 0.92f, 0.92f, 1.0f, 0.0f, 0.5f, 0.0f, 0.4f, 0.9f, 0.0f, 0.5f, 0.0f, 1.0f}},
    {"blue_rubber", {0.03f, 0.08f, 0.45f, 0.0f, 0.0f, 0.3f, 0.0f, 0.75f, 0.0f, 0.0f, 0.5f, 0.0f, 1.0f}},
    {"white_plastic", {0.8f, 0.8f, 0.8f, 0.0f, 0.0f, 0.5f, 0.0f, 0.25f, 0.0f, 0.0f, 0.5f, 0.0f, 1.0f}},
    {"car_paint", {0.5f, 0.015f, 0.02f, 0.2f, 0.0f, 0.5f, 0.0f, 0.45f, 0.0f, 0.0f, 0.5f, 1.0f, 0.93f}},
    {"satin_cloth", {0.45f, 0.12f, 0.3f, 0.0f, 0.0f, 0.3f, 0.0f, 0.85f, 0.0f, 1.0f, 0.6f, 0.0f, 1.0f}},
    {"skin", {0.8f, 0.5f, 0.4f, 0.0f, 0.8f, 0.35f, 0.0f, 0.55f, 0.0f, 0.1f, 0.5f, 0.0f, 1.0f}},
    {"ceramic", {0.85f, 0.82f, 0.75f, 0.0f, 0.0f, 0.5f, 0.0f, 0.5f, 0.0f, 0.0f, 0.5f, 0.8f, 1.0f}},
};

}  // namespace bench
