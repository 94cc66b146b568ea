// Per-instruction-set building blocks of the kernel: reciprocal, square root,
// a reciprocal square root (AVX-512: rsqrt14 refined to float precision), and the (N, 3)
// interleaved <-> structure-of-arrays transposes done in registers.
//
// Included by kernel.hpp inside the per-arch namespace, after `Floats` is
// defined; the intrinsic paths are chosen by the flags of the including file.
#pragma once  // (per translation unit: each kernel_<isa>.cpp includes it once)

// An element's three components sit at flat indices 3 j + k of the interleaved
// array. For a register of L lanes (L = 8 or 16, both coprime with 3), lane l
// of the r-th register of a group of three holds flat index L r + l. Loading:
// blend the three registers so that lane l takes register r with
// (L r + l) % 3 == k, then permute lane l's element j = (L r + l) / 3 to lane j.
// Storing inverts both steps.
template <int L>
struct Interleave3 {
    static constexpr int source_register(int k, int lane) {
        for (int r = 0; r < 3; ++r)
            if ((L * r + lane) % 3 == k) return r;
        return -1;
    }
    // lane that holds element j of component k after the blend
    static constexpr int lane_of_element(int k, int j) {
        for (int lane = 0; lane < L; ++lane)
            if ((L * source_register(k, lane) + lane) / 3 == j) return lane;
        return -1;
    }
    // element of component k that lands in `lane` when writing register r
    static constexpr int element_at_lane(int k, int lane) {
        for (int j = 0; j < L; ++j)
            if ((3 * j + k) % L == lane) return j;
        return -1;
    }
};

// The permutations as compile-time tables (loaded once, hoisted out of loops).
template <int L, int k, bool for_store>
struct Interleave3Permutation {
    alignas(64) int lanes[L];
    constexpr Interleave3Permutation() : lanes{} {
        for (int i = 0; i < L; ++i)
            lanes[i] = for_store ? Interleave3<L>::element_at_lane(k, i) : Interleave3<L>::lane_of_element(k, i);
    }
};

template <int L, int k, bool for_store>
inline constexpr Interleave3Permutation<L, k, for_store> kInterleave3Permutation{};

// Fused multiply-adds: a b + c, a b - c and c - a b, one rounding where the
// instruction set has them (two on SSE2). The kernels build with
// -ffp-contract=off, so every rounding is one the code asks for and an
// element's bits do not depend on the code around its batch: with contraction
// the compiler may fuse a product in straight-line code but not the same
// product hoisted out of a loop, and the pipelined loop's results would change
// with the call's start, length and thread chunks. xsimd 8.1 has no AVX-512 fma of its
// own (it writes x * y + z).
#if defined(__AVX512F__)
PB_KERNEL_INLINE Floats mul_add(Floats a, Floats b, Floats c) { return _mm512_fmadd_ps(a, b, c); }
PB_KERNEL_INLINE Floats mul_sub(Floats a, Floats b, Floats c) { return _mm512_fmsub_ps(a, b, c); }
PB_KERNEL_INLINE Floats neg_mul_add(Floats a, Floats b, Floats c) { return _mm512_fnmadd_ps(a, b, c); }
#else
PB_KERNEL_INLINE Floats mul_add(Floats a, Floats b, Floats c) { return xsimd::fma(a, b, c); }
PB_KERNEL_INLINE Floats mul_sub(Floats a, Floats b, Floats c) { return xsimd::fms(a, b, c); }
PB_KERNEL_INLINE Floats neg_mul_add(Floats a, Floats b, Floats c) { return xsimd::fnma(a, b, c); }
#endif

// Reciprocals and square roots are exact (divps, sqrtps) on every instruction
// set. The kernels are bound by the multiply and FMA pipes; the divide and
// square-root unit works beside them, so an exact 1/x or sqrt(x) is cheaper
// there than an rcp or rsqrt estimate refined by a Newton step, which takes 3
// or 4 of the pipes' slots. No kernel uses rcpps or rsqrtps: their estimates
// are implementation-defined (Intel and AMD return different bits), and a
// result refined from them would differ by vendor.
PB_KERNEL_INLINE Floats reciprocal(Floats x) { return Floats(1.0f) / x; }
// sqrt(x), 0 for x <= 0 (and for NaN on x86, where max returns its second operand)
PB_KERNEL_INLINE Floats square_root(Floats x) { return xsimd::sqrt(xsimd::max(x, Floats(0.0f))); }
// sqrt(x) for x >= 0 by construction (a sum of squares): no clamp
PB_KERNEL_INLINE Floats square_root_nonnegative(Floats x) { return xsimd::sqrt(x); }
#if !defined(__AVX512F__)
PB_KERNEL_INLINE Floats reciprocal_sqrt(Floats x) { return Floats(1.0f) / xsimd::sqrt(x); }
#endif

#if defined(__AVX512F__)

// rsqrt14's estimate is specified bit for bit (the same on every vendor's AVX-512),
// so the refined result is too.
PB_KERNEL_INLINE Floats reciprocal_sqrt(Floats x) {
    const __m512 estimate = _mm512_rsqrt14_ps(x);  // relative error < 2^-14
    // One Newton-Raphson step: y + (y / 2) (1 - x y²)
    const __m512 residual = _mm512_fnmadd_ps(_mm512_mul_ps(x, estimate), estimate, _mm512_set1_ps(1.0f));
    return _mm512_fmadd_ps(_mm512_mul_ps(_mm512_set1_ps(0.5f), estimate), residual, estimate);
}

