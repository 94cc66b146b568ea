// Part of kernel.hpp, included inside the per-arch namespace: drawing wi from
// the three lobes exactly as README "Sampling and pdf" defines it, branch-free
// (every lane computes every lobe's candidate, then selects), and the
// counter-based uniforms.
#pragma once  // (per translation unit)

using UInts = xsimd::batch<std::uint32_t, Arch>;

// Low 32 bits of a 32 x 32-bit product (xsimd 8.1 has no native one for AVX-512).
#if defined(__AVX512F__)
PB_KERNEL_INLINE UInts multiply_low(UInts a, std::uint32_t b) { return _mm512_mullo_epi32(a, _mm512_set1_epi32(static_cast<int>(b))); }
#elif defined(__AVX2__)
PB_KERNEL_INLINE UInts multiply_low(UInts a, std::uint32_t b) { return _mm256_mullo_epi32(a, _mm256_set1_epi32(static_cast<int>(b))); }
#else
PB_KERNEL_INLINE UInts multiply_low(UInts a, std::uint32_t b) { return a * UInts(b); }
#endif

#include "counter_rng.hpp"

constexpr float kTwoPi = 6.28318530717958647692f;

struct Uniforms {
    Floats u0, u1, u2;
};

struct LaneIndices {
    alignas(64) std::uint32_t lanes[kLanes];
    constexpr LaneIndices() : lanes{} {
        for (std::int64_t j = 0; j < kLanes; ++j) lanes[j] = static_cast<std::uint32_t>(j);
    }
};
inline constexpr LaneIndices kLaneIndices{};

// u_k for elements first + 0 .. first + kLanes - 1; first is a multiple of
// kLanes, so the low 32 bits never carry into the high ones within a batch.
PB_KERNEL_INLINE Uniforms counter_uniforms(std::uint64_t first, const CounterKeys& keys) {
    const UInts index_low = UInts::load_aligned(kLaneIndices.lanes) + UInts(static_cast<std::uint32_t>(first));
    const auto high = static_cast<std::uint32_t>(first >> 32);
    Floats u[3];
    for (int k = 0; k < 3; ++k) {
        const UInts bits = counter_bits(index_low, high, keys, k) >> 8;
        u[k] = xsimd::to_float(xsimd::bitwise_cast<xsimd::batch<std::int32_t, Arch>>(bits)) * 0x1p-24f;
    }
    return {u[0], u[1], u[2]};
}

struct LobeChoice {
    Mask cosine, specular;  // clearcoat otherwise
};

// Lobe 0 if u0 < P0, else 1 if u0 < P0 + P1, else 2; never 2 when P2 = 0
// (P0 + P1 may round below 1 while u0 reaches 1 - 2^-24, or 1 if passed).
PB_KERNEL_INLINE LobeChoice choose_lobe(Floats u0, const LobeProbabilities& p) {
    const Mask cosine = u0 < p.cosine;
    return {cosine, ((u0 < p.cosine + p.specular) | (p.clearcoat <= Floats(0.0f))) & !cosine};
}

// (sin 2πu, cos 2πu) for u in [0, 1]: reduced to a quarter turn, q = round(4u),
// θ = (4u - q) π/2 in [-π/4, π/4], then Cephes' single-precision minimax
// polynomials (about 1 ulp), rotated by q quarter turns.
PB_KERNEL_INLINE std::pair<Floats, Floats> sincos_turns(Floats u) {
    const Floats quarter_turns = 4.0f * u;
    const Floats q = xsimd::nearbyint(quarter_turns);
    const Floats theta = (quarter_turns - q) * 1.57079632679489661923f;
    const Floats z = theta * theta;
    const Floats sin_theta =
        xsimd::fma(xsimd::fma(xsimd::fma(Floats(-1.9515295891e-4f), z, Floats(8.3321608736e-3f)), z, Floats(-1.6666654611e-1f)),
                   z * theta, theta);
    const Floats cos_theta = xsimd::fma(
        xsimd::fma(xsimd::fma(Floats(2.443315711809948e-5f), z, Floats(-1.388731625493765e-3f)), z, Floats(4.166664568298827e-2f)),
        z * z, xsimd::fnma(Floats(0.5f), z, Floats(1.0f)));
    // q mod 4 = 1 or 3 swaps sine and cosine; 2, 3 negate the sine; 1, 2 the cosine
    const Mask q1 = q == Floats(1.0f), q2 = q == Floats(2.0f), q3 = q == Floats(3.0f);
    const Mask swap = q1 | q3;
    const Floats sine = xsimd::select(swap, cos_theta, sin_theta);
    const Floats cosine = xsimd::select(swap, sin_theta, cos_theta);
    return {xsimd::select(q2 | q3, -sine, sine), xsimd::select(q1 | q2, -cosine, cosine)};
}

// sqrt(x) for x >= 0 through the refined reciprocal square root (0 stays 0)
PB_KERNEL_INLINE Floats fast_sqrt(Floats x) {
    return xsimd::select(x > Floats(0.0f), x * reciprocal_sqrt(x), Floats(0.0f));
}

PB_KERNEL_INLINE Vec3 normalized(const Vec3& v) {
    const Floats inv_length = reciprocal_sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    return {v.x * inv_length, v.y * inv_length, v.z * inv_length};
}

