"""principled_brdf.eval against a straightforward numpy float32 implementation
of the model (docs/model.md, "The model") on the same pairs, both timed in this process (the CLI's ``bench``;
``bench/python_vs_numpy.py`` runs it too)."""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import numpy as np

from ._batch import cpu_info, eval as _eval
from .material import Material

if TYPE_CHECKING:
    from collections.abc import Callable, Mapping
    from typing import Any

    from ._typing import Float32Array

MATERIAL: dict[str, Any] = dict(base_color=(0.82, 0.67, 0.16), metallic=0.2, subsurface=0.3, specular=0.5, specular_tint=0.1,
                roughness=0.4, anisotropic=0.3, sheen=0.2, sheen_tint=0.5, clearcoat=0.5, clearcoat_gloss=0.7)


def numpy_eval(m: Mapping[str, Any], wi: Float32Array, wo: Float32Array) -> Float32Array:
    """The model (disney2014) written the obvious way with float32 numpy arrays."""
    f32 = np.float32
    base = np.asarray(m["base_color"], f32)
    lx, ly, lz = wi[:, 0], wi[:, 1], wi[:, 2]
    vx, vy, vz = wo[:, 0], wo[:, 1], wo[:, 2]
    h = wi + wo
    h /= np.linalg.norm(h, axis=1, keepdims=True)
    cos_h, cos_d = h[:, 2], np.einsum("ij,ij->i", wi, h)

    def schlick(u: Any) -> Any:
        return np.clip(f32(1) - u, 0, 1) ** 5

    fl, fv, fh = schlick(lz), schlick(vz), schlick(cos_d)
    lum = f32(0.3) * base[0] + f32(0.6) * base[1] + f32(0.1) * base[2]
    tint = base / lum if lum >= 2.0 ** -126 else np.ones(3, f32)
    spec0 = (m["specular"] * 0.08 * (1 + (tint - 1) * m["specular_tint"])) * (1 - m["metallic"]) + base * m["metallic"]
    sheen_color = 1 + (tint - 1) * m["sheen_tint"]
    r = f32(m["roughness"])
    fd90 = 0.5 + 2 * r * cos_d**2
    fd = (1 + (fd90 - 1) * fl) * (1 + (fd90 - 1) * fv)
    fss90 = r * cos_d**2
    fss = (1 + (fss90 - 1) * fl) * (1 + (fss90 - 1) * fv)
    ss = 1.25 * (fss * (1 / (lz + vz) - 0.5) + 0.5)
    aspect = np.sqrt(1 - 0.9 * m["anisotropic"])
    ax, ay = f32(max(0.001, r * r / aspect)), f32(max(0.001, r * r * aspect))
    ds = 1 / (np.pi * ax * ay * ((h[:, 0] / ax) ** 2 + (h[:, 1] / ay) ** 2 + cos_h**2) ** 2)
    gs = 1 / (lz + np.sqrt((lx * ax) ** 2 + (ly * ay) ** 2 + lz**2)) / (vz + np.sqrt((vx * ax) ** 2 + (vy * ay) ** 2 + vz**2))
    ac = f32(0.1 + (0.001 - 0.1) * m["clearcoat_gloss"])
    dr = (ac * ac - 1) / (np.pi * np.log(ac * ac) * (1 + (ac * ac - 1) * cos_h**2))
    gr = 1 / (lz + np.sqrt(0.0625 + lz**2 - 0.0625 * lz**2)) / (vz + np.sqrt(0.0625 + vz**2 - 0.0625 * vz**2))
    fr = 0.04 + 0.96 * fh
    diffuse = (1 / np.pi) * (fd + (ss - fd) * m["subsurface"])
    f = (diffuse[:, None] * base + fh[:, None] * m["sheen"] * sheen_color) * (1 - m["metallic"])
    f += (gs * ds)[:, None] * (spec0 + (1 - spec0) * fh[:, None])
    f += (0.25 * m["clearcoat"] * gr * fr * dr)[:, None]
    f[(lz <= 0) | (vz <= 0)] = 0
    return f.astype(f32, copy=False)


def random_pairs(n: int, seed: int = 1) -> tuple[Float32Array, Float32Array]:
    """``n`` random (wi, wo) pairs in the upper hemisphere, float32 (n, 3) each."""
    rng = np.random.default_rng(seed)

    def hemisphere() -> Float32Array:
        v = rng.normal(size=(n, 3)).astype(np.float32)
        v[:, 2] = np.abs(v[:, 2]) + 1e-3
        return v / np.linalg.norm(v, axis=1, keepdims=True)

    return hemisphere(), hemisphere()


def best_seconds(fn: Callable[[], object], repeats: int) -> float:
    """The fastest of ``repeats`` runs of ``fn()``."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def compare_with_numpy(pairs: int = 1 << 22, repeats: int = 5,
                       report: Callable[[str], object] = print) -> dict[str, Any]:
    """Times pb.eval (the default call with a fresh output; out= checked and unchecked) and
    numpy_eval on ``pairs`` pairs."""
    material = Material(**MATERIAL)
    report(f"generating {pairs:,} random pairs ...")
    wi, wo = random_pairs(pairs)
    out = np.empty_like(wi)
    reference = numpy_eval(MATERIAL, wi, wo)
    worst = float(np.max(np.abs(_eval(material, wi, wo) - reference) / np.maximum(np.abs(reference), 1e-3)))
    report(f"timing numpy float32 ({repeats} runs) ...")
    numpy_seconds = best_seconds(lambda: numpy_eval(MATERIAL, wi, wo), repeats)
    report(f"timing pb.eval ({repeats} runs each) ...")
    eval_seconds = best_seconds(lambda: _eval(material, wi, wo), repeats)
    checked_out_seconds = best_seconds(lambda: _eval(material, wi, wo, out=out), repeats)
    unchecked_seconds = best_seconds(lambda: _eval(material, wi, wo, out=out, check=False), repeats)
    info = cpu_info()
    result = {
        "pairs": pairs,
        "isa": info["isa"],
        "threads": info["threads"],
        "numpy_pairs_per_s": pairs / numpy_seconds,
        "eval_pairs_per_s": pairs / eval_seconds,
        "eval_out_pairs_per_s": pairs / checked_out_seconds,
        "eval_unchecked_pairs_per_s": pairs / unchecked_seconds,
        "speedup": numpy_seconds / eval_seconds,
        "speedup_unchecked": numpy_seconds / unchecked_seconds,
        "max_relative_difference": worst,
    }
    report(f"pairs: {pairs:,} ({info['isa']}, {info['threads']} threads)")
    report(f"  numpy float32:                   {result['numpy_pairs_per_s'] / 1e6:9.1f} M pairs/s")
    report(f"  pb.eval(m, wi, wo):              {result['eval_pairs_per_s'] / 1e6:9.1f} M pairs/s "
           f"({result['speedup']:.0f}x numpy)")
    report(f"  pb.eval(..., out=):              {result['eval_out_pairs_per_s'] / 1e6:9.1f} M pairs/s "
           f"(the direction check: {result['eval_out_pairs_per_s'] / result['eval_unchecked_pairs_per_s']:.2f}x "
           "of unchecked)")
    report(f"  pb.eval(..., out=, check=False): {result['eval_unchecked_pairs_per_s'] / 1e6:9.1f} M pairs/s "
           f"({result['speedup_unchecked']:.0f}x numpy)")
    report(f"  max relative difference vs numpy (floor 1e-3): {worst:.2e}")
    return result
