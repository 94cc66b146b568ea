// The 11 parameters of docs/model.md, "The model": names, defaults, domains.
// Shared by the reference, the batch layer and (through the bindings) Python,
// so the table exists exactly once.
#pragma once

#include <array>
#include <cstddef>
#include <limits>

namespace principled_brdf {

// Index of each parameter in a packed parameter row. base_color takes three
// slots (linear R, G, B); every other parameter takes one.
enum Param : int {
    kBaseColorR = 0,
    kBaseColorG,
    kBaseColorB,
    kMetallic,
    kSubsurface,
    kSpecular,
    kSpecularTint,
    kRoughness,
    kAnisotropic,
    kSheen,
    kSheenTint,
    kClearcoat,
    kClearcoatGloss,
    kParamSlots  // 13
};

struct ParamInfo {
    const char* name;
    int first_slot;
    int slots;  // 3 for base_color, else 1
    double default_value[3];
    double lower;
    double upper;  // +inf where the domain has no upper bound
};

inline constexpr double kUnbounded = std::numeric_limits<double>::infinity();

// Defaults are the BRDF Explorer's (disney.brdf's parameter block).
inline constexpr std::array<ParamInfo, 11> kParams{{
    {"base_color", kBaseColorR, 3, {0.82, 0.67, 0.16}, 0.0, kUnbounded},
    {"metallic", kMetallic, 1, {0.0}, 0.0, 1.0},
    {"subsurface", kSubsurface, 1, {0.0}, 0.0, 1.0},
    {"specular", kSpecular, 1, {0.5}, 0.0, kUnbounded},
    {"specular_tint", kSpecularTint, 1, {0.0}, 0.0, 1.0},
    {"roughness", kRoughness, 1, {0.5}, 0.0, kUnbounded},
    {"anisotropic", kAnisotropic, 1, {0.0}, 0.0, 1.0},
    {"sheen", kSheen, 1, {0.0}, 0.0, kUnbounded},
    {"sheen_tint", kSheenTint, 1, {0.5}, 0.0, 1.0},
    {"clearcoat", kClearcoat, 1, {0.0}, 0.0, kUnbounded},
    {"clearcoat_gloss", kClearcoatGloss, 1, {1.0}, 0.0, 1.0},
}};

// The default of the parameter that owns a slot (base_color's for its three).
constexpr double default_of(Param slot) {
    for (const ParamInfo& info : kParams)
        if (slot >= info.first_slot && slot < info.first_slot + info.slots) return info.default_value[slot - info.first_slot];
    return 0.0;
}

// Which specular masking term the model uses (docs/model.md, "The model"); the names
// are the Python ones, in the enum's order.
enum class Model : int {
    kDisney2014 = 0,  // anisotropic Smith GGX with the material's alpha_x, alpha_y
    kDisney2012 = 1,  // isotropic Smith GGX with alpha_g = (0.5 + roughness / 2)^2
};
inline constexpr std::array<const char*, 2> kModelNames{"disney2014", "disney2012"};

// The lobes of f, in the order eval_lobes returns them; multiple_scattering is
// the energy compensation's (0 unless it is on).
inline constexpr std::array<const char*, 5> kLobeNames{"diffuse", "sheen", "specular", "clearcoat", "multiple_scattering"};
inline constexpr int kLobeCount = static_cast<int>(kLobeNames.size());

// The lobes sampling draws from, by the index a sample reports.
inline constexpr std::array<const char*, 3> kSampledLobeNames{"cosine", "specular", "clearcoat"};

// How the primary specular lobe draws its half vector (docs/sampling.md).
enum class SpecularSampler : int {
    kVisibleNormals = 0,  // Dupuy & Benyoub 2023 spherical caps; pdf G1(wo) Ds / (4 cos θv)
    kDistribution = 1,    // Burley 2012 eq. 14-15; pdf Ds cos θh / (4 cos θd)
};
inline constexpr std::array<const char*, 2> kSpecularSamplerNames{"visible", "distribution"};

}  // namespace principled_brdf
