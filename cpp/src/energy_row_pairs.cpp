// The row-pair tables of principled_brdf/energy_row_pairs.hpp, filled from the
// generated tables when the library is loaded.
#include "principled_brdf/energy_row_pairs.hpp"

namespace principled_brdf::energy {
namespace {

struct RowPairTables {
    alignas(64) float values[2][(kRoughnesses - 1) * kIntervals * kPairWidth] = {};

    RowPairTables() {
        for (int model = 0; model < 2; ++model)
            for (int j = 0; j + 1 < kRoughnesses; ++j)
                for (int k = 0; k < kIntervals; ++k)
                    for (int h = 0; h < 2; ++h)
                        for (int c = 0; c < kCoefficients; ++c)
                            values[model][kPairWidth * (j * kIntervals + k) + kCoefficients * h + c] =
                                kMissing[model][kCoefficients * ((j + h) * kIntervals + k) + c];
    }
};

const RowPairTables tables;

}  // namespace

const float* const kMissingRowPairs[2] = {tables.values[0], tables.values[1]};

}  // namespace principled_brdf::energy
