// The intercept tables of principled_brdf/energy_intercepts.hpp, derived from
// the generated tables when the library is loaded.
#include "principled_brdf/energy_intercepts.hpp"

#include <cmath>

namespace principled_brdf::energy {
namespace {

// μ at the start of interval b (ν_b less 1/8; energy_tables.hpp), for b <= kIntervals
double cosine_at(int b) {
    return std::ldexp(1.0 + (b % kIntervalsPerOctave) / double(kIntervalsPerOctave), b / kIntervalsPerOctave - 3) - kCosineOffset;
}

struct InterceptTables {
    alignas(64) float values[2][kRoughnesses * kIntervals * 2] = {};

    InterceptTables() {
        for (int model = 0; model < 2; ++model)
            for (int at = 0; at < kRoughnesses * kIntervals; ++at) {
                const double value = kMissing[model][2 * at], slope = kMissing[model][2 * at + 1];
                values[model][2 * at] = static_cast<float>(value - cosine_at(at % kIntervals + 1) * slope);
                values[model][2 * at + 1] = kMissing[model][2 * at + 1];
            }
    }
};

const InterceptTables tables;

}  // namespace

const float* const kMissingIntercepts[2] = {tables.values[0], tables.values[1]};

}  // namespace principled_brdf::energy
