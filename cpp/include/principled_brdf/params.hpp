// The 14 parameters of docs/model.md, "The model", and docs/model-2015.md:
// names, defaults, domains.
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
    // read by the 2015 models only (docs/model-2015.md); 0 for the others
    kSpecTrans,
    kFlatness,
    kDiffTrans,
    kParamSlots  // 16
};

// The slots the 2012 and 2014 models read, and the columns of their
// derivatives: base_color to clearcoat_gloss. The 2015 models' derivatives
// take every slot (gradient_slots).
inline constexpr int kGradientSlots = kSpecTrans;  // 13

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
inline constexpr std::array<ParamInfo, 14> kParams{{
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
    {"spec_trans", kSpecTrans, 1, {0.0}, 0.0, 1.0},
    {"flatness", kFlatness, 1, {0.0}, 0.0, 1.0},
    {"diff_trans", kDiffTrans, 1, {0.0}, 0.0, 2.0},
}};

// The default of the parameter that owns a slot (base_color's for its three).
constexpr double default_of(Param slot) {
    for (const ParamInfo& info : kParams)
        if (slot >= info.first_slot && slot < info.first_slot + info.slots) return info.default_value[slot - info.first_slot];
    return 0.0;
}

// The models (docs/model.md, "The model"; docs/model-2015.md): the 2014 and 2012
// BRDFs, which differ only in the specular masking term, and the 2015 BSDFs of a
// solid and of a thin sheet. What is known of each, its name among it, is its
// row of the model table (model_table.hpp).
enum class Model : int {
    kDisney2014 = 0,  // anisotropic Smith GGX with the material's alpha_x, alpha_y
    kDisney2012 = 1,  // isotropic Smith GGX with alpha_g = (0.5 + roughness / 2)^2
    kDisney2015 = 2,  // the 2015 BSDF of a solid: a rough dielectric interface over the whole sphere (docs/model-2015.md)
    kDisney2015Thin = 3,  // the 2015 BSDF of a thin sheet: light passes through without bending (docs/model-2015.md)
};

// The lobes of f, in the order eval_lobes returns them; multiple_scattering is
// the energy compensation's (0 unless it is on), transmission the 2015 models'
// light through the interface (0 for the BRDFs), diffuse_transmission the thin
// sheet's diffuse light through it (0 for the others).
inline constexpr std::array<const char*, 7> kLobeNames{"diffuse", "sheen", "specular", "clearcoat", "multiple_scattering",
                                                       "transmission", "diffuse_transmission"};
inline constexpr int kLobeCount = static_cast<int>(kLobeNames.size());

// The lobes sampling draws from, by the index a sample reports (transmission: the 2015 models';
// diffuse_transmission: the thin sheet's).
inline constexpr std::array<const char*, 5> kSampledLobeNames{"cosine", "specular", "clearcoat", "transmission",
                                                              "diffuse_transmission"};

// Which way light flows through a transmitting interface (docs/model-2015.md):
// radiance from wi to wo, or importance from wo to wi; only the 2015 solid's
// transmission differs (by η_t²).
enum class TransportMode : int { kRadiance = 0, kImportance = 1 };
inline constexpr std::array<const char*, 2> kTransportModeNames{"radiance", "importance"};

// How the primary specular lobe draws its half vector (docs/sampling.md).
enum class SpecularSampler : int {
    kVisibleNormals = 0,  // Dupuy & Benyoub 2023 spherical caps; pdf G1(wo) Ds / (4 cos θv)
    kDistribution = 1,    // Burley 2012 eq. 14-15; pdf Ds cos θh / (4 cos θd)
};
inline constexpr std::array<const char*, 2> kSpecularSamplerNames{"visible", "distribution"};

}  // namespace principled_brdf
