#include "native_loop.hpp"

#include <algorithm>
#include <cmath>

namespace principled_brdf::bench {
namespace {

constexpr float kPi = 3.14159265358979f;

inline float schlick(float u) {
    const float m = std::min(std::max(1.0f - u, 0.0f), 1.0f);
    return m * m * m * m * m;
}

inline float mixf(float a, float b, float t) { return a + (b - a) * t; }

struct Constants {
    float diffuse[3], sheen[3], f0[3];
    float subsurface, roughness, inv_ax2, inv_ay2, ax2, ay2, ggx_norm, clearcoat_scale, ac2;
};

Constants constants_of(const NativeMaterial& m) {
    Constants c;
    const float lum = 0.3f * m.base_color[0] + 0.6f * m.base_color[1] + 0.1f * m.base_color[2];
    for (int k = 0; k < 3; ++k) {
        const float tint = lum > 0 ? m.base_color[k] / lum : 1.0f;
        c.diffuse[k] = m.base_color[k] * (1 - m.metallic) / kPi;
        c.sheen[k] = m.sheen * (1 - m.metallic) * mixf(1, tint, m.sheen_tint);
        c.f0[k] = mixf(m.specular * 0.08f * mixf(1, tint, m.specular_tint), m.base_color[k], m.metallic);
    }
    const float aspect = std::sqrt(1 - 0.9f * m.anisotropic);
    const float ax = std::max(0.001f, m.roughness * m.roughness / aspect);
    const float ay = std::max(0.001f, m.roughness * m.roughness * aspect);
    c.subsurface = m.subsurface;
    c.roughness = m.roughness;
    c.ax2 = ax * ax;
    c.ay2 = ay * ay;
    c.inv_ax2 = 1 / c.ax2;
    c.inv_ay2 = 1 / c.ay2;
    c.ggx_norm = 1 / (kPi * ax * ay);
    const float ac = mixf(0.1f, 0.001f, m.clearcoat_gloss);
    c.ac2 = ac * ac;
    c.clearcoat_scale = 0.25f * m.clearcoat * (c.ac2 - 1) / (kPi * std::log(c.ac2));
    return c;
}

inline void eval_one(const Constants& c, float lx, float ly, float lz, float vx, float vy, float vz, float out[3]) {
    const float hx = lx + vx, hy = ly + vy, hz = lz + vz;
    const float len2 = hx * hx + hy * hy + hz * hz;
    const float cos_d = (lx * hx + ly * hy + lz * hz) / std::sqrt(len2);
    const float cos2_d = cos_d * cos_d;
    const float fl = schlick(lz), fv = schlick(vz), fh = schlick(cos_d);
    const float fd90 = 0.5f + 2 * c.roughness * cos2_d;
    const float fd = mixf(1, fd90, fl) * mixf(1, fd90, fv);
    const float fss90 = c.roughness * cos2_d;
    const float fss = mixf(1, fss90, fl) * mixf(1, fss90, fv);
    const float ss = 1.25f * (fss * (1 / (lz + vz) - 0.5f) + 0.5f);
    const float diffuse = mixf(fd, ss, c.subsurface);
    const float ds_root = len2 / (hx * hx * c.inv_ax2 + hy * hy * c.inv_ay2 + hz * hz);
    const float ds = c.ggx_norm * ds_root * ds_root;
    const float gs = 1 / (lz + std::sqrt(c.ax2 * lx * lx + c.ay2 * ly * ly + lz * lz)) /
                     (vz + std::sqrt(c.ax2 * vx * vx + c.ay2 * vy * vy + vz * vz));
    const float dr = len2 / (c.ac2 * hz * hz + hx * hx + hy * hy);
    const float gr = 1 / (lz + std::sqrt(0.0625f + 0.9375f * lz * lz)) / (vz + std::sqrt(0.0625f + 0.9375f * vz * vz));
    const float clearcoat = c.clearcoat_scale * gr * (0.04f + 0.96f * fh) * dr;
    const bool above = lz > 0 && vz > 0;
    for (int k = 0; k < 3; ++k) {
        const float f = diffuse * c.diffuse[k] + fh * c.sheen[k] + gs * ds * mixf(c.f0[k], 1, fh) + clearcoat;
        out[k] = above ? f : 0.0f;
    }
}

}  // namespace

void native_eval_interleaved(const NativeMaterial& m, const float* __restrict wi, const float* __restrict wo,
                             float* __restrict out, std::int64_t n) {
    const Constants c = constants_of(m);
    for (std::int64_t i = 0; i < n; ++i)
        eval_one(c, wi[3 * i], wi[3 * i + 1], wi[3 * i + 2], wo[3 * i], wo[3 * i + 1], wo[3 * i + 2], out + 3 * i);
}

void native_eval_rows(const NativeMaterial& m, const float* __restrict wi, const float* __restrict wo,
                      float* __restrict out, std::int64_t n) {
    const Constants c = constants_of(m);
    for (std::int64_t i = 0; i < n; ++i) {
        float f[3];
        eval_one(c, wi[i], wi[n + i], wi[2 * n + i], wo[i], wo[n + i], wo[2 * n + i], f);
        out[i] = f[0];
        out[n + i] = f[1];
        out[2 * n + i] = f[2];
    }
}

}  // namespace principled_brdf::bench
