// The model instantiated for double (docs/model.md), in principled_brdf::f64:
// the float64 reference (reference.hpp) and the toolkit's distributions where
// they are the model's (microfacet.hpp). Exact operations (model/scalar_ops.hpp).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>
#include <utility>

#include "principled_brdf/dielectric_energy_tables.hpp"
#include "principled_brdf/energy_corners.hpp"
#include "principled_brdf/model_table.hpp"

namespace principled_brdf::f64 {

#include "scalar_ops.hpp"
#define PB_MODEL_INLINE inline
#include "model.hpp"
#include "toolkit.hpp"
#undef PB_MODEL_INLINE

}  // namespace principled_brdf::f64
