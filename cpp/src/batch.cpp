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

void set_direction_check(EvalJob& job, float tolerance) {
    // |w| within [1 - tol, 1 + tol]  <=>  |w|² within [(1 - tol)², (1 + tol)²]
    job.check_directions = true;
    job.length2_lowest = (1.0f - tolerance) * (1.0f - tolerance);
    job.length2_highest = (1.0f + tolerance) * (1.0f + tolerance);
}

std::int64_t eval(const EvalJob& job, std::int64_t n, int threads, const std::string& isa) {
    const kernel::KernelTable& kernels = isa.empty() ? kernel::active() : kernel::by_name(isa, "isa");
    const int thread_count = resolve_threads(threads);
    const Chunks chunks = split(n, thread_count);
    std::vector<std::int64_t> bad(chunks.count, -1);
    parallel_for(chunks.count, thread_count, [&](int c) {
        const std::int64_t begin = c * chunks.size;
        bad[c] = kernels.eval_range(job, begin, std::min(n, begin + chunks.size));
    });
    for (std::int64_t b : bad)
        if (b >= 0) return b;
    return -1;
}

void add_pairs(const float* wi, const float* wo, float* out, std::int64_t n, int threads) {
    const int thread_count = resolve_threads(threads);
    const Chunks chunks = split(n, thread_count);
    parallel_for(chunks.count, thread_count, [&](int c) {
        const std::int64_t begin = 3 * c * chunks.size, end = 3 * std::min(n, (c + 1) * chunks.size);
        for (std::int64_t i = begin; i < end; ++i) out[i] = wi[i] + wo[i];
    });
}

std::int64_t first_bad_direction(const Vec3Array& directions, std::int64_t n, float tolerance, int threads) {
    EvalJob bounds;
    set_direction_check(bounds, tolerance);
    const float lowest = bounds.length2_lowest, highest = bounds.length2_highest;
    const kernel::KernelTable& kernels = kernel::active();
    if (directions.layout == Vec3Layout::kSingle) {
        const float* w = directions.data;
        const float length2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
        return n > 0 && !(length2 >= lowest && length2 <= highest) ? 0 : -1;
    }
    const int thread_count = resolve_threads(threads);
    const Chunks chunks = split(n, thread_count);
    std::vector<std::int64_t> first_bad(chunks.count, -1);
    parallel_for(chunks.count, thread_count, [&](int c) {
        const std::int64_t begin = c * chunks.size;
        first_bad[c] = kernels.first_bad_direction(directions, begin, std::min(n, begin + chunks.size), lowest, highest);
    });
    for (std::int64_t bad : first_bad)
        if (bad >= 0) return bad;
    return -1;
}

}  // namespace principled_brdf
