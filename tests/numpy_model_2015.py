"""An independent float64 transcription of the 2015 BSDF (Burley 2015): the
solid model ``disney2015`` and the thin sheet ``disney2015_thin`` as the
repository's docs state them (docs/model-2015.md), written from the equations
in numpy and never from the C++ code. The library's float64 reference and its
kernels are held to it; its own properties (reciprocity, the energy bound,
the limits) are checked in tests/model/test_numpy_model_2015_properties.py.

Conventions: local frame, n = (0, 0, 1); wi towards the light, wo towards the
viewer, both unit, anywhere on the sphere; the outside is the side of n (index
1), the inside has index η. f excludes the cosine. Radiance mode unless
``mode="importance"``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

PI = np.pi

DEFAULTS = {
    "base_color": (0.82, 0.67, 0.16), "metallic": 0.0, "specular": 0.5, "specular_tint": 0.0, "roughness": 0.5,
    "anisotropic": 0.0, "sheen": 0.0, "sheen_tint": 0.5, "clearcoat": 0.0, "clearcoat_gloss": 1.0,
    "spec_trans": 0.0, "diff_trans": 0.0, "flatness": 0.0,
}
SMALLEST_TINTED_LUMINANCE = 2.0**-126


class Lobes(NamedTuple):
    diffuse: np.ndarray
    sheen: np.ndarray
    specular: np.ndarray
    clearcoat: np.ndarray
    transmission: np.ndarray
    diffuse_transmission: np.ndarray

    def total(self) -> np.ndarray:
        return sum(self[1:], self[0])


def eta_of_specular(specular):
    """((η - 1)/(η + 1))² = 0.08 specular, at least 1.001."""
    return np.maximum(2.0 / (1.0 - np.sqrt(0.08 * np.asarray(specular, float))) - 1.0, 1.001)


def schlick(u):
    return np.clip(1.0 - u, 0.0, 1.0) ** 5


def fresnel_dielectric(cos_i, eta):
    """Exact unpolarised reflectance, Walter et al. 2007 eq. 22 in its g form."""
    c = np.abs(cos_i)
    g2 = eta**2 - 1.0 + c**2
    g = np.sqrt(np.maximum(g2, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        a = (g - c) / (g + c)
        b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0)
        f = 0.5 * a * a * (1.0 + b * b)
    return np.where(g2 <= 0.0, 1.0, f)


def _p(params, name, n):
    value = np.asarray(params.get(name, DEFAULTS[name]), float)
    return np.broadcast_to(value, (n, 3) if name == "base_color" else (n,))


def _alphas(roughness, anisotropic):
    aspect = np.sqrt(1.0 - 0.9 * anisotropic)
    return np.maximum(0.001, roughness**2 / aspect), np.maximum(0.001, roughness**2 * aspect)


def _ggx_d(h, ax, ay):
    """h unit with h·n > 0."""
    return 1.0 / (PI * ax * ay * ((h[:, 0] / ax) ** 2 + (h[:, 1] / ay) ** 2 + h[:, 2] ** 2) ** 2)


def _smith_s(w, ax, ay):
    """S(w) = G1(w) / (2 |n·w|) = 1 / (|n·w| + sqrt((w·x ax)² + (w·y ay)² + (n·w)²))."""
    c = np.abs(w[:, 2])
    return 1.0 / (c + np.sqrt((w[:, 0] * ax) ** 2 + (w[:, 1] * ay) ** 2 + c * c))


def _ggx_g1(w, ax, ay):
    """G1 = 1 / (1 + Λ), Λ = (-1 + sqrt(1 + (ax² wx² + ay² wy²) / wz²)) / 2, at |cos|."""
    lam = 0.5 * (-1.0 + np.sqrt(1.0 + ((ax * w[:, 0]) ** 2 + (ay * w[:, 1]) ** 2) / w[:, 2] ** 2))
    return 1.0 / (1.0 + lam)


def _gtr1(cos_h, a):
    a2 = a * a
    return np.where(a >= 1.0, 1.0 / PI, (a2 - 1.0) / (PI * np.log(a2) * (1.0 + (a2 - 1.0) * cos_h**2)))


def _siso(c, g):
    c = np.abs(c)
    return 1.0 / (c + np.sqrt(g * g + c * c - g * g * c * c))


def _mirror(w):
    return w * np.array([1.0, 1.0, -1.0])


def _unit(v):
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _colors(p):
    c = p["base_color"]
    lum = 0.3 * c[:, 0] + 0.6 * c[:, 1] + 0.1 * c[:, 2]
    tinted = lum >= SMALLEST_TINTED_LUMINANCE
    tint = np.where(tinted[:, None], c / np.where(tinted, lum, 1.0)[:, None], 1.0)
    sheen_color = (1.0 - p["sheen_tint"])[:, None] + tint * p["sheen_tint"][:, None]
    return tint, sheen_color


def _reflection_outside(p, wi, wo, thin):
    """The lobes with both directions outside (cos θl, cos θv > 0); thin: the sheet's (1 - dt) split."""
    n = len(wi)
    c, m, st, r = p["base_color"], p["metallic"], p["spec_trans"], p["roughness"]
    eta = eta_of_specular(p["specular"])
    tint, sheen_color = _colors(p)
    h = _unit(wi + wo)
    cos_l, cos_v, cos_d = wi[:, 2], wo[:, 2], np.sum(wi * h, axis=1)
    fl, fv, fh = schlick(cos_l), schlick(cos_v), schlick(cos_d)
    w_d = (1.0 - m) * (1.0 - st)
    dt = p["diff_trans"] / 2.0 if thin else np.zeros(n)

    f_lambert = (1.0 - fl / 2.0) * (1.0 - fv / 2.0)
    rr = 2.0 * r * cos_d**2
    f_retro = rr * (fl + fv + fl * fv * (rr - 1.0))
    fss90 = r * cos_d**2
    fss = (1.0 + (fss90 - 1.0) * fl) * (1.0 + (fss90 - 1.0) * fv)
    f_hk = 1.25 * (fss * (1.0 / (cos_l + cos_v) - 0.5) + 0.5)
    flat = p["flatness"]
    diffuse_shape = (1.0 - flat) * f_lambert + flat * f_hk + f_retro
    diffuse = (w_d * (1.0 - dt) * diffuse_shape / PI)[:, None] * c
    sheen = (w_d * (1.0 - dt) * fh * p["sheen"])[:, None] * sheen_color

    ax, ay = _alphas(r, p["anisotropic"])
    ds_gs = _ggx_d(h, ax, ay) * _smith_s(wi, ax, ay) * _smith_s(wo, ax, ay)
    f0_tint = (0.08 * p["specular"])[:, None] * tint
    tinted = f0_tint + (1.0 - f0_tint) * fh[:, None]
    metal = c + (1.0 - c) * fh[:, None]
    st_ = p["specular_tint"][:, None]
    fresnel = ((1.0 - m)[:, None] * ((1.0 - st_) * fresnel_dielectric(cos_d, eta)[:, None] + st_ * tinted)
               + m[:, None] * metal)
    specular = fresnel * ds_gs[:, None]

    ac = 0.1 + (0.001 - 0.1) * p["clearcoat_gloss"]
    clearcoat = 0.25 * p["clearcoat"] * _siso(cos_l, 0.25) * _siso(cos_v, 0.25) * (0.04 + 0.96 * fh) * _gtr1(h[:, 2], ac)
    zero = np.zeros((n, 3))
    return Lobes(diffuse, sheen, specular, np.repeat(clearcoat[:, None], 3, axis=1), zero, zero)


