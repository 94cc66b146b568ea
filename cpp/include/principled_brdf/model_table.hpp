// The model table: one row per model, everything the kernels, the bindings
// and (through them) Python know of a model apart from its formulas
// (docs/model.md, "Adding a model"). A model is found by its row, never by
// its enum value's position.
#pragma once

#include <array>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <type_traits>
#include <utility>

#include "params.hpp"

namespace principled_brdf {

// The lobes of f, by their index in kLobeNames (eval_lobes' order).
enum class Lobe : int { kDiffuse, kSheen, kSpecular, kClearcoat, kMultipleScattering, kTransmission, kDiffuseTransmission };
// The lobes sampling draws from, by their index in kSampledLobeNames (the index a sample reports).
enum class SampledLobe : int { kCosine, kSpecular, kClearcoat, kTransmission, kDiffuseTransmission };

// A set of parameters (bit k: kParams[k]), of lobes or of sampled lobes (bit k: the enum's k-th).
using BitSet = std::uint32_t;

template <class Enum>
constexpr BitSet bits_of(std::initializer_list<Enum> members) {
    BitSet set = 0;
    for (Enum member : members) set |= BitSet(1) << static_cast<int>(member);
    return set;
}

// The parameters a test of their first slot keeps.
constexpr BitSet parameters_where(bool (*keep)(Param first_slot)) {
    BitSet set = 0;
    for (std::size_t k = 0; k < kParams.size(); ++k)
        if (keep(static_cast<Param>(kParams[k].first_slot))) set |= BitSet(1) << k;
    return set;
}

constexpr bool contains(BitSet set, int member) { return (set >> member) & 1u; }

struct ModelRow {
    Model model;
    const char* name;              // the Python name
    bool whole_sphere;             // f over the whole sphere of directions (a BSDF), else the upper hemisphere only
    BitSet reads;                  // the parameters it reads; the others must stay at their defaults
    int gradient_slots;            // its derivatives' columns: the first gradient_slots packed slots
    BitSet lobes;                  // the lobes f can have nonzero (Lobe)
    BitSet sampled_lobes;          // the lobes sampling can draw (SampledLobe)
    int energy_table;              // the BRDFs' energy compensation's table (energy_tables.hpp's first index), or -1: none
    bool energy_compensation;      // whether it offers energy_compensation=True (the 2015 solid's: dielectric_energy_tables.hpp)
    double max_ior;                // the largest index of refraction, from specular (docs/model-2015.md); +inf: unbounded
};

inline constexpr int kNoEnergyTable = -1;
// The 2015 models hold their float32 accuracy up to η = 10 (docs/model-2015.md, "Parameters").
inline constexpr double kMaxIor2015 = 10.0;

namespace model_rows {
constexpr bool before_spec_trans(Param first) { return first < kSpecTrans; }
constexpr bool solid_reads(Param first) { return first != kSubsurface && first != kDiffTrans; }
constexpr bool sheet_reads(Param first) { return first != kSubsurface; }

inline constexpr BitSet kBrdfLobes = bits_of({Lobe::kDiffuse, Lobe::kSheen, Lobe::kSpecular, Lobe::kClearcoat,
                                              Lobe::kMultipleScattering});
inline constexpr BitSet kBrdfSampled = bits_of({SampledLobe::kCosine, SampledLobe::kSpecular, SampledLobe::kClearcoat});
inline constexpr BitSet kSolidLobes =
        bits_of({Lobe::kDiffuse, Lobe::kSheen, Lobe::kSpecular, Lobe::kClearcoat, Lobe::kTransmission});
inline constexpr BitSet kSolidSampled = kBrdfSampled | bits_of({SampledLobe::kTransmission});
// the solid's energy compensation adds a lobe, its transmitted part drawn as a diffuse transmission
inline constexpr BitSet kCompensatedSolidLobes = kSolidLobes | bits_of({Lobe::kMultipleScattering});
inline constexpr BitSet kSolidOrSheetSampled = kSolidSampled | bits_of({SampledLobe::kDiffuseTransmission});
}  // namespace model_rows

inline constexpr std::array<ModelRow, 4> kModels{{
    {Model::kDisney2014, "disney2014", false, parameters_where(model_rows::before_spec_trans), kGradientSlots,
     model_rows::kBrdfLobes, model_rows::kBrdfSampled, 0, true, std::numeric_limits<double>::infinity()},
    {Model::kDisney2012, "disney2012", false, parameters_where(model_rows::before_spec_trans), kGradientSlots,
     model_rows::kBrdfLobes, model_rows::kBrdfSampled, 1, true, std::numeric_limits<double>::infinity()},
    {Model::kDisney2015, "disney2015", true, parameters_where(model_rows::solid_reads), kParamSlots,
     model_rows::kCompensatedSolidLobes, model_rows::kSolidOrSheetSampled, kNoEnergyTable, true, kMaxIor2015},
    {Model::kDisney2015Thin, "disney2015_thin", true, parameters_where(model_rows::sheet_reads), kParamSlots,
     model_rows::kSolidLobes | bits_of({Lobe::kDiffuseTransmission}),
     model_rows::kSolidOrSheetSampled, kNoEnergyTable, false, kMaxIor2015},
}};

constexpr const ModelRow& row_of(Model model) {
    for (const ModelRow& row : kModels)
        if (row.model == model) return row;
    throw "principled_brdf: a Model without a row in kModels";  // (a compile error where evaluated at compile time)
}

// Every model has exactly one row.
constexpr bool one_row_each() {
    for (std::size_t a = 0; a < kModels.size(); ++a)
        for (std::size_t b = a + 1; b < kModels.size(); ++b)
            if (kModels[a].model == kModels[b].model) return false;
    return true;
}
static_assert(one_row_each(), "a model appears twice in kModels");

// The largest specular a model takes: 0.08 specular = ((η - 1)/(η + 1))² at its largest η.
constexpr double max_specular(const ModelRow& row) {
    if (row.max_ior == std::numeric_limits<double>::infinity()) return row.max_ior;
    const double r = (row.max_ior - 1.0) / (row.max_ior + 1.0);
    return r * r / 0.08;
}

// body(model) with the model as a compile-time constant (std::integral_constant),
// for each row of the table the one that is `model`.
template <class Body, std::size_t... k>
auto with_model(Model model, Body&& body, std::index_sequence<k...>) {
    using Result = decltype(body(std::integral_constant<Model, kModels[0].model>{}));
    Result result{};
    ((model == kModels[k].model && (result = body(std::integral_constant<Model, kModels[k].model>{}), true)) || ...);
    return result;
}

template <class Body>
auto with_model(Model model, Body&& body) {
    return with_model(model, body, std::make_index_sequence<kModels.size()>{});
}

// The models whose directions lie on the whole sphere (the others are BRDFs: f = 0 off the upper hemisphere).
constexpr bool is_bsdf(Model model) { return row_of(model).whole_sphere; }
// The slots a model's derivatives are taken by: the first gradient_slots(model) of the table.
constexpr int gradient_slots(Model model) { return row_of(model).gradient_slots; }
constexpr bool has_energy_table(Model model) { return row_of(model).energy_table != kNoEnergyTable; }

}  // namespace principled_brdf
