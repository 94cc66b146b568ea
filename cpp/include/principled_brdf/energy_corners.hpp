// The tables of energy_tables.hpp rearranged for lookups whose row differs
// from lane to lane (a per-element roughness): the four nodes about a point,
//   kMissingCorners[model][4 (j kCosines + k) + c] = kMissing[model][j kCosines + k + (c & 1) + (c >> 1) kCosines],
// (row j at nodes k and k + 1, then row j + 1 at both), for j < kRoughnesses - 1
// and k < kCosines - 1 (0 elsewhere): one 16-byte load a lane instead of two
// pairs gathered from two rows (model/energy.hpp).
#pragma once

#include "principled_brdf/energy_tables.hpp"

namespace principled_brdf::energy {

inline constexpr int kCorners = 4;

extern const float* const kMissingCorners[2];

}  // namespace principled_brdf::energy