// Two-source permutes (vpermt2ps): a component of 16 elements comes from the
// three registers in two steps: first from (a, b), then the rest from c.
template <int step, int k, bool for_store>
struct Permute2Table {
    alignas(64) int lanes[16];
    constexpr Permute2Table() : lanes{} {
        for (int i = 0; i < 16; ++i) {
            if (!for_store) {
                const int flat = 3 * i + k;  // element i of component k
                lanes[i] = step == 0 ? (flat < 32 ? flat : 0) : (flat < 32 ? i : 16 + flat - 32);
            } else {
                const int flat = 16 * k + i;  // lane i of output register k
                const int component = flat % 3, element = flat / 3;
                lanes[i] = step == 0 ? (component == 0 ? element : component == 1 ? 16 + element : 0)
                                     : (component == 2 ? 16 + element : i);
            }
        }
    }
};

template <int step, int k, bool for_store>
inline constexpr Permute2Table<step, k, for_store> kPermute2{};

template <int step, int k, bool for_store>
PB_KERNEL_INLINE __m512i permute2_indices() {
    return _mm512_load_si512(kPermute2<step, k, for_store>.lanes);
}

template <int k>
PB_KERNEL_INLINE Floats gather_component(__m512 a, __m512 b, __m512 c) {
    const __m512 from_ab = _mm512_permutex2var_ps(a, permute2_indices<0, k, false>(), b);
    return _mm512_permutex2var_ps(from_ab, permute2_indices<1, k, false>(), c);
}

PB_KERNEL_INLINE void load_interleaved(const float* p, Floats& x, Floats& y, Floats& z) {
    const __m512 a = _mm512_loadu_ps(p), b = _mm512_loadu_ps(p + 16), c = _mm512_loadu_ps(p + 32);
    x = gather_component<0>(a, b, c);
    y = gather_component<1>(a, b, c);
    z = gather_component<2>(a, b, c);
}

template <int r>
PB_KERNEL_INLINE __m512 scatter_register(__m512 x, __m512 y, __m512 z) {
    const __m512 from_xy = _mm512_permutex2var_ps(x, permute2_indices<0, r, true>(), y);
    return _mm512_permutex2var_ps(from_xy, permute2_indices<1, r, true>(), z);
}

PB_KERNEL_INLINE void store_interleaved(float* p, Floats x, Floats y, Floats z) {
    _mm512_storeu_ps(p, scatter_register<0>(x, y, z));
    _mm512_storeu_ps(p + 16, scatter_register<1>(x, y, z));
    _mm512_storeu_ps(p + 32, scatter_register<2>(x, y, z));
}

// store_interleaved by non-temporal stores, p aligned to a register (64 bytes)
PB_KERNEL_INLINE void stream_interleaved(float* p, Floats x, Floats y, Floats z) {
    _mm512_stream_ps(p, scatter_register<0>(x, y, z));
    _mm512_stream_ps(p + 16, scatter_register<1>(x, y, z));
    _mm512_stream_ps(p + 32, scatter_register<2>(x, y, z));
}

#elif defined(__AVX2__)

template <int k>
PB_KERNEL_INLINE __m256i interleave_load_permutation() {
    return _mm256_load_si256(reinterpret_cast<const __m256i*>(kInterleave3Permutation<8, k, false>.lanes));
}

template <int k>
PB_KERNEL_INLINE __m256i interleave_store_permutation() {
    return _mm256_load_si256(reinterpret_cast<const __m256i*>(kInterleave3Permutation<8, k, true>.lanes));
}

template <int k, int r>
constexpr int lanes_from_register() {
    int mask = 0;
    for (int lane = 0; lane < 8; ++lane)
        if (Interleave3<8>::source_register(k, lane) == r) mask |= 1 << lane;
    return mask;
}

template <int k>
PB_KERNEL_INLINE Floats gather_component(__m256 a, __m256 b, __m256 c) {
    __m256 blended = _mm256_blend_ps(a, b, lanes_from_register<k, 1>());
    blended = _mm256_blend_ps(blended, c, lanes_from_register<k, 2>());
    return _mm256_permutevar8x32_ps(blended, interleave_load_permutation<k>());
}

PB_KERNEL_INLINE void load_interleaved(const float* p, Floats& x, Floats& y, Floats& z) {
    const __m256 a = _mm256_loadu_ps(p), b = _mm256_loadu_ps(p + 8), c = _mm256_loadu_ps(p + 16);
    x = gather_component<0>(a, b, c);
    y = gather_component<1>(a, b, c);
    z = gather_component<2>(a, b, c);
}

template <int r, int k>
constexpr int lanes_of_component() {
    int mask = 0;
    for (int lane = 0; lane < 8; ++lane)
        if ((8 * r + lane) % 3 == k) mask |= 1 << lane;
    return mask;
}

template <int r>
PB_KERNEL_INLINE __m256 scatter_register(__m256 px, __m256 py, __m256 pz) {
    return _mm256_blend_ps(_mm256_blend_ps(px, py, lanes_of_component<r, 1>()), pz, lanes_of_component<r, 2>());
}

