// The corner tables of principled_brdf/energy_corners.hpp, filled from the
// generated tables when the library is loaded.
#include "principled_brdf/energy_corners.hpp"

namespace principled_brdf::energy {
namespace {

struct CornerTables {
    alignas(64) float values[2][kRoughnesses * kCosines * kCorners] = {};

    CornerTables() {
        for (int model = 0; model < 2; ++model)
            for (int j = 0; j + 1 < kRoughnesses; ++j)
                for (int k = 0; k + 1 < kCosines; ++k) {
                    const int at = j * kCosines + k;
                    for (int c = 0; c < kCorners; ++c)
                        values[model][kCorners * at + c] = kMissing[model][at + (c & 1) + (c >> 1) * kCosines];
                }
    }
};

const CornerTables tables;

}  // namespace

const float* const kMissingCorners[2] = {tables.values[0], tables.values[1]};

}  // namespace principled_brdf::energy
