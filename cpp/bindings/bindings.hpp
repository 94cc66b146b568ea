// Entry points of the binding translation units.
#pragma once

#include <pybind11/pybind11.h>

namespace principled_brdf::bindings {

void bind_params(pybind11::module_& m);
void bind_reference(pybind11::module_& m);
void bind_microfacet(pybind11::module_& m);
void bind_batch(pybind11::module_& m);

}  // namespace principled_brdf::bindings