// The three registers of 8 interleaved elements (x0 y0 z0 x1 ...), in memory order
PB_KERNEL_INLINE std::array<__m256, 3> interleaved_registers(Floats x, Floats y, Floats z) {
    const __m256 px = _mm256_permutevar8x32_ps(x, interleave_store_permutation<0>());
    const __m256 py = _mm256_permutevar8x32_ps(y, interleave_store_permutation<1>());
    const __m256 pz = _mm256_permutevar8x32_ps(z, interleave_store_permutation<2>());
    return {scatter_register<0>(px, py, pz), scatter_register<1>(px, py, pz), scatter_register<2>(px, py, pz)};
}

PB_KERNEL_INLINE void store_interleaved(float* p, Floats x, Floats y, Floats z) {
    std::array<__m256, 3> registers = interleaved_registers(x, y, z);
    for (int r = 0; r < 3; ++r) _mm256_storeu_ps(p + 8 * r, registers[r]);
}

// store_interleaved by non-temporal stores, p aligned to a register (32 bytes)
PB_KERNEL_INLINE void stream_interleaved(float* p, Floats x, Floats y, Floats z) {
    std::array<__m256, 3> registers = interleaved_registers(x, y, z);
    for (int r = 0; r < 3; ++r) _mm256_stream_ps(p + 8 * r, registers[r]);
}

#else  // SSE2, NEON: exact division and square root, transposes through memory

PB_KERNEL_INLINE void load_interleaved(const float* p, Floats& x, Floats& y, Floats& z) {
    alignas(64) float xs[Floats::size], ys[Floats::size], zs[Floats::size];
    for (std::size_t j = 0; j < Floats::size; ++j) {
        xs[j] = p[3 * j];
        ys[j] = p[3 * j + 1];
        zs[j] = p[3 * j + 2];
    }
    x = Floats::load_aligned(xs);
    y = Floats::load_aligned(ys);
    z = Floats::load_aligned(zs);
}

PB_KERNEL_INLINE void store_interleaved(float* p, Floats x, Floats y, Floats z) {
    alignas(64) float xs[Floats::size], ys[Floats::size], zs[Floats::size];
    x.store_aligned(xs);
    y.store_aligned(ys);
    z.store_aligned(zs);
    for (std::size_t j = 0; j < Floats::size; ++j) {
        p[3 * j] = xs[j];
        p[3 * j + 1] = ys[j];
        p[3 * j + 2] = zs[j];
    }
}

// (no non-temporal stores here: the ordinary ones, at any address)
PB_KERNEL_INLINE void stream_interleaved(float* p, Floats x, Floats y, Floats z) { store_interleaved(p, x, y, z); }

#endif

// Non-temporal stores made visible to other threads before a loop returns.
PB_KERNEL_INLINE void streaming_fence() {
#if defined(__SSE2__)
    _mm_sfence();
#endif
}

// ---------------------------------------------------------------- rows to elements
// out[width * lane + r] = rows[r][lane] for r < width and every lane: a batch's
// rows (its Jacobian) written element after element. `rows` holds
// padded_rows(width) aligned rows; the padding rows are read, never written out.
//
// The blocks of a register transpose are stored whole, the last, partial one
// first: its full-width store for an element runs into the start of the next
// element, which block 0 writes afterwards. Only the batch's last element
// stores its partial block in pieces (a masked store costs a dozen cycles on
// some cores, and there would be one per element).
#if defined(__AVX2__)
// 8 x 8 blocks in registers; AVX-512's 16 lanes as two groups of 8 (both halves
// of a row are aligned loads)
inline constexpr int kTransposeBlock = 8;

// The 8 x 8 block of rows b to b + 7, lanes group to group + 7, as columns:
// column[lane] holds those rows of element group + lane.
PB_KERNEL_INLINE void transpose_block(const float (*rows)[kLanes], int b, int group, __m256 (&column)[8]) {
    __m256 r[8], t[8], u[8];
    for (int k = 0; k < 8; ++k) r[k] = _mm256_load_ps(rows[b + k] + group);
    for (int k = 0; k < 8; k += 2) {
        t[k] = _mm256_unpacklo_ps(r[k], r[k + 1]);
        t[k + 1] = _mm256_unpackhi_ps(r[k], r[k + 1]);
    }
    for (int k = 0; k < 8; k += 4) {
        u[k] = _mm256_shuffle_ps(t[k], t[k + 2], 0x44);
        u[k + 1] = _mm256_shuffle_ps(t[k], t[k + 2], 0xEE);
        u[k + 2] = _mm256_shuffle_ps(t[k + 1], t[k + 3], 0x44);
        u[k + 3] = _mm256_shuffle_ps(t[k + 1], t[k + 3], 0xEE);
    }
    // element `lane`: low halves of u[0..3] for lanes 0-3, high halves for 4-7
    for (int lane = 0; lane < 4; ++lane) {
        column[lane] = _mm256_permute2f128_ps(u[lane], u[lane + 4], 0x20);
        column[lane + 4] = _mm256_permute2f128_ps(u[lane], u[lane + 4], 0x31);
    }
}

