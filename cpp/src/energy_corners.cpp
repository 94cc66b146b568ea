// The corner tables of principled_brdf/energy_corners.hpp, filled from the
// generated tables when the library is loaded.
#include "principled_brdf/energy_corners.hpp"

namespace principled_brdf::energy {
namespace {

struct CornerTables {
    alignas(64) float values[2][kRoughnesses * kIntervals * kCorners] = {};

    CornerTables() {
        for (int table = 0; table < 2; ++table)
            for (int at = 0; at < (kRoughnesses - 1) * kIntervals; ++at)
                for (int c = 0; c < kCorners; ++c)
                    values[table][kCorners * at + c] = kMissing[table][2 * at + (c & 1) + (c >> 1) * 2 * kIntervals];
    }
};

const CornerTables tables;

}  // namespace

const float* const kMissingCorners[2] = {tables.values[0], tables.values[1]};

}  // namespace principled_brdf::energy