def _rough_transmission(p, wi, wo, eta_t, importance):
    """Viewer on the side of n, light on the other, η_t the light side's index over the viewer's:
    Walter et al. 2007 eq. 21 (radiance: no η_o² factor since the viewer's index is 1 relative)."""
    c, m, st = p["base_color"], p["metallic"], p["spec_trans"]
    w_t = (1.0 - m) * st
    ax, ay = _alphas(p["roughness"], p["anisotropic"])
    hv = wo + eta_t[:, None] * wi
    hv = hv * np.where(hv[:, 2] < 0.0, -1.0, 1.0)[:, None]
    length = np.linalg.norm(hv, axis=1)
    ok = length > 0.0
    h = hv / np.where(ok, length, 1.0)[:, None]
    wo_h, wi_h = np.sum(wo * h, axis=1), np.sum(wi * h, axis=1)
    sides = ok & (wo_h * wo[:, 2] > 0.0) & (wi_h * wi[:, 2] > 0.0) & (h[:, 2] > 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        value = (w_t * (1.0 - fresnel_dielectric(wo_h, eta_t)) * _ggx_d(h, ax, ay) * _ggx_g1(wo, ax, ay)
                 * _ggx_g1(wi, ax, ay) * np.abs(wo_h) * np.abs(wi_h)
                 / (np.abs(wo[:, 2]) * np.abs(wi[:, 2]) * (wo_h + eta_t * wi_h) ** 2))
    if importance:
        value = value * eta_t**2
    value = np.where(sides, value, 0.0)
    return value[:, None] * np.sqrt(c)


def _solid(p, wi, wo, importance):
    n = len(wi)
    eta = eta_of_specular(p["specular"])
    zero = np.zeros((n, 3))
    lobes = {name: zero.copy() for name in Lobes._fields}
    cos_l, cos_v = wi[:, 2], wo[:, 2]

    outside_refl = (cos_v > 0) & (cos_l > 0)
    if outside_refl.any():
        part = _reflection_outside(_take(p, outside_refl), wi[outside_refl], wo[outside_refl], thin=False)
        for name in Lobes._fields:
            lobes[name][outside_refl] = getattr(part, name)

    outside_trans = (cos_v > 0) & (cos_l < 0)
    if outside_trans.any():
        q = _take(p, outside_trans)
        lobes["transmission"][outside_trans] = _rough_transmission(q, wi[outside_trans], wo[outside_trans],
                                                                   eta[outside_trans], importance)

    # viewer inside: mirror both, η' = 1/η, only the interface weighted by w_T
    inside_refl = (cos_v < 0) & (cos_l < 0)
    if inside_refl.any():
        q = _take(p, inside_refl)
        a, b = _mirror(wi[inside_refl]), _mirror(wo[inside_refl])
        h = _unit(a + b)
        ax, ay = _alphas(q["roughness"], q["anisotropic"])
        w_t = (1.0 - q["metallic"]) * q["spec_trans"]
        value = (w_t * fresnel_dielectric(np.sum(a * h, axis=1), 1.0 / eta[inside_refl]) * _ggx_d(h, ax, ay)
                 * _smith_s(a, ax, ay) * _smith_s(b, ax, ay))
        lobes["specular"][inside_refl] = np.repeat(value[:, None], 3, axis=1)

    inside_trans = (cos_v < 0) & (cos_l > 0)
    if inside_trans.any():
        q = _take(p, inside_trans)
        lobes["transmission"][inside_trans] = _rough_transmission(
            q, _mirror(wi[inside_trans]), _mirror(wo[inside_trans]), 1.0 / eta[inside_trans], importance)
    return Lobes(**lobes)


def _thin(p, wi, wo):
    n = len(wi)
    flip = wo[:, 2] < 0
    wi = np.where(flip[:, None], _mirror(wi), wi)
    wo = np.where(flip[:, None], _mirror(wo), wo)
    zero = np.zeros((n, 3))
    lobes = {name: zero.copy() for name in Lobes._fields}
    cos_l, cos_v = wi[:, 2], wo[:, 2]
    refl = (cos_v > 0) & (cos_l > 0)
    if refl.any():
        part = _reflection_outside(_take(p, refl), wi[refl], wo[refl], thin=True)
        for name in Lobes._fields:
            lobes[name][refl] = getattr(part, name)
    trans = (cos_v > 0) & (cos_l < 0)
    if trans.any():
        q = _take(p, trans)
        a, b = wi[trans], wo[trans]
        a_m = _mirror(a)
        h = _unit(b + a_m)
        eta = eta_of_specular(q["specular"])
        r_t = np.clip((0.65 * eta - 0.35) * q["roughness"], 0.0, 1.0)
        ax, ay = _alphas(r_t, q["anisotropic"])
        c = q["base_color"]
        w_t = (1.0 - q["metallic"]) * q["spec_trans"]
        w_d = (1.0 - q["metallic"]) * (1.0 - q["spec_trans"])
        value = (w_t * (1.0 - fresnel_dielectric(np.sum(b * h, axis=1), eta)) * _ggx_d(h, ax, ay)
                 * _ggx_g1(b, ax, ay) * _ggx_g1(a_m, ax, ay) / (4.0 * np.abs(a[:, 2]) * np.abs(b[:, 2])))
        lobes["transmission"][trans] = value[:, None] * c
        lobes["diffuse_transmission"][trans] = (w_d * q["diff_trans"] / 2.0 / PI)[:, None] * c
    return Lobes(**lobes)


def _take(p, mask):
    return {name: value[mask] for name, value in p.items()}


def eval_lobes(params, wi, wo, model="disney2015", mode="radiance"):
    """Each lobe of f(wi, wo), (N, 3) each, float64."""
    wi, wo = np.atleast_2d(np.asarray(wi, float)), np.atleast_2d(np.asarray(wo, float))
    wi, wo = np.broadcast_arrays(wi, wo)
    n = len(wi)
    p = {name: _p(params, name, n).astype(float) for name in DEFAULTS}
    if model == "disney2015":
        return _solid(p, wi, wo, importance=mode == "importance")
    if model == "disney2015_thin":
        return _thin(p, wi, wo)
    raise ValueError(model)


def eval(params, wi, wo, model="disney2015", mode="radiance", cosine=False):
    f = eval_lobes(params, wi, wo, model, mode).total()
    if cosine:
        f = f * np.abs(np.atleast_2d(wi)[:, 2])[:, None]
    return f
