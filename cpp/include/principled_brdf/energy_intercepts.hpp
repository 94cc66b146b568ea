// The tables of energy_tables.hpp with each interval's line written from μ = 0:
//   kMissingIntercepts[model][2 (j kIntervals + b)] = v - μ_b+1 s (the line's 1 - E at μ = 0),
//   kMissingIntercepts[model][2 (j kIntervals + b) + 1] = s,
// for the value v and slope s of kMissing, computed in float64 and rounded once,
// and kInterceptRows[model][j]: whether a row blended between rows j and j + 1
// may be read from them. A lookup fma(μ, s, v0) errs by the roundings of v0
// and s, 2^-24 (|v0| + μ |s|), not 2^-24 |1 - E|, which is small where the
// line cancels: rows j and j + 1 qualify if on every interval of both
// |v0| + μ_b+1 |s| is within kMaxCancellation of the line's smaller end value
// (both positive). Any blend of two such rows is then within it too (each of
// its terms is a mean of the rows' with the same weights), and a lookup of
// one, from v0 and s rounded once more, is within (2 kMaxCancellation + 1)
// 2^-24 = 2e-6 of the float64 line with an FMA, (3 kMaxCancellation + 1)
// 2^-24 = 3e-6 without (SSE2, whose product rounds too).
#pragma once

#include "principled_brdf/energy_tables.hpp"

namespace principled_brdf::energy {

inline constexpr double kMaxCancellation = 16.0;

extern const float* const kMissingIntercepts[2];
extern const bool* const kInterceptRows[2];

}  // namespace principled_brdf::energy
