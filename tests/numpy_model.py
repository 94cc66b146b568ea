"""An independent float64 numpy transcription of docs/model.md, "The model" (the third implementation).

Written from docs/model.md, "The model" and Disney's BRDF Explorer shader ``disney.brdf``,
not from ``reference.hpp``: a slip in either shows up against the other.

Materials are given as a mapping ``name -> value`` (numbers or arrays, as in
docs/model.md, "The model"; ``base_color`` of shape ``(3,)`` or ``(..., 3)``) or as anything with
an ``as_dict()`` method (e.g. :class:`principled_brdf.Material`). Everything
broadcasts numpy-style against the directions' leading shape.

The only departure from the literal formulas: the GTR1 denominator
``1 + (ac² - 1) cos²θh`` is written ``ac² cos²θh + sin²θh`` with both terms taken
from the unnormalised ``H = wi + wo``, because for ``ac = 0.001`` the literal
form cancels catastrophically near ``cos θh = 1``.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

MODELS = ("disney2014", "disney2012")
SMALLEST_TINTED_LUMINANCE = 2.0 ** -126  # below it Ctint = 1 (float32 cannot hold 1/Cdlum)

DEFAULTS = {
    "base_color": (0.82, 0.67, 0.16),
    "metallic": 0.0,
    "subsurface": 0.0,
    "specular": 0.5,
    "specular_tint": 0.0,
    "roughness": 0.5,
    "anisotropic": 0.0,
    "sheen": 0.0,
    "sheen_tint": 0.5,
    "clearcoat": 0.0,
    "clearcoat_gloss": 1.0,
}


class Lobes(NamedTuple):
    diffuse: np.ndarray  # (1/π) mix(Fd, ss, subsurface) base_color (1 - metallic)
    sheen: np.ndarray  # Fsheen (1 - metallic)
    specular: np.ndarray  # Gs Fs Ds
    clearcoat: np.ndarray  # 0.25 clearcoat Gr Fr Dr, grey

    def total(self) -> np.ndarray:
        return self.diffuse + self.sheen + self.specular + self.clearcoat


def mix(a, b, t):
    """a + (b - a) t, written a (1 - t) + b t: the same number, without the loss of
    b's digits when b << a and t -> 1 (e.g. a saturated color's Ctint at tint 1)."""
    return a * (1.0 - t) + b * t


def schlick(u):
    m = np.clip(1.0 - u, 0.0, 1.0)
    return m**5


def _as_float(x) -> np.ndarray:
    """float64, or wider if given (np.longdouble lets a test check the float64 rounding)."""
    x = np.asarray(x)
    return x.astype(np.result_type(x.dtype, np.float64), copy=False)


def _params(material) -> dict:
    if hasattr(material, "as_dict"):
        # (the 2015 models' parameters, which this model does not read, at their defaults 0)
        material = {k: v for k, v in material.as_dict().items()
                    if not (k in ("spec_trans", "flatness", "diff_trans") and not np.any(v))}
    unknown = set(material) - set(DEFAULTS)
    if unknown:
        raise KeyError(f"unknown parameters {sorted(unknown)}")
    out = {}
    for name, default in DEFAULTS.items():
        out[name] = _as_float(material.get(name, default))
    return out


def _scalar(p):
    """A per-element scalar parameter with a trailing axis, ready to scale RGB."""
    return p[..., None]


def eval_lobes(material, wi, wo, model: str = "disney2014") -> Lobes:
    """The four lobes of docs/model.md, "The model" as float64 ``(..., 3)`` arrays."""
    return _evaluate(material, wi, wo, model)[0]


def schlick_fractions(material, wi, wo, model: str = "disney2014") -> Lobes:
    """For each lobe, the fraction of its value carried by its FH = Schlick(cos θd) term.

    Used by the tests to bound the float64 conditioning of ``(1 - cos θd)^5`` as
    ``cos θd -> 1``: a relative error r in FH moves a lobe by r times this fraction.
    Diffuse 0; sheen 1; specular |1 - Cspec0| FH / Fs; clearcoat 0.96 FH / Fr.
    """
    return _evaluate(material, wi, wo, model)[1]


def _evaluate(material, wi, wo, model):
    if model not in MODELS:
        raise ValueError(model)
    p = _params(material)
    wi = _as_float(wi)
    wo = _as_float(wo)

    base = p["base_color"]
    metallic = _scalar(p["metallic"])
    subsurface = p["subsurface"]
    specular = _scalar(p["specular"])
    specular_tint = _scalar(p["specular_tint"])
    roughness = p["roughness"]
    anisotropic = p["anisotropic"]
    sheen = _scalar(p["sheen"])
    sheen_tint = _scalar(p["sheen_tint"])
    clearcoat = p["clearcoat"]
    clearcoat_gloss = p["clearcoat_gloss"]

    cos_l = wi[..., 2]  # n·wi, n = z
    cos_v = wo[..., 2]  # n·wo
    upper = (cos_l > 0.0) & (cos_v > 0.0)

    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        H = wi + wo
        H2 = np.sum(H * H, axis=-1)
        h = H / np.sqrt(H2)[..., None]
        cos_h = h[..., 2]
        cos_d = np.sum(wi * h, axis=-1)  # = wo·h
        # cos²θh and sin²θh from the unnormalised H, for GTR1 (nothing cancels)
        cos2_h = H[..., 2] ** 2 / H2
        sin2_h = (H[..., 0] ** 2 + H[..., 1] ** 2) / H2

        # Colors; Ctint = base / Cdlum, 1 where Cdlum < 2^-126 (float32's smallest normal number)
        cd_lum = 0.3 * base[..., 0] + 0.6 * base[..., 1] + 0.1 * base[..., 2]
        tinted = cd_lum >= SMALLEST_TINTED_LUMINANCE
        c_tint = np.where(_scalar(tinted), base / np.where(tinted, cd_lum, 1.0)[..., None], 1.0)
        c_spec0 = mix(specular * 0.08 * mix(1.0, c_tint, specular_tint), base, metallic)
        c_sheen = mix(1.0, c_tint, sheen_tint)

        FL = schlick(cos_l)
        FV = schlick(cos_v)
        FH = schlick(cos_d)

        # Diffuse with retro-reflection
        fd90 = 0.5 + 2.0 * roughness * cos_d**2
        Fd = mix(1.0, fd90, FL) * mix(1.0, fd90, FV)
        # Hanrahan-Krueger-like subsurface
        fss90 = roughness * cos_d**2
        Fss = mix(1.0, fss90, FL) * mix(1.0, fss90, FV)
        ss = 1.25 * (Fss * (1.0 / (cos_l + cos_v) - 0.5) + 0.5)
        diffuse = _scalar((1.0 / np.pi) * mix(Fd, ss, subsurface)) * base * (1.0 - metallic)

        # Sheen
        sheen_lobe = _scalar(FH) * sheen * c_sheen * (1.0 - metallic)

        # Primary specular: anisotropic GTR2, Schlick Fresnel, separable Smith G
        aspect = np.sqrt(1.0 - 0.9 * anisotropic)
        ax = np.maximum(0.001, roughness**2 / aspect)
        ay = np.maximum(0.001, roughness**2 * aspect)
        Ds = 1.0 / (np.pi * ax * ay * ((h[..., 0] / ax) ** 2 + (h[..., 1] / ay) ** 2 + cos_h**2) ** 2)
        Fs = mix(c_spec0, 1.0, _scalar(FH))
        if model == "disney2014":

            def S(w):
                return 1.0 / (w[..., 2] + np.sqrt((w[..., 0] * ax) ** 2 + (w[..., 1] * ay) ** 2 + w[..., 2] ** 2))

            Gs = S(wi) * S(wo)
        else:
            alpha_g = (0.5 + roughness / 2.0) ** 2
            Gs = smith_iso(cos_l, alpha_g) * smith_iso(cos_v, alpha_g)
        specular_lobe = _scalar(Gs * Ds) * Fs

        # Clearcoat: GTR1 with the cancellation-free denominator
        ac = mix(0.1, 0.001, clearcoat_gloss)
        ac2 = ac * ac
        Dr = np.where(
            ac >= 1.0,
            1.0 / np.pi,
            (ac2 - 1.0) / (np.pi * np.log(ac2) * (ac2 * cos2_h + sin2_h)),
        )
        Fr = mix(0.04, 1.0, FH)
        Gr = smith_iso(cos_l, 0.25) * smith_iso(cos_v, 0.25)
        clearcoat_lobe = 0.25 * clearcoat * Gr * Fr * Dr
        clearcoat_lobe = np.repeat(clearcoat_lobe[..., None], 3, axis=-1)

        fractions = (
            np.zeros(3),
            np.ones(3),
            # Fs = 0 only when Cspec0 = 0 and FH = 0: the lobe is all FH
            np.where(Fs > 0.0, np.abs(1.0 - c_spec0) * _scalar(FH) / np.where(Fs > 0.0, Fs, 1.0), 1.0),
            np.repeat((0.96 * FH / Fr)[..., None], 3, axis=-1),
        )

    lobes = (diffuse, sheen_lobe, specular_lobe, clearcoat_lobe)
    shape = np.broadcast_shapes(*(lobe.shape for lobe in lobes), *(f.shape for f in fractions))
    mask = upper[..., None]
    return (
        Lobes(*(np.where(mask, np.broadcast_to(lobe, shape), 0.0) for lobe in lobes)),
        Lobes(*(np.where(mask, np.broadcast_to(f, shape), 0.0) for f in fractions)),
    )


def smith_iso(cos_w, g):
    """Siso(w, g) = 1 / (n·w + sqrt(g² + (n·w)² - g² (n·w)²)) (already holds 1/(2 n·w))."""
    g2 = g * g
    c2 = cos_w * cos_w
    return 1.0 / (cos_w + np.sqrt(g2 + c2 - g2 * c2))


def eval(material, wi, wo, model: str = "disney2014", cosine: bool = False) -> np.ndarray:
    """f(wi, wo) of docs/model.md, "The model" in 1/sr, float64 ``(..., 3)``; times cos θl if ``cosine``."""
    f = eval_lobes(material, wi, wo, model).total()
    if cosine:
        f = f * np.maximum(np.asarray(wi, dtype=np.float64)[..., 2:3], 0.0)
    return f
