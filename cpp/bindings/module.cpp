// The pybind11 module principled_brdf._core: one bind_* function per area.
#include <pybind11/pybind11.h>

#include "bindings.hpp"

PYBIND11_MODULE(_core, m) {
    m.doc() = "principled_brdf native core (use the principled_brdf package, not this module)";
    principled_brdf::bindings::bind_params(m);
    principled_brdf::bindings::bind_reference(m);
    principled_brdf::bindings::bind_microfacet(m);
    principled_brdf::bindings::bind_batch(m);
    principled_brdf::bindings::bind_fit(m);
}
