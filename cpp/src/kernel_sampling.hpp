// Part of kernel.hpp, included inside the per-arch namespace: drawing wi from
// the three lobes exactly as README "Sampling and pdf" defines it, branch-free
// across lanes (one construction for all lobes, its parameters selected per
// lane), and the counter-based uniforms.
#pragma once  // (per translation unit)

using UInts = xsimd::batch<std::uint32_t, Arch>;
using Ints = xsimd::batch<std::int32_t, Arch>;

// Low 32 bits of a 32 x 32-bit product (xsimd 8.1 has no native one for AVX-512).
#if defined(__AVX512F__)
PB_KERNEL_INLINE UInts multiply_low(UInts a, std::uint32_t b) { return _mm512_mullo_epi32(a, _mm512_set1_epi32(static_cast<int>(b))); }
#elif defined(__AVX2__)
PB_KERNEL_INLINE UInts multiply_low(UInts a, std::uint32_t b) { return _mm256_mullo_epi32(a, _mm256_set1_epi32(static_cast<int>(b))); }
#else
PB_KERNEL_INLINE UInts multiply_low(UInts a, std::uint32_t b) { return a * UInts(b); }
#endif

#include "counter_rng.hpp"

struct Uniforms {
    Floats u0, u1, u2;
};

// The three counters of lane j, spread: spread_counter(j) + k 0x9E3779B9 for
// stream k. Those of a batch are the first element's spread counter plus
// these (the spread is linear mod 2^32): one add per stream instead of a
// 32-bit multiply.
struct LaneCounters {
    alignas(64) std::uint32_t lanes[3][kLanes];
    constexpr LaneCounters() : lanes{} {
        for (std::uint32_t k = 0; k < 3; ++k)
            for (std::int64_t j = 0; j < kLanes; ++j) lanes[k][j] = spread_counter(static_cast<std::uint32_t>(j)) + k * kGolden;
    }
};
inline constexpr LaneCounters kLaneCounters{};

// The top 24 bits of x as a float in [0, 1): (x >> 8) 2^-24. On AVX-512 as
// (x & ~0xFF) 2^-32 with an unsigned conversion, which fuses with the hash's
// last xor into one three-input logic op.
PB_KERNEL_INLINE Floats unit_interval(UInts x) {
#if defined(__AVX512F__)
    return Floats(_mm512_cvtepu32_ps(x & UInts(0xFFFFFF00u))) * 0x1p-32f;
#else
    return xsimd::to_float(xsimd::bitwise_cast<Ints>(x >> 8)) * 0x1p-24f;
#endif
}

// u_k for elements first + 0 .. first + kLanes - 1; first is a multiple of
// kLanes, so the low 32 bits never carry into the high ones within a batch.
// lowbias32's first step of c ^ key, y ^ (y >> 16) with y = c ^ key, is
// c ^ (c >> 16) ^ (key ^ (key >> 16)) (a logical shift distributes over ^):
// the key's part is one scalar and the rest fuses into one op on AVX-512.
PB_KERNEL_INLINE Uniforms counter_uniforms(std::uint64_t first, const CounterSeed& seed) {
    const std::uint32_t key = counter_key(seed, static_cast<std::uint32_t>(first >> 32));
    const UInts key_shifted_in(key ^ (key >> 16));
    const UInts first_spread(spread_counter(static_cast<std::uint32_t>(first)));
    Floats u[3];
    for (int k = 0; k < 3; ++k) {
        const UInts counter = UInts::load_aligned(kLaneCounters.lanes[k]) + first_spread;
        u[k] = unit_interval(lowbias32_rounds(counter ^ key_shifted_in ^ (counter >> 16)));
    }
    return {u[0], u[1], u[2]};
}

struct LobeChoice {
    Mask cosine, specular;  // clearcoat otherwise
};

// Lobe 0 if u0 < P0, else 1 if u0 < P0 + P1, else 2, compared as u0 Σ w
// against w0 and w0 + w1; never 2 when w2 = 0 (u0 may be 1 if passed).
PB_KERNEL_INLINE LobeChoice choose_lobe(Floats u0, const Shading& s, const LobeWeights& w) {
    const Floats scaled = u0 * (s.cosine_lobe_weight + w.specular + w.clearcoat);
    const Mask cosine = scaled < s.cosine_lobe_weight;
    return {cosine, ((scaled < s.cosine_lobe_weight + w.specular) | (w.clearcoat <= Floats(0.0f))) & !cosine};
}