// The first `count` (< 8) floats of x at p.
PB_KERNEL_INLINE void store_first(float* p, __m256 x, int count) {
    __m128 part = _mm256_castps256_ps128(x);
    if (count >= 4) {
        _mm_storeu_ps(p, part);
        part = _mm256_extractf128_ps(x, 1);
        p += 4;
        count -= 4;
    }
    if (count >= 2) {
        _mm_storel_pi(reinterpret_cast<__m64*>(p), part);
        part = _mm_movehl_ps(part, part);
        p += 2;
        count -= 2;
    }
    if (count == 1) _mm_store_ss(p, part);
}

template <int width>
PB_KERNEL_INLINE void store_rows_by_element(const float (*rows)[kLanes], float* out) {
    static_assert(width >= 8, "the partial block's overrun must land in a block written after it");
    constexpr int full_blocks = width / 8, partial = width % 8;
    __m256 column[8];
    // a group's last element overruns into the next group's first, which that group writes afterwards
    for (int group = 0; group < kLanes; group += 8) {
        float* const first = out + width * group;
        if constexpr (partial != 0) {
            transpose_block(rows, 8 * full_blocks, group, column);
            for (int lane = 0; lane < 7; ++lane) _mm256_storeu_ps(first + width * lane + 8 * full_blocks, column[lane]);
            if (group + 8 < kLanes) {
                _mm256_storeu_ps(first + width * 7 + 8 * full_blocks, column[7]);
            } else {
                store_first(first + width * 7 + 8 * full_blocks, column[7], partial);
            }
        }
        for (int b = 0; b < 8 * full_blocks; b += 8) {
            transpose_block(rows, b, group, column);
            for (int lane = 0; lane < 8; ++lane) _mm256_storeu_ps(first + width * lane + b, column[lane]);
        }
    }
}
#elif defined(__SSE2__) && !defined(__AVX512F__)
inline constexpr int kTransposeBlock = 4;  // 4 x 4 blocks in registers

template <int width>
PB_KERNEL_INLINE void store_rows_by_element(const float (*rows)[kLanes], float* out) {
    static_assert(width >= 4, "the partial block's overrun must land in a block written after it");
    constexpr int full_blocks = width / 4, partial = width % 4;
    auto transpose_block = [&](int b, __m128(&column)[4]) {
        column[0] = _mm_load_ps(rows[b]);
        column[1] = _mm_load_ps(rows[b + 1]);
        column[2] = _mm_load_ps(rows[b + 2]);
        column[3] = _mm_load_ps(rows[b + 3]);
        _MM_TRANSPOSE4_PS(column[0], column[1], column[2], column[3]);
    };
    __m128 column[4];
    if constexpr (partial != 0) {
        transpose_block(4 * full_blocks, column);
        for (int lane = 0; lane < 3; ++lane) _mm_storeu_ps(out + width * lane + 4 * full_blocks, column[lane]);
        float* last = out + width * 3 + 4 * full_blocks;
        if (partial >= 2) _mm_storel_pi(reinterpret_cast<__m64*>(last), column[3]);
        if (partial != 2) _mm_store_ss(last + partial - 1, _mm_shuffle_ps(column[3], column[3], _MM_SHUFFLE(0, 0, 0, partial - 1)));
    }
    for (int b = 0; b < 4 * full_blocks; b += 4) {
        transpose_block(b, column);
        for (int lane = 0; lane < 4; ++lane) _mm_storeu_ps(out + width * lane + b, column[lane]);
    }
}
#else
inline constexpr int kTransposeBlock = 1;

template <int width>
PB_KERNEL_INLINE void store_rows_by_element(const float (*rows)[kLanes], float* out) {
    for (std::int64_t lane = 0; lane < kLanes; ++lane)
        for (int r = 0; r < width; ++r) out[width * lane + r] = rows[r][lane];
}
#endif

constexpr int padded_rows(int width) { return (width + kTransposeBlock - 1) / kTransposeBlock * kTransposeBlock; }

// `width` rows of kLanes values as kLanes elements of `width` values each,
// element-major (for widths the transposes above are not compiled for).
PB_KERNEL_INLINE void store_lanes_by_element(const float (*rows)[kLanes], int width, float* out) {
    for (std::int64_t lane = 0; lane < kLanes; ++lane)
        for (int r = 0; r < width; ++r) out[width * lane + r] = rows[r][lane];
}

// ---------------------------------------------------------------- what the model calls
// (docs/model.md: the same names for double are in model/scalar_ops.hpp)

PB_KERNEL_INLINE Floats select(const Mask& m, Floats a, Floats b) { return xsimd::select(m, a, b); }
PB_KERNEL_INLINE Floats min(Floats a, Floats b) { return xsimd::min(a, b); }
PB_KERNEL_INLINE Floats max(Floats a, Floats b) { return xsimd::max(a, b); }
PB_KERNEL_INLINE bool any(const Mask& m) { return xsimd::any(m); }
PB_KERNEL_INLINE bool all(const Mask& m) { return xsimd::all(m); }
// ln 2 in two parts (Cody-Waite): the first has 16 significant bits, so its
// product with an exponent or a rounded multiple is exact
constexpr float kLn2High = 0.693145751953125f, kLn2Low = 1.42860682030941723e-6f;

