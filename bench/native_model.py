"""The Disney 2014 BRDF (docs/model.md, "The model", model="disney2014") written
once over a framework's array operations, for the native PyTorch and JAX
versions that bench/interop_speed.py times beside the library's operations.

``f(ops, material, wi, wo)``: ``material`` maps the parameter names of
docs/model.md to arrays of the framework (0-d for one value, ``(N,)`` per
element; ``base_color`` ``(3,)`` or ``(N, 3)``), ``wi`` and ``wo`` are ``(N, 3)``;
the result is ``(N, 3)``. ``ops`` supplies the few operations whose names
differ between the frameworks. The GTR1 denominator is written from the
unnormalized half vector (docs/model.md, "Numerics"), as the library does.
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

# The 13 slots of the parameter table, in pb.eval_grad's order.
SLOTS = ("base_color_r", "base_color_g", "base_color_b", "metallic", "subsurface", "specular", "specular_tint",
         "roughness", "anisotropic", "sheen", "sheen_tint", "clearcoat", "clearcoat_gloss")

SMALLEST_TINTED_LUMINANCE = 2.0**-126


class Ops(NamedTuple):
    sqrt: Any
    log: Any
    where: Any  # where(condition, array, array or number)
    clip01: Any  # clamp to [0, 1]
    at_least: Any  # at_least(x, number): max(x, number)


def material_of_slots(slots: Any) -> dict[str, Any]:
    """A material from an array ``(..., 13)`` of the slots (SLOTS' order)."""
    material = {"base_color": slots[..., 0:3]}
    for k, name in enumerate(SLOTS[3:], start=3):
        material[name] = slots[..., k]
    return material


def f(ops: Ops, material: dict[str, Any], wi: Any, wo: Any) -> Any:
    def mix(a: Any, b: Any, t: Any) -> Any:
        return a + (b - a) * t

    def schlick(u: Any) -> Any:
        return ops.clip01(1.0 - u) ** 5

    def rgb(p: Any) -> Any:  # a scalar parameter scaling a color
        return p[..., None]

    base = material["base_color"]
    metallic = material["metallic"]
    roughness = material["roughness"]
    lx, ly, lz = wi[..., 0], wi[..., 1], wi[..., 2]
    vx, vy, vz = wo[..., 0], wo[..., 1], wo[..., 2]
    hx, hy, hz = lx + vx, ly + vy, lz + vz
    h_norm2 = hx * hx + hy * hy + hz * hz
    h_norm = ops.sqrt(h_norm2)
    cos_h = hz / h_norm
    cos_d = (lx * hx + ly * hy + lz * hz) / h_norm

    cd_lum = 0.3 * base[..., 0] + 0.6 * base[..., 1] + 0.1 * base[..., 2]
    tinted = cd_lum >= SMALLEST_TINTED_LUMINANCE
    c_tint = ops.where(rgb(tinted), base / rgb(ops.where(tinted, cd_lum, 1.0)), 1.0)
    c_spec0 = mix(rgb(material["specular"]) * 0.08 * mix(1.0, c_tint, rgb(material["specular_tint"])), base,
                  rgb(metallic))
    c_sheen = mix(1.0, c_tint, rgb(material["sheen_tint"]))
    fl, fv, fh = schlick(lz), schlick(vz), schlick(cos_d)

    fd90 = 0.5 + 2.0 * roughness * cos_d * cos_d
    fd = mix(1.0, fd90, fl) * mix(1.0, fd90, fv)
    fss90 = roughness * cos_d * cos_d
    fss = mix(1.0, fss90, fl) * mix(1.0, fss90, fv)
    ss = 1.25 * (fss * (1.0 / (lz + vz) - 0.5) + 0.5)
    diffuse = rgb((1.0 / math.pi) * mix(fd, ss, material["subsurface"])) * base
    sheen = rgb(fh * material["sheen"]) * c_sheen

    aspect = ops.sqrt(1.0 - 0.9 * material["anisotropic"])
    ax = ops.at_least(roughness * roughness / aspect, 0.001)
    ay = ops.at_least(roughness * roughness * aspect, 0.001)
    tx, ty = hx / (h_norm * ax), hy / (h_norm * ay)
    ds = 1.0 / (math.pi * ax * ay * (tx * tx + ty * ty + cos_h * cos_h) ** 2)
    gs = 1.0 / ((lz + ops.sqrt((lx * ax) ** 2 + (ly * ay) ** 2 + lz * lz))
                * (vz + ops.sqrt((vx * ax) ** 2 + (vy * ay) ** 2 + vz * vz)))
    specular = rgb(gs * ds) * mix(c_spec0, 1.0, rgb(fh))

    ac = mix(0.1, 0.001, material["clearcoat_gloss"])
    ac2 = ac * ac
    dr = (ac2 - 1.0) / (math.pi * ops.log(ac2) * (ac2 * hz * hz + hx * hx + hy * hy) / h_norm2)
    gr = 1.0 / ((lz + ops.sqrt(0.0625 + lz * lz - 0.0625 * lz * lz)) * (vz + ops.sqrt(0.0625 + vz * vz - 0.0625 * vz * vz)))
    clearcoat = 0.25 * material["clearcoat"] * gr * mix(0.04, 1.0, fh) * dr

    value = (diffuse + sheen) * rgb(1.0 - metallic) + specular + rgb(clearcoat)
    return ops.where(rgb((lz > 0.0) & (vz > 0.0)), value, 0.0)