// (sin 2πu, cos 2πu) for u in [0, 1] by the double angle, without quadrant
// selects: with t = u - 1/2 and θ = πt in [-π/2, π/2], 2πu = 2θ + π, so
//   sin 2πu = -2 sinθ cosθ = T C,  cos 2πu = 2 sin²θ - 1 = T² - 1,
// T = √2 sinθ = t P(t²) and C = -√2 cosθ = Q(t²), near-minimax polynomials
// of degrees 9 and 10 in t (Chebyshev least squares; 3e-8 in exact arithmetic,
// under 8e-7 absolute after float rounding, against about 1e-7 for a
// quadrant-reduced sincos; wi, pdf and weight stay consistent whatever φ is).
PB_KERNEL_INLINE std::pair<Floats, Floats> sincos_turns(Floats u) {
    const Floats t = u - 0.5f;
    const Floats z = t * t;
    Floats p(0.1098245158791542f);
    for (float coefficient : {-0.8461116552352905f, 3.606354236602783f, -7.308245658874512f, 4.442883014678955f})
        p = mul_add(p, z, Floats(coefficient));
    Floats q(0.034501612186431885f);
    for (float coefficient : {-0.33225154876708984f, 1.888274908065796f, -5.73988151550293f, 6.9788641929626465f, -1.4142135381698608f})
        q = mul_add(q, z, Floats(coefficient));
    const Floats root2_sin = t * p;
    return {root2_sin * q, mul_sub(root2_sin, root2_sin, Floats(1.0f))};
}

PB_KERNEL_INLINE Vec3 select(const Mask& m, const Vec3& a, const Vec3& b) {
    return {xsimd::select(m, a.x, b.x), xsimd::select(m, a.y, b.y), xsimd::select(m, a.z, b.z)};
}

// e^x - 1 for x in [0, 14] (the clearcoat draw): x = k ln 2 + r with k = round(x / ln 2)
// (ln 2 in two parts, Cody-Waite, so r is exact to float precision) and |r| <= ln 2 / 2;
// then e^x - 1 = 2^k (e^r - 1) + (2^k - 1), both terms of one sign for k >= 1, and
// e^r - 1 = r (1 + r/2 + ... + r^6/7!) (Taylor). Relative error < 2e-7 over [0, 14].
PB_KERNEL_INLINE Floats exp_minus_one(Floats x) {
    const Ints k_int = xsimd::nearbyint_as_int(x * 1.44269504088896341f);  // one conversion on every instruction set
    const Floats k = xsimd::to_float(k_int);
    const Floats r = neg_mul_add(k, Floats(1.42860682030941723e-6f), neg_mul_add(k, Floats(0.693145751953125f), x));
    Floats series(1.0f / 5040.0f);
    for (float coefficient : {1.0f / 720.0f, 1.0f / 120.0f, 1.0f / 24.0f, 1.0f / 6.0f, 0.5f, 1.0f})
        series = mul_add(series, r, Floats(coefficient));
    const Floats two_to_k = xsimd::bitwise_cast<Floats>((k_int + Ints(127)) << 23);
    return mul_add(two_to_k, series * r, two_to_k - 1.0f);
}

// What the draw returns: wi, and the visible-normal Smith denominator of wo
// (View::smith_visible), which the draw computes on the way.
struct Direction {
    Vec3 wi;
    Floats smith_visible;  // cos θv + |V|, V = (ax wo.x, ay wo.y, wo.z)
};