#if defined(__AVX512F__)
// ln x as e ln 2 + ln m for x = 2^e m, m in [0.75, 1.5), taken exactly by
// getexp and getmant (zeros, subnormals, infinities and NaN included: ln 0 is
// -inf), and ln m = 2 atanh(s) = 2 s (1 + s²/3 + s⁴/5 + s⁶/7 + s⁸/9) with
// s = (m - 1) / (m + 1), |s| <= 0.2 (the series' remainder < 1e-8 relative).
// About 20 instructions, fewer than xsimd's log: the per-element loops take it
// of every batch's clearcoat a².
PB_KERNEL_INLINE Floats log(Floats x) {
    const __m512 m = _mm512_getmant_ps(x, _MM_MANT_NORM_p75_1p5, _MM_MANT_SIGN_nan);
    const __m512 one = _mm512_set1_ps(1.0f);
    // getmant halves a mantissa of 1.5 or more, so that its exponent is getexp's plus one
    const __m512 exponent = _mm512_getexp_ps(x);
    const __m512 e = _mm512_mask_add_ps(exponent, _mm512_cmp_ps_mask(m, one, _CMP_LT_OQ), exponent, one);
    Floats s = Floats(_mm512_sub_ps(m, one)) / Floats(_mm512_add_ps(m, one));
    Floats s2 = s * s;
    Floats series(1.0f / 9.0f);
    for (float coefficient : {1.0f / 7.0f, 1.0f / 5.0f, 1.0f / 3.0f, 1.0f})
        series = mul_add(series, s2, Floats(coefficient));
    Floats log_m = (s + s) * series;
    return mul_add(Floats(e), Floats(kLn2High), mul_add(Floats(e), Floats(kLn2Low), log_m));
}
#else
PB_KERNEL_INLINE Floats log(Floats x) { return xsimd::log(x); }
#endif
PB_KERNEL_INLINE Floats exp(Floats x) { return xsimd::exp(x); }
// table lookups (model/energy.hpp): the integer part of x >= 0 (truncation), back to
// floats, and (table[i], table[i + 1]) per lane, the two nodes of a linear interpolation
PB_KERNEL_INLINE Ints truncate_to_index(Floats x) { return xsimd::to_int(x); }
PB_KERNEL_INLINE Floats index_to_real(Ints i) { return xsimd::to_float(i); }
PB_KERNEL_INLINE Ints min(Ints a, Ints b) { return xsimd::min(a, b); }
// The interval of ν = μ + 1/8 that holds each lane (16 an octave from 1/8,
// the last [9/8, 9/8 + 1/16) for μ = 1, model/energy.hpp) and that interval's
// end: ν's exponent and top four mantissa bits, plus one. Any μ in [0, 1 + 1/16)
// (a unit vector's z, rounded up included) finds its own interval; any other ν
// (μ < 0, where the lobe is discarded) some interval of the table, never an
// index outside it. The interval is that of the exact sum: ν rounded to nearest
// may round up onto the next interval's start, where the two lines meet but
// may have very different slopes; at μ = 1 - 2^-24, which rounds to ν = 9/8,
// the flat last interval would then stand for a line that, at low roughness in
// the 2012 model, falls 2e-3 of 1 - E over that last ulp.
constexpr int kIntervalShift = 23 - 4;
constexpr std::int32_t kFirstIntervalBits = 0x3E000000 >> kIntervalShift;  // 1/8's bits
static_assert(energy::kCosineOffset == 0.125f, "the first interval starts at 1/8");
PB_KERNEL_INLINE Floats interval_end(Ints bits) {
    return xsimd::bitwise_cast<Floats>((bits & Ints(-(1 << kIntervalShift))) + Ints(1 << kIntervalShift));
}
#if defined(__AVX512F__)
// Here the interval comes as ν's bits >> 19, the interval plus 31 · 64: the
// permutes of a row read it modulo 64 (a row's slots past the last interval
// repeat it, kernel_material.hpp), without a subtraction or a clamp;
// gather_corners takes the offset off and clamps. ν is the sum rounded toward
// zero (the instruction's own rounding mode), so never past the exact one.
static_assert(kFirstIntervalBits % 64 == 0, "1/8's bits >> 19 are 0 modulo 64");
PB_KERNEL_INLINE std::pair<Ints, Floats> energy_interval(Floats mu) {
    const __m512 nu = _mm512_add_round_ps(mu, Floats(energy::kCosineOffset), _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC);
    Ints bits = xsimd::bitwise_cast<Ints>(Floats(nu));
    return {bits >> kIntervalShift, interval_end(bits)};
}
#else
// ν = μ + (1/8 - 2^-27), the float below 1/8, rounded to nearest, lies in
// the interval of the exact μ + 1/8 for every μ >= 0: the shift puts each sum
// of a μ inside an interval strictly between the rounding midpoints about the
// interval's ends (2^-27 is half the spacing of floats in [1/8, 1/4) and no
// more than a μ >= 1/8 moves by its last bit, while a sum's spacing is at most
// twice its μ's), and a μ at a boundary at most into the interval before, whose
// line meets the next one there. Then ν is clamped to [1/8, 9/8], where μ = 1
// starts its interval, a NaN to 1/8: x86's max returns its second operand for
// a NaN, NEON's the NaN.
constexpr float kBelowCosineOffset = 0.125f - 0x1p-27f;
PB_KERNEL_INLINE std::pair<Ints, Floats> energy_interval(Floats mu) {
    Floats offset(energy::kCosineOffset);
    Floats nu = mu + Floats(kBelowCosineOffset);
#if defined(__ARM_NEON)
    Floats at_least_first = select(nu > offset, nu, offset);
#else
    Floats at_least_first = max(nu, offset);
#endif
    Ints bits = xsimd::bitwise_cast<Ints>(min(at_least_first, offset + Floats(1.0f)));
    return {(bits >> kIntervalShift) - Ints(kFirstIntervalBits), interval_end(bits)};
}
#endif
#if defined(__AVX2__)
// Non-negative 32-bit lane indices as integers for scalar loads' addresses, two
// lanes at a time out of the register (vmovq, vpextrq) and apart by a shift:
// half the vector-to-integer moves of GCC's way with a stored array, one
// vmovd or vpextrd a lane on the FP pipes these kernels are bound by. (Reading
// the indices back from a stored array instead would make each 4-byte load
// wait on the forwarding of the 64-byte store.)
struct LaneIndices {
    std::uint64_t pairs[kLanes / 2];
    PB_KERNEL_INLINE std::int64_t operator[](int lane) const {
        const std::uint64_t pair = pairs[lane / 2];
        return static_cast<std::int64_t>(lane % 2 ? pair >> 32 : pair & 0xFFFFFFFFu);
    }
};
PB_KERNEL_INLINE void put_pairs(std::uint64_t* pairs, __m128i block) {
    pairs[0] = static_cast<std::uint64_t>(_mm_cvtsi128_si64(block));
    pairs[1] = static_cast<std::uint64_t>(_mm_extract_epi64(block, 1));
}
#if defined(__AVX512F__)
PB_KERNEL_INLINE LaneIndices lane_indices(Ints i) {
    const __m512i v = i;
    LaneIndices lanes;
    put_pairs(lanes.pairs, _mm512_castsi512_si128(v));
    put_pairs(lanes.pairs + 2, _mm512_extracti32x4_epi32(v, 1));
    put_pairs(lanes.pairs + 4, _mm512_extracti32x4_epi32(v, 2));
    put_pairs(lanes.pairs + 6, _mm512_extracti32x4_epi32(v, 3));
    return lanes;
}
#else
PB_KERNEL_INLINE LaneIndices lane_indices(Ints i) {
    const __m256i v = i;
    LaneIndices lanes;
    put_pairs(lanes.pairs, _mm256_castsi256_si128(v));
    put_pairs(lanes.pairs + 2, _mm256_extracti128_si256(v, 1));
    return lanes;
}
#endif
#endif
// (the intrinsics: xsimd 8.1's batch::gather for fma3<avx2> falls back to an out-of-line element loop)
#if defined(__AVX512F__)
// nodes[k] per lane for k in [0, 64): a two-register permute for each half of
// the nodes (index bits 0-4), each written only to the lanes whose k lies in
// its half (mask2: the other lanes keep what they hold, at first the index
// itself), so that no blend is needed. No gather: a row that every lane
// shares fits in four registers.
PB_KERNEL_INLINE __mmask16 upper_half(__m512i k) { return _mm512_test_epi32_mask(k, _mm512_set1_epi32(32)); }

