// The intercept tables of principled_brdf/energy_intercepts.hpp, derived from
// the generated tables when the library is loaded.
#include "principled_brdf/energy_intercepts.hpp"

#include <algorithm>
#include <cmath>

namespace principled_brdf::energy {
namespace {

// μ at the start of interval b (ν_b less 1/8; energy_tables.hpp), for b <= kIntervals
double cosine_at(int b) {
    return std::ldexp(1.0 + (b % kIntervalsPerOctave) / double(kIntervalsPerOctave), b / kIntervalsPerOctave - 3) - kCosineOffset;
}

struct InterceptTables {
    alignas(64) float values[2][kRoughnesses * kIntervals * 2] = {};
    bool rows[2][kRoughnesses] = {};

    InterceptTables() {
        for (int model = 0; model < 2; ++model) {
            bool well_conditioned[kRoughnesses];
            for (int j = 0; j < kRoughnesses; ++j) {
                well_conditioned[j] = true;
                for (int b = 0; b < kIntervals; ++b) {
                    const int at = 2 * (j * kIntervals + b);
                    const double value = kMissing[model][at], slope = kMissing[model][at + 1];
                    const double end = cosine_at(b + 1), start_value = value - (end - cosine_at(b)) * slope;
                    const double intercept = value - end * slope;
                    values[model][at] = static_cast<float>(intercept);
                    values[model][at + 1] = kMissing[model][at + 1];
                    const double smaller = std::min(value, start_value);
                    well_conditioned[j] &= smaller > 0.0 && std::abs(intercept) + end * std::abs(slope) <= kMaxCancellation * smaller;
                }
            }
            for (int j = 0; j + 1 < kRoughnesses; ++j) rows[model][j] = well_conditioned[j] && well_conditioned[j + 1];
        }
    }
};

const InterceptTables tables;

}  // namespace

const float* const kMissingIntercepts[2] = {tables.values[0], tables.values[1]};
const bool* const kInterceptRows[2] = {tables.rows[0], tables.rows[1]};

}  // namespace principled_brdf::energy
