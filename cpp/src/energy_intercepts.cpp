// The intercept table of principled_brdf/energy_intercepts.hpp, derived from
// the generated table when the library is loaded.
#include "principled_brdf/energy_intercepts.hpp"

#include <cmath>

#include "principled_brdf/model_table.hpp"

namespace principled_brdf::energy {
namespace {

// μ at the start of interval b (ν_b less 1/8; energy_tables.hpp), for b <= kIntervals
double cosine_at(int b) {
    return std::ldexp(1.0 + (b % kIntervalsPerOctave) / double(kIntervalsPerOctave), b / kIntervalsPerOctave - 3) - kCosineOffset;
}

struct InterceptTable {
    alignas(64) float values[kRoughnesses * kIntervals * 2] = {};

    InterceptTable() {
        const float* missing = kMissing[row_of(Model::kDisney2014).energy_table];
        for (int at = 0; at < kRoughnesses * kIntervals; ++at) {
            const double value = missing[2 * at], slope = missing[2 * at + 1];
            values[2 * at] = static_cast<float>(value - cosine_at(at % kIntervals + 1) * slope);
            values[2 * at + 1] = missing[2 * at + 1];
        }
    }
};

const InterceptTable table;

}  // namespace

const float* const kMissingIntercepts2014 = table.values;

}  // namespace principled_brdf::energy