PB_KERNEL_INLINE Floats permute_lookup(const float* nodes, __m512i k, __mmask16 upper) {
    const __m512 lower = _mm512_mask2_permutex2var_ps(_mm512_loadu_ps(nodes), k, _knot_mask16(upper), _mm512_loadu_ps(nodes + 16));
    return _mm512_mask2_permutex2var_ps(_mm512_loadu_ps(nodes + 32), _mm512_castps_si512(lower), upper,
                                        _mm512_loadu_ps(nodes + 48));
}

// (row[k], row[k + 1]) for k in [0, 64) from a row of 65 nodes that every
// lane shares (the table of 1 - E_avg), the upper nodes as the lower ones of
// the row moved by one
template <int intervals>
PB_KERNEL_INLINE std::pair<Floats, Floats> gather_pair_in_row(const float* row, Ints k) {
    static_assert(intervals == 64, "a row's intervals fill two permutes of 32 nodes");
    const __mmask16 upper = upper_half(k);
    return {permute_lookup(row, k, upper), permute_lookup(row + 1, k, upper)};
}

// A blended row of the 1 - E table (kernel_material.hpp), as the lookups read
// it: the permutes read the intervals' values from 64 floats, then their
// slopes from the next 64.
constexpr int row_value_at(int interval) { return interval; }
constexpr int row_slope_at(int interval) { return 64 + interval; }

