// The batch layer: splits a call into per-thread chunks and hands each to the
// chosen kernel. Chunk boundaries do not change any result: every element goes
// through the same lane-wise code, whichever chunk or tail it falls in.
#include "principled_brdf/batch.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

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

// Read once: the C library counts the CPUs from /sys on each call, which costs
// more than evaluating a small call.
int hardware_threads() {
    static const int count = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    return count;
}

std::vector<std::string> available_isas() {
    std::vector<std::string> names;
    for (const kernel::KernelTable* table : kernel::available()) names.emplace_back(table->isa);
    return names;
}

std::string active_isa() { return kernel::active().isa; }

int float_lanes(const std::string& isa) { return kernel::by_name(isa, "isa").float_lanes; }

// Runs range(begin, end) over per-thread chunks; the first bad element any returned, or -1.
template <class Range>
std::int64_t run_chunks(std::int64_t n, int threads, const Range& range) {
    const int thread_count = resolve_threads(threads);
    const Chunks chunks = split(n, thread_count);
    std::vector<std::int64_t> bad(chunks.count, -1);
    parallel_for(chunks.count, thread_count, [&](int c) {
        const std::int64_t begin = c * chunks.size;
        bad[c] = range(begin, std::min(n, begin + chunks.size));
    });
    for (std::int64_t b : bad)
        if (b >= 0) return b;
    return -1;
}

const kernel::KernelTable& kernels_for(const std::string& isa) {
    return isa.empty() ? kernel::active() : kernel::by_name(isa, "isa");
}

std::int64_t eval(const EvalJob& job, std::int64_t n, int threads, const std::string& isa) {
    const kernel::KernelTable& kernels = kernels_for(isa);
    EvalJob streamed = job;
    streamed.out[0].streaming = job.output == Output::kTotal && job.out[0].layout == Vec3Layout::kInterleaved && streaming_output(n);
    return run_chunks(n, threads, [&](std::int64_t begin, std::int64_t end) { return kernels.eval_range(streamed, begin, end); });
}

void normal_equations(const NormalEquationsJob& job, std::int64_t count, int threads, const std::string& isa) {
    const kernel::KernelTable& kernels = kernels_for(isa);
    // tasks of a few problems (their sums do not depend on the split)
    const std::int64_t per_task = std::max<std::int64_t>(1, std::min<std::int64_t>(64, kMinElementsPerThread / std::max<std::int64_t>(1, job.pairs)));
    const std::int64_t tasks = (count + per_task - 1) / per_task;
    if (tasks == 0) return;
    parallel_for(static_cast<int>(tasks), resolve_threads(threads), [&](int t) {
        const std::int64_t begin = t * per_task;
        kernels.normal_equations_range(job, begin, std::min(count, begin + per_task));
    });
}

std::int64_t sample(const SampleJob& job, std::int64_t n, int threads, const std::string& isa) {
    const kernel::KernelTable& kernels = kernels_for(isa);
    return run_chunks(n, threads, [&](std::int64_t begin, std::int64_t end) { return kernels.sample_range(job, begin, end); });
}

namespace rng {
#include "counter_rng.hpp"
}  // namespace rng

void counter_uniforms(std::uint64_t seed, std::int64_t first, std::int64_t n, float* out) {
    const rng::CounterSeed mixed = rng::counter_seed(seed);
    for (std::int64_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) out[3 * i + k] = rng::counter_uniform(static_cast<std::uint64_t>(first) + static_cast<std::uint64_t>(i), mixed, k);
}

void add_pairs(const float* wi, const float* wo, float* out, std::int64_t n, int threads, bool streaming) {
    const int thread_count = resolve_threads(threads);
    const Chunks chunks = split(n, thread_count);
    parallel_for(chunks.count, thread_count, [&](int c) {
        std::int64_t i = 3 * c * chunks.size;
        const std::int64_t end = 3 * std::min(n, (c + 1) * chunks.size);
#if defined(__SSE2__)
        if (streaming) {
            for (; i < end && reinterpret_cast<std::uintptr_t>(out + i) % 16 != 0; ++i) out[i] = wi[i] + wo[i];
            for (; i + 4 <= end; i += 4) _mm_stream_ps(out + i, _mm_add_ps(_mm_loadu_ps(wi + i), _mm_loadu_ps(wo + i)));
            _mm_sfence();
        }
#endif
        for (; i < end; ++i) out[i] = wi[i] + wo[i];
    });
}

DirectionCheck direction_check(double tolerance) {
    DirectionCheck check;
    check.enabled = true;
    check.length2_lowest = (1.0 - tolerance) * (1.0 - tolerance);
    check.length2_highest = (1.0 + tolerance) * (1.0 + tolerance);
    // The float32 squared length is within 3 float roundings (2e-7 relative)
    // of the float64 one; a margin of 1e-6 keeps the fast test inside the rule.
    constexpr double margin = 1e-6;
    check.fast_lowest = static_cast<float>(check.length2_lowest * (1.0 + margin));
    check.fast_highest = static_cast<float>(check.length2_highest * (1.0 - margin));
    return check;
}

}  // namespace principled_brdf
