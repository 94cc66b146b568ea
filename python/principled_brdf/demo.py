"""The main job (``python -m principled_brdf demo``, ``make demo``): evaluate
and sample millions of direction pairs with the SIMD kernels, print the
throughput beside the memory roofline and the float64 reference, check a
sample against the reference, and write a picture."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from . import _core, presets, reference
from ._batch import cpu_info, eval as _eval, sample as _sample
from .benchmark import best_seconds, random_pairs
from .material import Material
from .render import render_sphere, to_srgb8, write_png

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence
    from typing import Any

    from ._typing import Float32Array, FloatArray

DEMO_MATERIAL: dict[str, Any] = dict(base_color=(0.9, 0.55, 0.25), metallic=0.3, roughness=0.35, anisotropic=0.4,
                                     sheen=0.3, clearcoat=0.6, clearcoat_gloss=0.8)
PICTURE_PRESETS = ("gold", "chrome", "brushed_metal", "car_paint", "blue_rubber", "satin_cloth")


def run(pairs: int = 1 << 22, output: str = "principled_brdf_demo.png", repeats: int = 5,
        report: Callable[[str], object] = print) -> dict[str, Any]:
    from . import __version__

    info = cpu_info()
    report(f"principled-brdf {__version__}: {info['isa']} ({info['float_lanes']} float lanes), "
           f"{info['threads']} threads")
    material = Material(**DEMO_MATERIAL)
    report(f"generating {pairs:,} random pairs ...")
    wi, wo = random_pairs(pairs, seed=7)
    out = np.empty_like(wi)

    report("timing (best of several runs) ...")
    rates = {}
    eval_s = best_seconds(lambda: _eval(material, wi, wo, out=out, check=False), repeats)
    checked_s = best_seconds(lambda: _eval(material, wi, wo), repeats)
    sample_s = best_seconds(lambda: _sample(material, wo, seed=1, check=False), repeats)
    roofline_s = best_seconds(lambda: _core.memory_roofline(wi, wo, out, 0), repeats)
    subset = min(pairs, 100_000)
    reference_s = best_seconds(lambda: reference.eval(material, wi[:subset], wo[:subset]), 2) * pairs / subset
    gigabytes = 36 * pairs / 1e9  # an (N, 3) eval reads wi and wo and writes f: 12 bytes each per pair

    report(f"\n{pairs:,} pairs, RGB float32:")
    rows = [
        ("eval (out=, check=False)", eval_s),
        ("eval (checked, new output)", checked_s),
        ("sample (wi, pdf, weight, lobe)", sample_s),
        ("memory roofline: copy of eval's bytes", roofline_s),
        ("float64 reference eval", reference_s),
    ]
    for name, seconds in rows:
        rates[name] = pairs / seconds
        report(f"  {name:<38} {pairs / seconds / 1e6:9.1f} M pairs/s  {gigabytes / seconds:6.1f} GB/s-equivalent"
               f"  {roofline_s / seconds:5.2f}x roofline")

    f = _eval(material, wi[:subset], wo[:subset])
    ref = reference.eval(material, wi[:subset].astype(np.float64), wo[:subset].astype(np.float64))
    error = float(np.max(np.abs(f - ref) / np.maximum(np.abs(ref), 1e-6)))
    drawn = _sample(material, wo[:subset], seed=3)
    above = drawn.pdf > 0
    report(f"\nmax relative error of eval vs the float64 reference on {subset:,} pairs: {error:.2e}")
    report(f"samples above the horizon: {above.mean():.4f}; mean weight (albedo estimate, RGB): "
           f"{np.round(drawn.weight.mean(axis=0), 4).tolist()}")

    report(f"rendering {len(PICTURE_PRESETS)} presets and a roughness sweep ...")
    roughness = np.linspace(0.05, 1.0, len(PICTURE_PRESETS))
    materials = [presets.get(name) for name in PICTURE_PRESETS] + [
        Material(base_color=(0.9, 0.55, 0.25), metallic=1.0, roughness=r) for r in roughness]
    labels = list(PICTURE_PRESETS) + [f"roughness {r:.2f}" for r in roughness]
    write_picture(output, [lit_sphere(m) for m in materials], labels, columns=len(PICTURE_PRESETS))
    report(f"wrote {output}: presets {', '.join(PICTURE_PRESETS)} (top); a metal with roughness 0.05 to 1 (bottom), "
           "under a sky and a key light")
    return {"rates": rates, "max_relative_error": error, "output": output}


def lit_sphere(material: Material, resolution: int = 160) -> Float32Array:
    """A sphere under render_sphere's key light and default sky (linear RGB), with 256
    sky samples per pixel: no grain where a rough metal reflects the dark ground."""
    return render_sphere(material, resolution, samples=256)


def write_picture(output: str, images: Sequence[FloatArray], labels: Sequence[str], columns: int) -> None:
    """The tone-mapped images in a grid, each labelled (with matplotlib; without it, unlabelled)."""
    rows = [np.concatenate(images[k:k + columns], axis=1) for k in range(0, len(images), columns)]
    grid = to_srgb8(np.concatenate(rows, axis=0))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        write_png(output, grid)
        return
    size = images[0].shape[0]
    figure = plt.figure(figsize=(grid.shape[1] / 100, (grid.shape[0] + 22 * len(rows)) / 100), dpi=100)
    for index, label in enumerate(labels):
        row, column = divmod(index, columns)
        # matplotlib's stub types rect as a tuple only; add_axes takes any sequence of four numbers
        axes = figure.add_axes(  # type: ignore[call-overload]
            [column / columns, 1 - (row + 1) / len(rows), 1 / columns, 1 / len(rows)])
        axes.imshow(grid[row * size:(row + 1) * size, column * size:(column + 1) * size], extent=(0, 1, 0, 1))
        axes.set_xlim(0, 1)
        axes.set_ylim(0, 1.14)
        axes.text(0.5, 1.07, label, ha="center", va="center", color="white", fontsize=9)
        axes.set_facecolor("black")
        axes.set_axis_off()
    figure.patch.set_facecolor("black")
    figure.savefig(output, facecolor="black")
    plt.close(figure)
