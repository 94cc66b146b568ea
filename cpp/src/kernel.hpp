// The SIMD kernel: SPEC §3 over xsimd::batch<float, Arch>, branch-free.
//
// Included exactly once by each kernel_<isa>.cpp, after it defines
// PRINCIPLED_BRDF_ARCH (the xsimd arch tag) and PRINCIPLED_BRDF_ARCH_NS (a
// namespace name). Everything here lives in that per-arch namespace, so code
// compiled with one instruction set's flags is never linked into another's.
//
// Accuracy (SPEC §6.2): the half vector is kept unnormalised, H = wi + wo.
// Its components are exact float sums where wi and wo nearly cancel, so
// cos²θh = Hz²/|H|² and sin²θh = (Hx² + Hy²)/|H|² keep full relative precision
// at the narrow GTR peaks, where 1 - cos²θh would cancel.
#include <xsimd/xsimd.hpp>

#include <cstdint>
#include <limits>

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include "kernel_api.hpp"

namespace principled_brdf::kernel::PRINCIPLED_BRDF_ARCH_NS {

using Arch = PRINCIPLED_BRDF_ARCH;
using Floats = xsimd::batch<float, Arch>;
using Mask = xsimd::batch_bool<float, Arch>;
constexpr std::int64_t kLanes = static_cast<std::int64_t>(Floats::size);

#include "simd_ops.hpp"

constexpr float kInvPi = 0.318309886183790671538f;

struct Vec3 {
    Floats x, y, z;
};

struct Rgb {
    Floats r, g, b;
};

inline Rgb operator*(Floats s, const Rgb& c) { return {s * c.r, s * c.g, s * c.b}; }
inline Rgb operator+(const Rgb& a, const Rgb& b) { return {a.r + b.r, a.g + b.g, a.b + b.b}; }

inline Floats mix(Floats a, Floats b, Floats t) { return xsimd::fma(b - a, t, a); }
inline Rgb mix(const Rgb& a, const Rgb& b, Floats t) { return {mix(a.r, b.r, t), mix(a.g, b.g, t), mix(a.b, b.b, t)}; }

// Schlick(u) = clamp(1 - u, 0, 1)^5
inline Floats schlick_weight(Floats u) {
    const Floats m = xsimd::min(xsimd::max(Floats(1.0f) - u, Floats(0.0f)), Floats(1.0f));
    const Floats m2 = m * m;
    return m2 * m2 * m;
}

// ---------------------------------------------------------------- materials

// The 13 parameter slots of one batch of elements.
struct RawMaterial {
    Floats slot[kParamSlots];
};

inline RawMaterial load_material(const EvalJob& job, std::int64_t i) {
    RawMaterial m;
    const ParamSlot& red = job.params[kBaseColorR];
    if (red.per_element() && red.stride == 3) {
        load_interleaved(red.data + 3 * i, m.slot[kBaseColorR], m.slot[kBaseColorG], m.slot[kBaseColorB]);
    } else {
        for (int s = kBaseColorR; s <= kBaseColorB; ++s) {
            const ParamSlot& p = job.params[s];
            m.slot[s] = p.per_element() ? Floats::load_unaligned(p.data + i) : Floats(p.value);
        }
    }
    for (int s = kMetallic; s < kParamSlots; ++s) {
        const ParamSlot& p = job.params[s];
        m.slot[s] = p.per_element() ? Floats::load_unaligned(p.data + i) : Floats(p.value);
    }
    return m;
}

// What the lobes need of a material, independent of the directions: computed
// once per call for a uniform material, per batch otherwise.
struct Shading {
    Rgb diffuse_color;  // base_color (1 - metallic) / π
    Floats subsurface;
    Floats roughness;
    Rgb sheen_color;    // sheen Csheen (1 - metallic)
    Rgb specular_f0;    // Cspec0
    Floats inv_alpha_x2, inv_alpha_y2, ggx_norm;  // GTR2 aniso: 1/ax², 1/ay², 1/(π ax ay)
    Floats alpha_x2, alpha_y2;                     // Smith (2014): ax², ay²
    Floats alpha_g2;                               // Smith (2012): alpha_g²
    Floats clearcoat_scale;                        // 0.25 clearcoat (ac² - 1) / (π ln ac²)
    Floats clearcoat_alpha2;                       // ac²
};

inline Shading shading_of(const RawMaterial& m) {
    const Floats* p = m.slot;
    const Floats one(1.0f);
    const Rgb base{p[kBaseColorR], p[kBaseColorG], p[kBaseColorB]};
    const Floats metallic = p[kMetallic];
    const Floats dielectric = one - metallic;

    // Ctint: hue and saturation at unit luminance (1 where the luminance is 0)
    const Floats luminance = 0.3f * base.r + 0.6f * base.g + 0.1f * base.b;
    const Mask has_luminance = luminance > Floats(0.0f);
    const Floats inv_luminance = one / xsimd::select(has_luminance, luminance, one);
    const Rgb tint{xsimd::select(has_luminance, base.r * inv_luminance, one),
                   xsimd::select(has_luminance, base.g * inv_luminance, one),
                   xsimd::select(has_luminance, base.b * inv_luminance, one)};
    const Rgb white{one, one, one};

    Shading s;
    s.diffuse_color = (dielectric * kInvPi) * base;
    s.subsurface = p[kSubsurface];
    s.roughness = p[kRoughness];
    s.sheen_color = (p[kSheen] * dielectric) * mix(white, tint, p[kSheenTint]);
    s.specular_f0 = mix((p[kSpecular] * 0.08f) * mix(white, tint, p[kSpecularTint]), base, metallic);

    // 2014 addenda: aspect = sqrt(1 - 0.9 anisotropic), alpha = roughness²
    const Floats aspect = xsimd::sqrt(one - 0.9f * p[kAnisotropic]);
    const Floats alpha = p[kRoughness] * p[kRoughness];
    const Floats alpha_x = xsimd::max(Floats(0.001f), alpha / aspect);
    const Floats alpha_y = xsimd::max(Floats(0.001f), alpha * aspect);
    s.alpha_x2 = alpha_x * alpha_x;
    s.alpha_y2 = alpha_y * alpha_y;
    s.inv_alpha_x2 = one / s.alpha_x2;
    s.inv_alpha_y2 = one / s.alpha_y2;
    s.ggx_norm = kInvPi / (alpha_x * alpha_y);
    const Floats alpha_g = 0.5f + 0.5f * p[kRoughness];
    s.alpha_g2 = (alpha_g * alpha_g) * (alpha_g * alpha_g);

    // GTR1 with ac = mix(0.1, 0.001, clearcoat_gloss); ac stays in [0.001, 0.1]
    const Floats clearcoat_alpha = mix(Floats(0.1f), Floats(0.001f), p[kClearcoatGloss]);
    s.clearcoat_alpha2 = clearcoat_alpha * clearcoat_alpha;
    s.clearcoat_scale = (0.25f * kInvPi) * p[kClearcoat] * (s.clearcoat_alpha2 - one) / xsimd::log(s.clearcoat_alpha2);
    return s;
}

// ---------------------------------------------------------------- the BRDF

// n·w + sqrt(q), the denominator of the Smith factor S(w) = G1(w) / (2 n·w)
// of SPEC §3, given q = (w·x ax)² + (w·y ay)² + (n·w)². Products of these
// share one reciprocal.
inline Floats smith_denominator(Floats cos_theta, Floats q) { return xsimd::fma(q, reciprocal_sqrt(q), cos_theta); }

// Isotropic form, alpha² = a2: q = a2 + cos²(1 - a2)
inline Floats smith_denominator_iso(Floats cos_theta, Floats a2) {
    return smith_denominator(cos_theta, xsimd::fma(cos_theta * cos_theta, Floats(1.0f) - a2, a2));
}

struct LobeValues {
    Rgb diffuse, sheen, specular;
    Floats clearcoat;
    Mask finite_half_vector;  // false where a direction held NaN or infinity (checks off)
};

template <Model model>
inline LobeValues eval_lobes(const Vec3& wi, const Vec3& wo, const Shading& s) {
    const Floats one(1.0f);
    const Floats cos_theta_l = wi.z, cos_theta_v = wo.z;

    // Unnormalised half vector H = wi + wo
    const Floats hx = wi.x + wo.x, hy = wi.y + wo.y, hz = wi.z + wo.z;
    const Floats hx2 = hx * hx, hy2 = hy * hy, hz2 = hz * hz;
    const Floats h_len2 = hx2 + hy2 + hz2;
    LobeValues out;
    out.finite_half_vector = h_len2 <= Floats(std::numeric_limits<float>::max());
    const Floats inv_h_len = reciprocal_sqrt(h_len2);
    const Floats wi_dot_h = wi.x * hx + wi.y * hy + wi.z * hz;  // |H| cos θd
    const Floats cos_theta_d = wi_dot_h * inv_h_len;
    const Floats cos2_theta_d = cos_theta_d * cos_theta_d;

    const Floats fl = schlick_weight(cos_theta_l);
    const Floats fv = schlick_weight(cos_theta_v);
    const Floats fh = schlick_weight(cos_theta_d);

    // Diffuse: Fd = mix(1, Fd90, FL) mix(1, Fd90, FV), Fd90 = 0.5 + 2 roughness cos²θd
    const Floats fd90_minus_1 = xsimd::fma(2.0f * s.roughness, cos2_theta_d, Floats(-0.5f));
    const Floats fd = xsimd::fma(fd90_minus_1, fl, one) * xsimd::fma(fd90_minus_1, fv, one);
    // Subsurface: ss = 1.25 (Fss (1/(cos θl + cos θv) - 0.5) + 0.5), Fss90 = roughness cos²θd
    const Floats fss90_minus_1 = xsimd::fms(s.roughness, cos2_theta_d, one);
    const Floats fss = xsimd::fma(fss90_minus_1, fl, one) * xsimd::fma(fss90_minus_1, fv, one);
    const Floats inv_cos_sum = reciprocal(cos_theta_l + cos_theta_v);
    const Floats ss = 1.25f * xsimd::fma(fss, inv_cos_sum - 0.5f, Floats(0.5f));
    out.diffuse = mix(fd, ss, s.subsurface) * s.diffuse_color;

    out.sheen = fh * s.sheen_color;

    // GTR2 aniso: Ds = 1/(π ax ay (hx²/ax² + hy²/ay² + hz²)²), with h = H/|H|
    const Floats stretched = xsimd::fma(hx2, s.inv_alpha_x2, xsimd::fma(hy2, s.inv_alpha_y2, hz2));
    const Floats ds_root = h_len2 * reciprocal(stretched);
    const Floats ds = s.ggx_norm * ds_root * ds_root;
    Floats gs_denominator;
    if constexpr (model == Model::kDisney2012) {
        gs_denominator = smith_denominator_iso(cos_theta_l, s.alpha_g2) * smith_denominator_iso(cos_theta_v, s.alpha_g2);
    } else {
        const Floats q_l = xsimd::fma(s.alpha_x2, wi.x * wi.x, xsimd::fma(s.alpha_y2, wi.y * wi.y, cos_theta_l * cos_theta_l));
        const Floats q_v = xsimd::fma(s.alpha_x2, wo.x * wo.x, xsimd::fma(s.alpha_y2, wo.y * wo.y, cos_theta_v * cos_theta_v));
        gs_denominator = smith_denominator(cos_theta_l, q_l) * smith_denominator(cos_theta_v, q_v);
    }
    out.specular = (ds * reciprocal(gs_denominator)) * mix(s.specular_f0, Rgb{one, one, one}, fh);

    // Clearcoat 0.25 clearcoat Gr Fr Dr with GTR1 Dr = (ac² - 1)/(π ln ac²) / (ac² cos²θh + sin²θh)
    // (the constants are in clearcoat_scale) and Gr = S(wi) S(wo) at alpha 0.25.
    const Floats fr = xsimd::fma(Floats(0.96f), fh, Floats(0.04f));
    const Floats quarter2 = Floats(0.0625f);
    const Floats gr_denominator = smith_denominator_iso(cos_theta_l, quarter2) * smith_denominator_iso(cos_theta_v, quarter2);
    const Floats dr_denominator = xsimd::fma(s.clearcoat_alpha2, hz2, hx2 + hy2);  // |H|² (ac² cos²θh + sin²θh)
    out.clearcoat = s.clearcoat_scale * fr * h_len2 * reciprocal(dr_denominator * gr_denominator);
    return out;
}

// ---------------------------------------------------------------- memory

// Every array of a call in one layout lets the loop be compiled for it;
// kMixedLayouts reads each array's layout at run time.
enum class Layouts { kInterleaved, kRows, kMixed };

template <Layouts layouts = Layouts::kMixed>
inline Vec3 load_vec3(const Vec3Array& a, std::int64_t i) {
    if constexpr (layouts == Layouts::kInterleaved) {
        Vec3 v;
        load_interleaved(a.data + 3 * i, v.x, v.y, v.z);
        return v;
    } else if constexpr (layouts == Layouts::kRows) {
        return {Floats::load_unaligned(a.data + i), Floats::load_unaligned(a.data + a.row_stride + i),
                Floats::load_unaligned(a.data + 2 * a.row_stride + i)};
    }
    switch (a.layout) {
        case Vec3Layout::kInterleaved: {
            Vec3 v;
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

template <Layouts layouts = Layouts::kMixed>
inline void store_rgb(const MutableVec3Array& a, std::int64_t i, const Rgb& c) {
    if (layouts == Layouts::kInterleaved || (layouts == Layouts::kMixed && a.layout == Vec3Layout::kInterleaved)) {
        store_interleaved(a.data + 3 * i, c.r, c.g, c.b);
    } else {
        c.r.store_unaligned(a.data + i);
        c.g.store_unaligned(a.data + a.row_stride + i);
        c.b.store_unaligned(a.data + 2 * a.row_stride + i);
    }
}

// ---------------------------------------------------------------- checks

// SPEC §7: squared length within [lowest, highest]; a NaN fails both
// comparisons and an infinity the second.
inline Mask unit_length(const Vec3& w, float lowest, float highest) {
    const Floats length2 = w.x * w.x + w.y * w.y + w.z * w.z;
    return (length2 >= Floats(lowest)) & (length2 <= Floats(highest));
}

inline bool unit_length(const Vec3Array& a, std::int64_t i, float lowest, float highest) {
    const float* p = a.layout == Vec3Layout::kSingle ? a.data : a.layout == Vec3Layout::kRows ? a.data + i : a.data + 3 * i;
    const std::int64_t stride = a.layout == Vec3Layout::kRows ? a.row_stride : 1;
    const float length2 = p[0] * p[0] + p[stride] * p[stride] + p[2 * stride] * p[2 * stride];
    return length2 >= lowest && length2 <= highest;
}

inline std::int64_t first_bad_direction(const Vec3Array& directions, std::int64_t begin, std::int64_t end,
                                        float lowest, float highest) {
    std::int64_t i = begin;
    while (i + kLanes <= end && xsimd::all(unit_length(load_vec3(directions, i), lowest, highest))) i += kLanes;
    for (; i < end; ++i)
        if (!unit_length(directions, i, lowest, highest)) return i;
    return -1;
}

// ---------------------------------------------------------------- the loop

template <Model model, Output output, Layouts layouts>
inline void eval_batch(const EvalJob& job, std::int64_t i, const Vec3& wi, const Vec3& wo, const Shading& s) {
    const LobeValues lobes = eval_lobes<model>(wi, wo, s);

    // f = 0 unless both directions are strictly above the surface (SPEC §1);
    // select also discards whatever the formulas gave there (H may be 0).
    const Mask above = (wi.z > Floats(0.0f)) & (wo.z > Floats(0.0f)) & lobes.finite_half_vector;
    const Floats weight = job.cosine ? wi.z : Floats(1.0f);
    auto masked = [&](const Rgb& c) {
        return Rgb{xsimd::select(above, weight * c.r, Floats(0.0f)), xsimd::select(above, weight * c.g, Floats(0.0f)),
                   xsimd::select(above, weight * c.b, Floats(0.0f))};
    };
    const Rgb clearcoat{lobes.clearcoat, lobes.clearcoat, lobes.clearcoat};
    if constexpr (output == Output::kLobes) {
        store_rgb<layouts>(job.out[0], i, masked(lobes.diffuse));
        store_rgb<layouts>(job.out[1], i, masked(lobes.sheen));
        store_rgb<layouts>(job.out[2], i, masked(lobes.specular));
        store_rgb<layouts>(job.out[3], i, masked(clearcoat));
    } else {
        store_rgb<layouts>(job.out[0], i, masked(lobes.diffuse + lobes.sheen + lobes.specular + clearcoat));
    }
}

// One batch at i; false, with nothing stored, when the fused direction check fails.
template <Model model, Output output, bool per_element, Layouts layouts>
inline bool process_batch(const EvalJob& job, std::int64_t i, const Shading& uniform) {
    const Vec3 wi = load_vec3<layouts>(job.wi, i);
    const Vec3 wo = load_vec3<layouts>(job.wo, i);
    if (job.check_directions) {
        const Mask ok = unit_length(wi, job.length2_lowest, job.length2_highest) &
                        unit_length(wo, job.length2_lowest, job.length2_highest);
        if (!xsimd::all(ok)) return false;
    }
    if constexpr (per_element) {
        eval_batch<model, output, layouts>(job, i, wi, wo, shading_of(load_material(job, i)));
    } else {
        eval_batch<model, output, layouts>(job, i, wi, wo, uniform);
    }
    return true;
}

inline std::int64_t first_bad_pair(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    for (std::int64_t i = begin; i < end; ++i)
        if (!unit_length(job.wi, i, job.length2_lowest, job.length2_highest) ||
            !unit_length(job.wo, i, job.length2_lowest, job.length2_highest))
            return i;
    return -1;
}

// The last count < kLanes elements go through padded copies, so the main loop
// never reads or writes past the end and every element sees the same code.
template <Model model, Output output, bool per_element>
bool eval_tail(const EvalJob& job, std::int64_t begin, std::int64_t count, const Shading& uniform) {
    alignas(64) float wi[3 * kLanes], wo[3 * kLanes];
    alignas(64) float params[kParamSlots][3 * kLanes];
    alignas(64) float out[kLobeCount][3 * kLanes];

    EvalJob padded = job;
    auto copy_vec3 = [&](const Vec3Array& from, float* to) {
        if (from.layout == Vec3Layout::kSingle) return from;
        for (std::int64_t j = 0; j < kLanes; ++j) {
            const std::int64_t e = begin + (j < count ? j : count - 1);  // repeat the last element
            for (int k = 0; k < 3; ++k)
                to[3 * j + k] = from.layout == Vec3Layout::kInterleaved ? from.data[3 * e + k]
                                                                        : from.data[k * from.row_stride + e];
        }
        return Vec3Array{to, Vec3Layout::kInterleaved, 0};
    };
    padded.wi = copy_vec3(job.wi, wi);
    padded.wo = copy_vec3(job.wo, wo);
    for (int s = 0; s < kParamSlots; ++s) {
        const ParamSlot& slot = job.params[s];
        if (!slot.per_element()) continue;
        if (slot.stride == 3) {
            // Interleaved base_color: the R slot's copy holds all three channels.
            padded.params[s].data = params[kBaseColorR] + (s - kBaseColorR);
            if (s != kBaseColorR) continue;
        } else {
            padded.params[s].data = params[s];
        }
        for (std::int64_t j = 0; j < kLanes; ++j) {
            const std::int64_t e = begin + (j < count ? j : count - 1);
            for (int c = 0; c < slot.stride; ++c) params[s][j * slot.stride + c] = slot.data[e * slot.stride + c];
        }
    }
    const int outputs = output == Output::kLobes ? kLobeCount : 1;
    for (int k = 0; k < outputs; ++k) padded.out[k] = MutableVec3Array{out[k], Vec3Layout::kInterleaved, 0};

    if (!process_batch<model, output, per_element, Layouts::kInterleaved>(padded, 0, uniform)) return false;

    for (int k = 0; k < outputs; ++k) {
        const MutableVec3Array& to = job.out[k];
        for (std::int64_t j = 0; j < count; ++j) {
            for (int c = 0; c < 3; ++c) {
                const std::int64_t index = to.layout == Vec3Layout::kInterleaved ? 3 * (begin + j) + c
                                                                                 : c * to.row_stride + begin + j;
                to.data[index] = out[k][3 * j + c];
            }
        }
    }
    return true;
}

template <Model model, Output output, bool per_element, Layouts layouts>
std::int64_t eval_loop(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    Shading uniform{};
    if constexpr (!per_element) uniform = shading_of(load_material(job, 0));
    std::int64_t i = begin;
    for (; i + kLanes <= end; i += kLanes)
        if (!process_batch<model, output, per_element, layouts>(job, i, uniform)) return first_bad_pair(job, i, i + kLanes);
    if (i < end && !eval_tail<model, output, per_element>(job, i, end - i, uniform)) return first_bad_pair(job, i, end);
    return -1;
}

inline Layouts layouts_of(const EvalJob& job) {
    const int outputs = job.output == Output::kLobes ? kLobeCount : 1;
    for (Vec3Layout layout : {Vec3Layout::kInterleaved, Vec3Layout::kRows}) {
        bool all = job.wi.layout == layout && job.wo.layout == layout;
        for (int k = 0; k < outputs; ++k) all = all && job.out[k].layout == layout;
        if (all) return layout == Vec3Layout::kInterleaved ? Layouts::kInterleaved : Layouts::kRows;
    }
    return Layouts::kMixed;
}

template <Model model, Output output, bool per_element>
std::int64_t eval_range_for(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    switch (layouts_of(job)) {
        case Layouts::kInterleaved:
            return eval_loop<model, output, per_element, Layouts::kInterleaved>(job, begin, end);
        case Layouts::kRows:
            return eval_loop<model, output, per_element, Layouts::kRows>(job, begin, end);
        default:
            return eval_loop<model, output, per_element, Layouts::kMixed>(job, begin, end);
    }
}

template <Model model, Output output>
std::int64_t eval_range_for(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    return job.uniform_material() ? eval_range_for<model, output, false>(job, begin, end)
                                  : eval_range_for<model, output, true>(job, begin, end);
}

inline std::int64_t eval_range(const EvalJob& job, std::int64_t begin, std::int64_t end) {
    const bool lobes = job.output == Output::kLobes;
    if (job.model == Model::kDisney2012) {
        return lobes ? eval_range_for<Model::kDisney2012, Output::kLobes>(job, begin, end)
                     : eval_range_for<Model::kDisney2012, Output::kTotal>(job, begin, end);
    }
    return lobes ? eval_range_for<Model::kDisney2014, Output::kLobes>(job, begin, end)
                 : eval_range_for<Model::kDisney2014, Output::kTotal>(job, begin, end);
}

}  // namespace principled_brdf::kernel::PRINCIPLED_BRDF_ARCH_NS