PB_KERNEL_INLINE std::pair<Floats, Floats> value_and_slope_in_row(const float* row, Ints interval) {
    static_assert(energy::kIntervals <= 64, "a row fills two permutes of 32 nodes");
    const __mmask16 upper = upper_half(interval);
    return {permute_lookup(row + row_value_at(0), interval, upper), permute_lookup(row + row_slope_at(0), interval, upper)};
}
#elif defined(__AVX2__)
// Each lane's two adjacent floats as one 8-byte load, four lanes to a pair of
// 128-bit halves, then split into the nodes below and above. Scalar loads, not
// gathers: a gather is no faster than its lanes' loads, and these wait only on
// the index moves.
PB_KERNEL_INLINE std::pair<Floats, Floats> gather_pair(const float* table, Ints i) {
    LaneIndices index = lane_indices(i);
    auto pairs = [&](int lane) {  // lanes l and l + 1: (t[i_l], t[i_l + 1], t[i_(l+1)], t[i_(l+1) + 1])
        const __m128d low = _mm_castsi128_pd(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(table + index[lane])));
        return _mm_castpd_ps(_mm_loadh_pd(low, reinterpret_cast<const double*>(table + index[lane + 1])));
    };
    // lanes 0-3 and 4-7: (t[i0], t[i0 + 1], t[i1], t[i1 + 1] | t[i2], ...)
    const __m256 low = _mm256_set_m128(pairs(2), pairs(0));
    const __m256 high = _mm256_set_m128(pairs(6), pairs(4));
    // even or odd floats of each half: (lanes 0 1 4 5 | 2 3 6 7), then the 64-bit quarters reordered
    auto split = [](__m256 x) { return _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(x), _MM_SHUFFLE(3, 1, 2, 0))); };
    return {split(_mm256_shuffle_ps(low, high, _MM_SHUFFLE(2, 0, 2, 0))), split(_mm256_shuffle_ps(low, high, _MM_SHUFFLE(3, 1, 3, 1)))};
}
#else
PB_KERNEL_INLINE std::pair<Floats, Floats> gather_pair(const float* table, Ints i) {
    alignas(64) std::int32_t index[kLanes];
    alignas(64) float below[kLanes];
    alignas(64) float above[kLanes];
    i.store_aligned(index);
    for (std::int64_t j = 0; j < kLanes; ++j) {
        below[j] = table[index[j]];
        above[j] = table[index[j] + 1];
    }
    return {Floats::load_aligned(below), Floats::load_aligned(above)};
}
#endif
#if !defined(__AVX512F__)
template <int intervals>
PB_KERNEL_INLINE std::pair<Floats, Floats> gather_pair_in_row(const float* row, Ints k) { return gather_pair(row, k); }

// A blended row of the 1 - E table (kernel_material.hpp), as the lookups read
// it: each interval's value and slope side by side, one pair a lane.
constexpr int row_value_at(int interval) { return 2 * interval; }
constexpr int row_slope_at(int interval) { return 2 * interval + 1; }

PB_KERNEL_INLINE std::pair<Floats, Floats> value_and_slope_in_row(const float* row, Ints interval) {
    return gather_pair(row, interval + interval);
}
#endif
// table lookups of whole nodes (model/dielectric_energy.hpp): floor(x) for x >= 0,
// and (table[i], table[i + 1]) per lane for a whole i held as a real
PB_KERNEL_INLINE Floats floor_of(Floats x) { return xsimd::floor(x); }
#if defined(__AVX512F__)
PB_KERNEL_INLINE std::pair<Floats, Floats> table_pair(const float* table, Floats index) {
    const __m512i i = _mm512_cvttps_epi32(index);
    return {_mm512_i32gather_ps(i, table, 4), _mm512_i32gather_ps(_mm512_add_epi32(i, _mm512_set1_epi32(1)), table, 4)};
}
#else
PB_KERNEL_INLINE std::pair<Floats, Floats> table_pair(const float* table, Floats index) {
    return gather_pair(table, truncate_to_index(index));
}
#endif

