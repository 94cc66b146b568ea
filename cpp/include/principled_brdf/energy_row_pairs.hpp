// The table of energy_tables.hpp rearranged for lookups whose row differs from
// lane to lane (a per-element roughness): the cubics of rows j and j + 1 at
// interval k side by side in 32 contiguous bytes,
//   kMissingRowPairs[model][kPairWidth (j kIntervals + k) + kCoefficients h + c]
//     = kMissing[model][kCoefficients ((j + h) kIntervals + k) + c],   h = 0, 1,
// for j < kRoughnesses - 1: one 32-byte load a lane (model/energy.hpp).
#pragma once

#include "principled_brdf/energy_tables.hpp"

namespace principled_brdf::energy {

inline constexpr int kPairWidth = 2 * kCoefficients;

extern const float* const kMissingRowPairs[2];

}  // namespace principled_brdf::energy
