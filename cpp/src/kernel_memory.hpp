// Part of kernel.hpp, included inside the per-arch namespace: loads and stores
// in the three layouts, tails, the direction check.
#pragma once  // (per translation unit)

// Every array of a call in one layout lets the loop be compiled for it;
// Layouts::kMixed reads each array's layout at run time.
enum class Layouts { kInterleaved, kRows, kMixed };

template <Layouts layouts = Layouts::kMixed>
PB_KERNEL_INLINE Vec3<Floats> load_vec3(const Vec3Array& a, std::int64_t i) {
    if constexpr (layouts == Layouts::kInterleaved) {
        Vec3<Floats> v;
        load_interleaved(a.data + 3 * i, v.x, v.y, v.z);
        return v;
    } else if constexpr (layouts == Layouts::kRows) {
        return {Floats::load_unaligned(a.data + i), Floats::load_unaligned(a.data + a.row_stride + i),
                Floats::load_unaligned(a.data + 2 * a.row_stride + i)};
    }
    switch (a.layout) {
        case Vec3Layout::kInterleaved: {
            Vec3<Floats> v;
            load_interleaved(a.data + 3 * i, v.x, v.y, v.z);
            return v;
        }
        case Vec3Layout::kRows:
            return {Floats::load_unaligned(a.data + i), Floats::load_unaligned(a.data + a.row_stride + i),
                    Floats::load_unaligned(a.data + 2 * a.row_stride + i)};
        default:
            return {Floats(a.data[0]), Floats(a.data[1]), Floats(a.data[2])};
    }
}

// (may_stream: for eval's f, the only output the batch layer may ask to stream)
template <Layouts layouts = Layouts::kMixed, bool may_stream = false>
PB_KERNEL_INLINE void store_rgb(const MutableVec3Array& a, std::int64_t i, const Rgb<Floats>& c) {
    if (layouts == Layouts::kInterleaved || (layouts == Layouts::kMixed && a.layout == Vec3Layout::kInterleaved)) {
        if (may_stream && a.streaming) {  // (a.data + 3 i register-aligned: eval_loop)
            stream_interleaved(a.data + 3 * i, c.r, c.g, c.b);
        } else {
            store_interleaved(a.data + 3 * i, c.r, c.g, c.b);
        }
    } else {
        c.r.store_unaligned(a.data + i);
        c.g.store_unaligned(a.data + a.row_stride + i);
        c.b.store_unaligned(a.data + 2 * a.row_stride + i);
    }
}

// f's lobes (or their shares of a sample's weight) in kLobeNames' order, each through `weighted`.
template <Layouts layouts, class Weighted>
PB_KERNEL_INLINE void store_lobes(const MutableVec3Array* out, std::int64_t i, const LobeColors<Floats>& lobes,
                                  const Weighted& weighted) {
    for (int k = 0; k < kLobeCount; ++k) store_rgb<layouts>(out[k], i, weighted(lobes[k]));
}

// One batch at i of a derivative output: with `jacobian`, the Jacobian (a Store)
// written beside f; else the cotangent's products (a Sink) alone.
// `differentiate(target)` runs the forward pass into either and returns f.
template <bool jacobian, class Store, class Sink, Layouts layouts, class Job, class Differentiate>
PB_KERNEL_INLINE void derivative_batch(const Job& job, std::int64_t i, Differentiate&& differentiate) {
    if constexpr (jacobian) {
        Store store{job, i};
        Rgb<Floats> f = differentiate(store);
        store.finish();
        store_rgb<layouts>(job.out[0], i, f);
    } else {
        Sink sink{job, i, load_vec3<layouts>(job.cotangent, i)};
        differentiate(sink);
        sink.finish();
    }
}

// The direction check (DirectionCheck in batch.hpp). The fast test: true only
// for lanes whose length the rule accepts.
PB_KERNEL_INLINE Mask surely_unit_length(const Vec3<Floats>& w, const DirectionCheck& check) {
    Floats length2 = mul_add(w.x, w.x, mul_add(w.y, w.y, w.z * w.z));
    return (length2 >= Floats(check.fast_lowest)) & (length2 <= Floats(check.fast_highest));  // false for NaN
}