// wi for the chosen lobes. Each lobe draws a point at azimuth φ = 2π u1 about
// a centre and stretches it (README "Sampling and pdf"):
//   m = (sinθ cos φ + c.x, sinθ sin φ + c.y, cosθ + c.z),  d = (sx m.x, sy m.y, m.z)
// cosine lobe:  sin²θ = u2, c = 0, s = 1, wi = d
// clearcoat:    sin²θ = ac² (ac^(-2 u2) - 1) / (1 - ac²) = e^x - 1 scaled, x = -u2 ln ac²;
//               c = 0, s = 1, h ∝ d
// specular, visible normals by spherical caps (Dupuy & Benyoub 2023):
//               c = normalize(ax wo.x, ay wo.y, wo.z), cosθ = (1 - u2)(1 + c.z) - c.z,
//               s = (ax, ay), h ∝ d
// specular, distribution (eq. 14-15): sin²θ = u2, c = 0, s = (ax, ay), h ∝ d
// and wi = 2 (wo·h) h - wo for the reflected lobes. So every lane does one
// draw, whatever the mixture of lobes in its batch; the parts of a lobe no
// lane chose are skipped, which changes no result. A d of length 0 (u2 = 1 at
// special angles) gives h = 0 and wi = -wo: below the horizon like every
// other u2 = 1 sample of the reflected lobes.
PB_KERNEL_INLINE Direction sample_direction(const Vec3& wo, const Uniforms& u, const LobeChoice& lobe, const Shading& s,
                                            SpecularSampler sampler) {
    const Floats zero(0.0f), one(1.0f);
    // the visible-normal cap construction scaled by L = |V|, V = (ax wo.x, ay wo.y, wo.z),
    // so V need not be normalised: L cosθ = (1 - u2)(L + V.z) - V.z, L² sin²θ = L² - (L cosθ)²;
    // cos θv + L is the View's smith_visible, which the weight needs anyway
    const Vec3 stretched{s.alpha_x * wo.x, s.alpha_y * wo.y, wo.z};
    const Floats length2 = mul_add(stretched.x, stretched.x, mul_add(stretched.y, stretched.y, stretched.z * stretched.z));
    const Floats length = square_root(length2);
    const Floats smith_visible = wo.z + length;
    const auto [sin_phi, cos_phi] = sincos_turns(u.u1);
    if (xsimd::all(lobe.cosine)) {
        const Floats radius = square_root(u.u2);
        return {{radius * cos_phi, radius * sin_phi, square_root(one - u.u2)}, smith_visible};
    }
    const Mask clearcoat = !lobe.cosine & !lobe.specular;
    const bool visible_normals = sampler == SpecularSampler::kVisibleNormals;
    const Mask visible_specular = visible_normals ? lobe.specular : Mask(false);

    Floats sin2_theta = u.u2;  // cosine lobe, distribution sampler
    Floats scaled_cos = zero;  // L cosθ of the visible-normal specular
    Floats centre_x = zero, centre_y = zero;
    if (visible_normals && xsimd::any(lobe.specular)) {
        scaled_cos = mul_sub(one - u.u2, length + stretched.z, stretched.z);
        sin2_theta = xsimd::select(lobe.specular, neg_mul_add(scaled_cos, scaled_cos, length2), sin2_theta);
        centre_x = xsimd::select(lobe.specular, stretched.x, zero);
        centre_y = xsimd::select(lobe.specular, stretched.y, zero);
    }
    if (xsimd::any(clearcoat)) {
        const Floats sin2 = xsimd::min(s.clearcoat_sin2_scale * exp_minus_one(-u.u2 * s.clearcoat_log_alpha2), one);
        sin2_theta = xsimd::select(clearcoat, sin2, sin2_theta);
    }
    const Floats sin_theta = square_root(sin2_theta);
    // m.z: L cosθ + V.z for the visible-normal specular, else cosθ from sin²θ
    const Floats height = xsimd::select(visible_specular, scaled_cos + stretched.z, square_root(one - sin2_theta));
    const Floats stretch_x = xsimd::select(lobe.specular, s.alpha_x, one);
    const Floats stretch_y = xsimd::select(lobe.specular, s.alpha_y, one);
    const Vec3 d{stretch_x * mul_add(sin_theta, cos_phi, centre_x), stretch_y * mul_add(sin_theta, sin_phi, centre_y), height};

    // wi = 2 (wo·h) h - wo with h = d / |d|
    const Floats d_len2 = mul_add(d.x, d.x, mul_add(d.y, d.y, d.z * d.z));
    const Floats scale = xsimd::select(d_len2 > zero, 2.0f * mul_add(wo.x, d.x, mul_add(wo.y, d.y, wo.z * d.z)) * reciprocal(d_len2), zero);
    const Vec3 reflected{mul_sub(scale, d.x, wo.x), mul_sub(scale, d.y, wo.y), mul_sub(scale, d.z, wo.z)};
    return {select(lobe.cosine, d, reflected), smith_visible};
}
