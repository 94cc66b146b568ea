// Entry points of the binding translation units.
#pragma once

#include <pybind11/pybind11.h>

#include <array>
#include <stdexcept>
#include <string>

#include "principled_brdf/batch.hpp"
#include "principled_brdf/model_table.hpp"

namespace principled_brdf::bindings {

// An index into one of params.hpp's name tables, as the enum it numbers: the
// Python side validated the name; this keeps a bad index from reaching C++.
template <class Enum, std::size_t N>
Enum enum_from(int index, const std::array<const char*, N>& names, const char* what) {
    if (index < 0 || index >= static_cast<int>(names.size()))
        throw std::invalid_argument(std::string(what) + ": expected an index below " + std::to_string(names.size()));
    return static_cast<Enum>(index);
}

// An index into MODEL_NAMES (the model table's order) as its model.
inline Model model_from(int index) {
    if (index < 0 || index >= static_cast<int>(kModels.size()))
        throw std::invalid_argument("model: expected an index below " + std::to_string(kModels.size()));
    return kModels[index].model;
}
inline TransportMode mode_from(int index) { return enum_from<TransportMode>(index, kTransportModeNames, "mode"); }
inline SpecularSampler sampler_from(int index) {
    return enum_from<SpecularSampler>(index, kSpecularSamplerNames, "specular_sampler");
}

// The parameter slots of a derivative (Columns): None for all, or increasing slot indices.
Columns columns_from(const pybind11::object& slots, Model model);

void bind_params(pybind11::module_& m);
void bind_reference(pybind11::module_& m);
void bind_microfacet(pybind11::module_& m);
void bind_batch(pybind11::module_& m);
void bind_fit(pybind11::module_& m);

}  // namespace principled_brdf::bindings
