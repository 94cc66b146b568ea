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

// ---------------------------------------------------------------- segments
namespace {

std::int64_t segment_offset(const Segments& segments, int input, std::int64_t s) {
    return segments.offsets[input] != nullptr ? segments.offsets[input][s] : 0;
}

template <class Job>
void advance_params(const Job& job, Job& part, const Segments& segments, std::int64_t s) {
    part.per_element_material = !job.uniform_material();
    for (int slot = 0; slot < kParamSlots; ++slot) {
        const ParamSlot& from = job.params[slot];
        if (!from.per_element()) continue;
        const float* data = from.data + segment_offset(segments, kSegmentSlots + slot, s);
        part.params[slot] = segments.single[slot] ? ParamSlot{*data, nullptr, 1} : ParamSlot{0.0f, data, from.stride};
    }
}

void advance_output(MutableVec3Array& out, std::int64_t first) {
    if (out.data != nullptr) out.data += out.layout == Vec3Layout::kRows ? first : 3 * first;
}

void advance_input(Vec3Array& in, const Segments& segments, int input, std::int64_t s) {
    if (in.data != nullptr) in.data += segment_offset(segments, input, s);
}

EvalJob segment_job(const EvalJob& job, const Segments& segments, std::int64_t s) {
    EvalJob part = job;
    const std::int64_t first = s * segments.length;
    advance_input(part.wi, segments, kSegmentWi, s);
    advance_input(part.wo, segments, kSegmentWo, s);
    if (job.output == Output::kVjp || job.output == Output::kDirectionVjp)
        advance_input(part.cotangent, segments, kSegmentThird, s);
    advance_params(job, part, segments, s);
    for (MutableVec3Array& out : part.out) advance_output(out, first);
    if (part.pdf != nullptr) part.pdf += first;
    if (part.jacobian != nullptr) {
        part.jacobian += job.jacobian_row_stride > 0 ? first : job.jacobian_width() * first;
    }
    return part;
}

SampleJob segment_job(const SampleJob& job, const Segments& segments, std::int64_t s) {
    SampleJob part = job;
    const std::int64_t first = s * segments.length;
    advance_input(part.wo, segments, kSegmentWo, s);
    advance_input(part.u, segments, kSegmentThird, s);
    advance_params(job, part, segments, s);
    advance_output(part.wi, first);
    advance_output(part.weight, first);
    for (MutableVec3Array& out : part.lobe_weight) advance_output(out, first);
    part.pdf += first;
    part.lobe += first;
    part.first_index = job.first_index + first;  // the generator sees the call's element indices
    return part;
}

// range(job, begin, end) over the call's elements in per-thread chunks, each
// chunk's elements segment by segment; the first bad element (the call's index), or -1.
template <class Job, class Range>
std::int64_t run_segments(const Job& job, const Segments& segments, int threads, const Range& range) {
    const std::int64_t length = segments.length;
    return run_chunks(segments.count * length, threads, [&](std::int64_t begin, std::int64_t end) -> std::int64_t {
        for (std::int64_t s = begin / length; s * length < end; ++s) {
            const std::int64_t first = s * length;
            const std::int64_t bad = range(segment_job(job, segments, s), std::max(begin, first) - first,
                                           std::min(end, first + length) - first);
            if (bad >= 0) return first + bad;
        }
        return -1;
    });
}

}  // namespace

std::int64_t eval(const EvalJob& job, const Segments& segments, int threads, const std::string& isa) {
    if (segments.count <= 1) return eval(segments.count == 1 ? segment_job(job, segments, 0) : job, segments.count * segments.length, threads, isa);
    const kernel::KernelTable& kernels = kernels_for(isa);
    EvalJob streamed = job;
    streamed.out[0].streaming = job.output == Output::kTotal && job.out[0].layout == Vec3Layout::kInterleaved &&
                                streaming_output(segments.count * segments.length);
    return run_segments(streamed, segments, threads, [&](const EvalJob& part, std::int64_t begin, std::int64_t end) {
        return kernels.eval_range(part, begin, end);
    });
}

std::int64_t sample(const SampleJob& job, const Segments& segments, int threads, const std::string& isa) {
    if (segments.count <= 1) return sample(segments.count == 1 ? segment_job(job, segments, 0) : job, segments.count * segments.length, threads, isa);
    const kernel::KernelTable& kernels = kernels_for(isa);
    return run_segments(job, segments, threads, [&](const SampleJob& part, std::int64_t begin, std::int64_t end) {
        return kernels.sample_range(part, begin, end);
    });
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
