// The 2014 model's table of energy_tables.hpp with each interval's line written from μ = 0:
//   kMissingIntercepts2014[2 (j kIntervals + b)] = v - μ_b+1 s (the line's 1 - E at μ = 0),
//   kMissingIntercepts2014[2 (j kIntervals + b) + 1] = s,
// for the value v and slope s of kMissing, computed in float64 and rounded once.
// A lookup fma(μ, s, v0) errs by the roundings of v0 and s, 2^-24 (|v0| +
// μ |s|), not 2^-24 |1 - E|, which is small where the line cancels. A row may
// be read so if on every interval |v0| + μ_b+1 |s| is within 16 times the
// line's smaller end value (both positive), as every row of the 2014 model's
// table is (tests/energy/test_energy_compensation.py), whose uniform materials'
// kernels read them (kernel_material.hpp). A blend of two such rows is then
// within 16 too (each of its terms is a mean of the rows' with the same
// weights), and a lookup of it, from v0 and s rounded once more, within
// (2 · 16 + 1) 2^-24 = 2e-6 of the float64 line with an FMA and (3 · 16 + 1)
// 2^-24 = 3e-6 without (SSE2, whose product rounds too).
#pragma once

#include "principled_brdf/energy_tables.hpp"

namespace principled_brdf::energy {

extern const float* const kMissingIntercepts2014;

}  // namespace principled_brdf::energy
