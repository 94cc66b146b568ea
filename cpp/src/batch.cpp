// The batch layer: splits a call into per-thread chunks and hands each to the
// chosen kernel. Chunk boundaries do not change any result: every element goes
// through the same lane-wise code, whichever chunk or tail it falls in.
#include "principled_brdf/batch.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>

#include "dispatch.hpp"
#include "thread_pool.hpp"

namespace principled_brdf {
namespace {

// Below this many elements per thread, waking threads costs more than it saves.
constexpr std::int64_t kMinElementsPerThread = 16384;
// Chunks are multiples of this (a multiple of every SIMD width).
constexpr std::int64_t kChunkGranule = 64;

struct Chunks {
    std::int64_t size;
    int count;
};

Chunks split(std::int64_t n, int threads) {
    const std::int64_t wanted = std::max<std::int64_t>(1, std::min<std::int64_t>(threads, n / kMinElementsPerThread));
    std::int64_t size = (n + wanted - 1) / wanted;
    size = std::max<std::int64_t>(kChunkGranule, (size + kChunkGranule - 1) / kChunkGranule * kChunkGranule);
    return {size, static_cast<int>((n + size - 1) / size)};
}

int resolve_threads(int threads) { return threads > 0 ? threads : hardware_threads(); }

}  // namespace

int hardware_threads() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }

std::vector<std::string> available_isas() {
    std::vector<std::string> names;
    for (const kernel::KernelTable* table : kernel::available()) names.emplace_back(table->isa);
    return names;
}

std::string active_isa() { return kernel::active().isa; }

int float_lanes(const std::string& isa) { return kernel::by_name(isa, "isa").float_lanes; }

void eval(const EvalJob& job, std::int64_t n, int threads, const std::string& isa) {
    const kernel::KernelTable& kernels = isa.empty() ? kernel::active() : kernel::by_name(isa, "isa");
    const int thread_count = resolve_threads(threads);
    const Chunks chunks = split(n, thread_count);
    parallel_for(chunks.count, thread_count, [&](int c) {
        const std::int64_t begin = c * chunks.size;
        kernels.eval_range(job, begin, std::min(n, begin + chunks.size));
    });
}

std::int64_t first_bad_direction(const Vec3Array& directions, std::int64_t n, float tolerance, int threads) {
    // |w| within [1 - tol, 1 + tol]  <=>  |w|² within [(1 - tol)², (1 + tol)²]; NaN fails both.
    const float lowest = (1.0f - tolerance) * (1.0f - tolerance);
    const float highest = (1.0f + tolerance) * (1.0f + tolerance);
    const std::int64_t count = directions.layout == Vec3Layout::kSingle ? std::min<std::int64_t>(n, 1) : n;
    const std::int64_t stride = directions.layout == Vec3Layout::kRows ? directions.row_stride : 1;
    const std::int64_t step = directions.layout == Vec3Layout::kRows ? 1 : 3;
    const float* data = directions.data;

    const int thread_count = resolve_threads(threads);
    const Chunks chunks = split(count, thread_count);
    std::vector<std::int64_t> first_bad(chunks.count, -1);
    parallel_for(chunks.count, thread_count, [&](int c) {
        const std::int64_t begin = c * chunks.size, end = std::min(count, begin + chunks.size);
        for (std::int64_t i = begin; i < end; ++i) {
            const float* p = data + i * step;
            const float x = p[0], y = p[stride], z = p[2 * stride];
            const float length2 = x * x + y * y + z * z;
            if (!(length2 >= lowest && length2 <= highest)) {
                first_bad[c] = i;
                return;
            }
        }
    });
    for (std::int64_t bad : first_bad)
        if (bad >= 0) return bad;
    return -1;
}

}  // namespace principled_brdf
