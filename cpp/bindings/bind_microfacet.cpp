#include "bindings.hpp"
namespace principled_brdf::bindings { void bind_microfacet(pybind11::module_&) {} }