// The rule itself for element i of a (scalar, from memory).
inline bool unit_length_at(const Vec3Array& a, std::int64_t i, const DirectionCheck& check) {
    const float* p = a.layout == Vec3Layout::kSingle ? a.data : a.layout == Vec3Layout::kRows ? a.data + i : a.data + 3 * i;
    const std::int64_t stride = a.layout == Vec3Layout::kRows ? a.row_stride : 1;
    return unit_length(p[0], p[stride], p[2 * stride], check);
}

// The loops run with the fast test and stop at the first batch it does not
// accept, returning that batch's start (or -1 when they wrote every element):
// nothing out of line is called inside them, which would make the compiler
// keep their state in memory around the call. This decides such a batch by
// the rule, element by element: the first element the rule rejects is the
// call's answer; if there is none, the batch runs with the check off (the same
// bits, the check changes no value) and the loop resumes after it.
template <class Job, class Loop, class Rejects>
std::int64_t run_checked(const Job& job, std::int64_t begin, std::int64_t end, const Loop& loop, const Rejects& rejects) {
    while (begin < end) {
        const std::int64_t stopped = loop(job, begin, end);
        if (stopped < 0) return -1;
        const std::int64_t batch_end = std::min(stopped + kLanes, end);
        for (std::int64_t i = stopped; i < batch_end; ++i)
            if (rejects(i)) return i;
        Job unchecked = job;
        unchecked.check.enabled = false;
        loop(unchecked, stopped, batch_end);
        begin = batch_end;
    }
    return -1;
}


// ---------------------------------------------------------------- tails
// The last count < kLanes elements of a range are copied into padded buffers
// (the last element repeated), so every load and store stays in bounds and
// every element goes through the same lane-wise code as the others.

struct Padding {
    std::int64_t begin, count;
    std::int64_t source(std::int64_t lane) const { return begin + (lane < count ? lane : count - 1); }
};

using PadBuffer = float[3 * kLanes];

PB_KERNEL_INLINE Vec3Array pad_vec3(const Vec3Array& from, const Padding& pad, float* buffer) {
    if (from.layout == Vec3Layout::kSingle) return from;
    for (std::int64_t j = 0; j < kLanes; ++j) {
        const std::int64_t e = pad.source(j);
        for (int k = 0; k < 3; ++k)
            buffer[3 * j + k] = from.layout == Vec3Layout::kInterleaved ? from.data[3 * e + k]
                                                                        : from.data[k * from.row_stride + e];
    }
    return Vec3Array{buffer, Vec3Layout::kInterleaved, 0};
}

PB_KERNEL_INLINE void pad_params(const ParamSlot* from, ParamSlot* to, const Padding& pad, PadBuffer* buffers) {
    for (int s = 0; s < kParamSlots; ++s) {
        const ParamSlot& slot = from[s];
        if (!slot.per_element()) continue;
        if (slot.stride == 3) {
            // Interleaved base_color: the R slot's copy holds all three channels.
            to[s].data = buffers[kBaseColorR] + (s - kBaseColorR);
            if (s != kBaseColorR) continue;
        } else {
            to[s].data = buffers[s];
        }
        for (std::int64_t j = 0; j < kLanes; ++j)
            for (int c = 0; c < slot.stride; ++c) buffers[s][j * slot.stride + c] = slot.data[pad.source(j) * slot.stride + c];
    }
}

PB_KERNEL_INLINE void unpad_vec3(const MutableVec3Array& to, const Padding& pad, const float* buffer) {
    for (std::int64_t j = 0; j < pad.count; ++j) {
        for (int c = 0; c < 3; ++c) {
            const std::int64_t index = to.layout == Vec3Layout::kInterleaved ? 3 * (pad.begin + j) + c
                                                                             : c * to.row_stride + pad.begin + j;
            to.data[index] = buffer[3 * j + c];
        }
    }
}

template <class T>
PB_KERNEL_INLINE void unpad_scalars(T* to, const Padding& pad, const T* buffer) {
    for (std::int64_t j = 0; j < pad.count; ++j) to[pad.begin + j] = buffer[j];
}