PB_KERNEL_INLINE Vec3 select(const Mask& m, const Vec3& a, const Vec3& b) {
    return {xsimd::select(m, a.x, b.x), xsimd::select(m, a.y, b.y), xsimd::select(m, a.z, b.z)};
}

// Primary specular half vector, unnormalised. Visible normals by spherical
// caps (Dupuy & Benyoub 2023): v = normalize(ax wo.x, ay wo.y, wo.z),
// z = (1 - u2)(1 + v.z) - v.z, m = (s cos φ, s sin φ, z) + v,
// h ∝ (ax m.x, ay m.y, m.z). Distribution (eq. 14-15):
// h ∝ (sqrt(u2) ax cos φ, sqrt(u2) ay sin φ, sqrt(1 - u2)).
PB_KERNEL_INLINE Vec3 specular_half_vector(const Vec3& wo, Floats u2, Floats cos_phi, Floats sin_phi, const Shading& s,
                                 SpecularSampler sampler) {
    if (sampler == SpecularSampler::kDistribution) {
        const Floats radius = fast_sqrt(u2);
        return {radius * s.alpha_x * cos_phi, radius * s.alpha_y * sin_phi, fast_sqrt(Floats(1.0f) - u2)};
    }
    const Vec3 v = normalized({s.alpha_x * wo.x, s.alpha_y * wo.y, wo.z});
    const Floats z = xsimd::fms(Floats(1.0f) - u2, Floats(1.0f) + v.z, v.z);
    const Floats sin_theta = fast_sqrt(xsimd::fnma(z, z, Floats(1.0f)));
    return {s.alpha_x * xsimd::fma(sin_theta, cos_phi, v.x), s.alpha_y * xsimd::fma(sin_theta, sin_phi, v.y), z + v.z};
}

// e^x - 1 for x in [0, 14] without expm1's division: exp(x) - 1, and for
// x < 0.25, where that cancels, the Taylor series to x^7 (error < 2e-8 relative).
PB_KERNEL_INLINE Floats exp_minus_one(Floats x) {
    Floats series(1.0f / 5040.0f);
    for (float coefficient : {1.0f / 720.0f, 1.0f / 120.0f, 1.0f / 24.0f, 1.0f / 6.0f, 0.5f, 1.0f})
        series = xsimd::fma(series, x, Floats(coefficient));
    return xsimd::select(x < Floats(0.25f), series * x, xsimd::exp(x) - 1.0f);
}

// Clearcoat (GTR1, a = ac) half vector: sin²θh = a² (a^(-2 u2) - 1) / (1 - a²),
// written as e^x - 1 with x = -u2 ln a², which keeps the narrow peak (u2 -> 0) accurate.
PB_KERNEL_INLINE Vec3 clearcoat_half_vector(Floats u2, Floats cos_phi, Floats sin_phi, const Shading& s) {
    const Floats sin2 = xsimd::min(s.clearcoat_sin2_scale * exp_minus_one(-u2 * s.clearcoat_log_alpha2), Floats(1.0f));
    const Floats sin_theta = fast_sqrt(sin2);
    return {sin_theta * cos_phi, sin_theta * sin_phi, fast_sqrt(Floats(1.0f) - sin2)};
}

// wi for the chosen lobes. Every lane computes the candidates of the lobes
// chosen in the batch and selects its own; a candidate no lane chose is
// skipped, which changes no result. A half vector of length 0 (u2 = 1 at
// special angles) gives h = 0, so wi = -wo: below the horizon like every
// other u2 = 1 sample of the reflected lobes.
PB_KERNEL_INLINE Vec3 sample_direction(const Vec3& wo, const Uniforms& u, const LobeChoice& lobe, const Shading& s,
                                       SpecularSampler sampler) {
    // φ = 2π u2 for the cosine lobe, 2π u1 for the others: one sincos for all
    const auto [sin_phi, cos_phi] = sincos_turns(xsimd::select(lobe.cosine, u.u2, u.u1));

    // Cosine lobe: r = sqrt(u1), wi = (r cos φ, r sin φ, sqrt(1 - u1))
    const Floats radius = fast_sqrt(u.u1);
    const Vec3 cosine{radius * cos_phi, radius * sin_phi, fast_sqrt(Floats(1.0f) - u.u1)};
    if (xsimd::all(lobe.cosine)) return cosine;

    const Mask clearcoat = !lobe.cosine & !lobe.specular;
    Vec3 h = xsimd::any(lobe.specular) ? specular_half_vector(wo, u.u2, cos_phi, sin_phi, s, sampler) : cosine;
    if (xsimd::any(clearcoat)) h = select(clearcoat, clearcoat_half_vector(u.u2, cos_phi, sin_phi, s), h);
    const Floats h_len2 = h.x * h.x + h.y * h.y + h.z * h.z;
    const Floats zero(0.0f);
    h = select(h_len2 > zero, normalized(h), Vec3{zero, zero, zero});
    // wi = 2 (wo·h) h - wo
    const Floats twice_cos = 2.0f * (wo.x * h.x + wo.y * h.y + wo.z * h.z);
    const Vec3 reflected{xsimd::fms(twice_cos, h.x, wo.x), xsimd::fms(twice_cos, h.y, wo.y), xsimd::fms(twice_cos, h.z, wo.z)};
    return select(lobe.cosine, cosine, reflected);
}
