// The tables of energy_tables.hpp rearranged for lookups whose row differs
// from lane to lane (a per-element roughness): an interval's value and slope
// in two adjacent rows,
//   kMissingCorners[table][4 (j kIntervals + b) + c] = kMissing[table][2 (j kIntervals + b) + (c & 1) + (c >> 1) 2 kIntervals],
// (row j's value and slope, then row j + 1's), for j < kRoughnesses - 1 (0
// beyond): one 16-byte load a lane instead of two pairs from two rows
// (model/energy.hpp).
#pragma once

#include "principled_brdf/energy_tables.hpp"

namespace principled_brdf::energy {

inline constexpr int kCorners = 4;

extern const float* const kMissingCorners[2];

}  // namespace principled_brdf::energy