// An interval's value and slope in two adjacent rows, for each lane, from a
// corner table (energy_corners.hpp), one 16-byte load a lane. On AVX2
// and AVX-512 the loads fill the 128-bit blocks of four registers, block b of
// register r with lane 4 b + r, and a 4x4 transpose within the blocks leaves
// corner c of lanes 4 b .. 4 b + 3 in block b of register c. No gathers: one
// 16-byte load a lane fetches all four corners, where gathers of 8-byte pairs
// would take two a register, each no faster than its lanes' loads.
#if defined(__AVX512F__)
// (the interval as energy_interval gives it here: offset by 1/8's bits >> 19,
// any value below the surface; clamped, and the offset taken off in the
// addresses' displacement)
PB_KERNEL_INLINE std::array<Floats, 4> gather_corners(const float* corners, Ints row_offset, Ints interval) {
    static_assert(energy::kCorners == 4, "a corner is 4 floats");
    Ints last(kFirstIntervalBits + energy::kIntervals - 1);
    // in floats, kCorners a corner (addresses scale by 4 at most)
    LaneIndices at = lane_indices((row_offset + xsimd::min(xsimd::max(interval, Ints(kFirstIntervalBits)), last)) << 2);
    auto corners_of = [&](int lane) { return _mm_load_ps(corners + (at[lane] - energy::kCorners * kFirstIntervalBits)); };
    auto blocks = [&](int r) {
        const __m512 low = _mm512_insertf32x4(_mm512_castps128_ps512(corners_of(r)), corners_of(4 + r), 1);
        return _mm512_insertf32x4(_mm512_insertf32x4(low, corners_of(8 + r), 2), corners_of(12 + r), 3);
    };
    const __m512 r0 = blocks(0), r1 = blocks(1), r2 = blocks(2), r3 = blocks(3);
    const __m512d low01 = _mm512_castps_pd(_mm512_unpacklo_ps(r0, r1)), high01 = _mm512_castps_pd(_mm512_unpackhi_ps(r0, r1));
    const __m512d low23 = _mm512_castps_pd(_mm512_unpacklo_ps(r2, r3)), high23 = _mm512_castps_pd(_mm512_unpackhi_ps(r2, r3));
    return {_mm512_castpd_ps(_mm512_unpacklo_pd(low01, low23)), _mm512_castpd_ps(_mm512_unpackhi_pd(low01, low23)),
            _mm512_castpd_ps(_mm512_unpacklo_pd(high01, high23)), _mm512_castpd_ps(_mm512_unpackhi_pd(high01, high23))};
}
#elif defined(__AVX2__)
PB_KERNEL_INLINE std::array<Floats, 4> gather_corners(const float* corners, Ints row_offset, Ints interval) {
    LaneIndices at = lane_indices((row_offset + interval) << 2);  // in floats, as above
    auto corners_of = [&](int lane) { return _mm_load_ps(corners + at[lane]); };
    auto blocks = [&](int r) { return _mm256_set_m128(corners_of(4 + r), corners_of(r)); };
    const __m256 r0 = blocks(0), r1 = blocks(1), r2 = blocks(2), r3 = blocks(3);
    const __m256d low01 = _mm256_castps_pd(_mm256_unpacklo_ps(r0, r1)), high01 = _mm256_castps_pd(_mm256_unpackhi_ps(r0, r1));
    const __m256d low23 = _mm256_castps_pd(_mm256_unpacklo_ps(r2, r3)), high23 = _mm256_castps_pd(_mm256_unpackhi_ps(r2, r3));
    return {_mm256_castpd_ps(_mm256_unpacklo_pd(low01, low23)), _mm256_castpd_ps(_mm256_unpackhi_pd(low01, low23)),
            _mm256_castpd_ps(_mm256_unpacklo_pd(high01, high23)), _mm256_castpd_ps(_mm256_unpackhi_pd(high01, high23))};
}
#else
PB_KERNEL_INLINE std::array<Floats, 4> gather_corners(const float* corners, Ints row_offset, Ints interval) {
    alignas(64) std::int32_t index[kLanes];
    alignas(64) float corner[4][kLanes];
    (row_offset + interval).store_aligned(index);
    for (std::int64_t j = 0; j < kLanes; ++j)
        for (int c = 0; c < 4; ++c) corner[c][j] = corners[energy::kCorners * index[j] + c];
    return {Floats::load_aligned(corner[0]), Floats::load_aligned(corner[1]), Floats::load_aligned(corner[2]),
            Floats::load_aligned(corner[3])};
}
#endif

// (sin 2πu, cos 2πu) for u in [0, 1] by the double angle, without quadrant
// selects: with t = u - 1/2 and θ = πt in [-π/2, π/2], 2πu = 2θ + π, so
//   sin 2πu = -2 sinθ cosθ = T C,  cos 2πu = 2 sin²θ - 1 = T² - 1,
// T = √2 sinθ = t P(t²) and C = -√2 cosθ = Q(t²), near-minimax polynomials
// of degrees 9 and 10 in t (Chebyshev least squares; 3e-8 in exact arithmetic,
// under 8e-7 absolute after float rounding, against about 1e-7 for a
// quadrant-reduced sincos; wi, pdf and weight stay consistent whatever φ is).
PB_KERNEL_INLINE std::pair<Floats, Floats> sincos_turns(Floats u) {
    Floats t = u - 0.5f;
    Floats z = t * t;
    Floats p(0.1098245158791542f);
    for (float coefficient : {-0.8461116552352905f, 3.606354236602783f, -7.308245658874512f, 4.442883014678955f})
        p = mul_add(p, z, Floats(coefficient));
    Floats q(0.034501612186431885f);
    for (float coefficient : {-0.33225154876708984f, 1.888274908065796f, -5.73988151550293f, 6.9788641929626465f, -1.4142135381698608f})
        q = mul_add(q, z, Floats(coefficient));
    Floats root2_sin = t * p;
    return {root2_sin * q, mul_sub(root2_sin, root2_sin, Floats(1.0f))};
}

// e^x - 1 for x in [0, 14] (the clearcoat draw): x = k ln 2 + r with k = round(x / ln 2)
// (ln 2 in two parts, Cody-Waite, so r is exact to float precision) and |r| <= ln 2 / 2;
// then e^x - 1 = 2^k (e^r - 1) + (2^k - 1), both terms of one sign for k >= 1, and
// e^r - 1 = r (1 + r/2 + ... + r^6/7!) (Taylor). Relative error < 2e-7 over [0, 14].
PB_KERNEL_INLINE Floats exp_minus_one(Floats x) {
    Ints k_int = xsimd::nearbyint_as_int(x * 1.44269504088896341f);  // one conversion on every instruction set
    Floats k = xsimd::to_float(k_int);
    Floats r = neg_mul_add(k, Floats(kLn2Low), neg_mul_add(k, Floats(kLn2High), x));
    Floats series(1.0f / 5040.0f);
    for (float coefficient : {1.0f / 720.0f, 1.0f / 120.0f, 1.0f / 24.0f, 1.0f / 6.0f, 0.5f, 1.0f})
        series = mul_add(series, r, Floats(coefficient));
    Floats two_to_k = xsimd::bitwise_cast<Floats>((k_int + Ints(127)) << 23);
    return mul_add(two_to_k, series * r, two_to_k - 1.0f);
}
