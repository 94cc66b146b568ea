"""The main job (``python -m principled_brdf demo``, ``make demo``): evaluate
and sample millions of direction pairs with the SIMD kernels, print the
throughput beside the memory roofline and the float64 reference, check a
sample against the reference, and write a picture."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from . import _core, _validate, presets, reference
from .directional_albedo import albedo
from ._batch import cpu_info, eval as _eval, sample as _sample
from .benchmark import best_seconds, random_pairs
from .material import Material
from .render import MAX_SAMPLE_WORK, render_sphere, to_srgb8, write_png

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence
    from typing import Any

    from ._typing import Float32Array, FloatArray, Model

DEMO_MATERIAL: dict[str, Any] = dict(base_color=(0.9, 0.55, 0.25), metallic=0.3, roughness=0.35, anisotropic=0.4,
                                     sheen=0.3, clearcoat=0.6, clearcoat_gloss=0.8)
PICTURE_PRESETS = ("gold", "chrome", "brushed_metal", "car_paint", "blue_rubber", "satin_cloth")
PICTURE_RESOLUTION = 128  # pixels per sphere
#: The metals of the picture's roughness sweep: a white one (F_avg ~ 1, the white furnace of
#: docs/energy-compensation.md) and gold (the lost energy is colored: Kulla & Conty 2017's F_avg term).
SWEEP_METALS = {"white metal": (0.95, 0.95, 0.95), "gold": (1.0, 0.71, 0.29)}
SWEEP_ROUGHNESS = np.linspace(0.05, 1.0, len(PICTURE_PRESETS))
LABEL_STRIP, ROW_GAP = 22, 4  # pixels above a row of spheres with labels, and above one without
#: The picture's row of the 2015 BSDF (label, model, parameters), outdoors: solids that refract what
#: is behind them, and thin shells that let light through.
GLASS_ROW: tuple[tuple[str, Model, dict[str, Any]], ...] = (
    ("clear glass", "disney2015", dict(base_color=(1.0, 1.0, 1.0), spec_trans=1.0, roughness=0.02, ior=1.5)),
    ("frosted glass", "disney2015", dict(base_color=(1.0, 1.0, 1.0), spec_trans=1.0, roughness=0.3, ior=1.5)),
    ("tinted glass", "disney2015", dict(base_color=(0.55, 0.8, 0.6), spec_trans=1.0, roughness=0.02, ior=1.5)),
    ("diamond, ior 2.4", "disney2015", dict(base_color=(1.0, 1.0, 1.0), spec_trans=1.0, roughness=0.02, ior=2.4)),
    ("leaf (thin)", "disney2015_thin", dict(base_color=(0.3, 0.6, 0.08), roughness=0.45, diff_trans=1.2, sheen=0.2)),
    ("paper lantern (thin)", "disney2015_thin", dict(base_color=(0.95, 0.85, 0.6), roughness=0.8, diff_trans=1.6)),
)
GLASS_ENVIRONMENT = "outdoor"  # a sky, a sun and a tiled ground: what refraction bends shows


def run(pairs: int = 1 << 22, output: str = "principled_brdf_demo.png", repeats: int = 5,
        resolution: int = PICTURE_RESOLUTION, report: Callable[[str], object] = print) -> dict[str, Any]:
    from . import __version__

    resolution = _validate.resolution("resolution", resolution, MIN_PICTURE_RESOLUTION, MAX_PICTURE_RESOLUTION,
                                      " pixels per sphere")
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

    furnace = [float(albedo(Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=1.0), 1.0, samples=1 << 18,
                            seed=1, energy_compensation=compensated).total[0]) for compensated in (False, True)]
    report(f"white furnace (base_color 1, metallic 1, roughness 1, view along the normal): directional albedo "
           f"{furnace[0]:.3f} single scattering, {furnace[1]:.3f} with energy_compensation")
    report(f"rendering {len(PICTURE_PRESETS)} presets, a roughness sweep of two metals, without and with "
           "energy compensation, and a row of glass and thin sheets ...")
    images, labels, titles = picture_spheres(resolution)
    write_picture(output, images, labels, columns=len(PICTURE_PRESETS), row_titles=titles)
    report(f"wrote {output}: presets {', '.join(PICTURE_PRESETS)} (top); below, a white and a gold metal from "
           f"roughness {SWEEP_ROUGHNESS[0]:g} to {SWEEP_ROUGHNESS[-1]:g}, each without and with energy_compensation "
           "(Kulla & Conty 2017), in the studio environment (softboxes, a dark surround); at the bottom the 2015 "
           f"BSDF outdoors: {', '.join(label for label, _, _ in GLASS_ROW)}")
    return {"rates": rates, "max_relative_error": error, "white_furnace": furnace, "output": output}


def picture_spheres(resolution: int = PICTURE_RESOLUTION) -> tuple[list[Float32Array], list[str], list[str]]:
    """The demo picture's spheres (row by row), their labels and the row titles: the presets,
    then each of :data:`SWEEP_METALS` along :data:`SWEEP_ROUGHNESS` without and, in the row
    below, with ``energy_compensation`` (docs/energy-compensation.md)."""
    images = [lit_sphere(presets.get(name), resolution) for name in PICTURE_PRESETS]
    labels, titles = list(PICTURE_PRESETS), ["presets"]
    for name, color in SWEEP_METALS.items():
        sweep = Material(base_color=color, metallic=1.0, roughness=SWEEP_ROUGHNESS[:, None, None])
        for compensated in (False, True):
            spheres = lit_sphere(sweep, resolution, energy_compensation=compensated)  # one batched render
            images += list(spheres)
            # the roughness above the first row of each pair; the second follows without a strip
            labels += ["" if compensated else f"roughness {r:.2f}" for r in SWEEP_ROUGHNESS]
            titles.append("+ energy\ncompensation" if compensated else name)
    images += [lit_sphere(Material(**params), resolution, model=model, environment=GLASS_ENVIRONMENT)
               for _, model, params in GLASS_ROW]
    labels += [label for label, _, _ in GLASS_ROW]
    titles.append("2015 BSDF,\noutdoors")
    return images, labels, titles


PICTURE_ENVIRONMENT = "studio"  # softboxes in a dark studio: metals read as the metal they are
PICTURE_SAMPLES = 256  # map samples per pixel: no visible grain on a glossy metal under the softboxes
#: The picture's spheres: the presets, each sweep metal without and with compensation, the glass row.
PICTURE_SPHERES = len(PICTURE_PRESETS) + 2 * len(SWEEP_METALS) * len(SWEEP_ROUGHNESS) + len(GLASS_ROW)
#: The most samples the picture takes in all (spheres x pixels x samples): a quarter of a render's
#: MAX_SAMPLE_WORK, since a map's sample (a BSDF and a map direction) and the glass row's paths cost
#: about four of the sky's; so the picture too ends within about half an hour on two cores.
MAX_PICTURE_WORK = MAX_SAMPLE_WORK // 4
#: The most pixels per sphere: PICTURE_SPHERES x resolution² x PICTURE_SAMPLES within MAX_PICTURE_WORK.
MAX_PICTURE_RESOLUTION = math.isqrt(MAX_PICTURE_WORK // (PICTURE_SPHERES * PICTURE_SAMPLES))  # 682
MIN_PICTURE_RESOLUTION = 8  # pixels per sphere


def lit_sphere(material: Material, resolution: int = PICTURE_RESOLUTION, *, energy_compensation: bool = False,
               model: Model = "disney2014", environment: str = PICTURE_ENVIRONMENT) -> Float32Array:
    """A sphere in ``environment`` (render_sphere, linear RGB) with :data:`PICTURE_SAMPLES`
    per pixel. ``material`` of leading shape ``S + (1, 1)`` gives ``S`` spheres
    (``render_sphere``); ``energy_compensation`` and ``model`` as in ``pb.eval``."""
    return render_sphere(material, resolution, environment=environment, samples=PICTURE_SAMPLES, model=model,
                         energy_compensation=energy_compensation)


def write_picture(output: str, images: Sequence[FloatArray], labels: Sequence[str], columns: int,
                  row_titles: Sequence[str] | None = None, title_width: int = 120) -> None:
    """The tone-mapped images in a grid, each labelled (with matplotlib; without it, unlabelled).

    ``row_titles``: one title per row, written in a margin ``title_width`` pixels wide on the
    left (lines split at newlines)."""
    rows = [np.concatenate(images[k:k + columns], axis=1) for k in range(0, len(images), columns)]
    if row_titles is not None and len(row_titles) != len(rows):
        raise ValueError(f"row_titles: expected {len(rows)} titles (one per row), got {len(row_titles)}")
    grid = to_srgb8(np.concatenate(rows, axis=0))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        write_png(output, grid)
        return
    size = images[0].shape[0]
    margin = title_width if row_titles is not None else 0
    # a label strip above each row that has a label; a thin gap above one that has none
    strips = [LABEL_STRIP if any(labels[k:k + columns]) else ROW_GAP for k in range(0, len(images), columns)]
    width, height = margin + grid.shape[1], grid.shape[0] + sum(strips)
    figure = plt.figure(figsize=(width / 100, height / 100), dpi=100)
    top = height
    for row, strip in enumerate(strips):
        top -= strip + size
        for column in range(columns):
            index = row * columns + column
            if index >= len(images):
                break
            # matplotlib's stub types rect as a tuple only; add_axes takes any sequence of four numbers
            axes = figure.add_axes(  # type: ignore[call-overload]
                [(margin + column * size) / width, top / height, size / width, (size + strip) / height])
            axes.imshow(grid[row * size:(row + 1) * size, column * size:(column + 1) * size], extent=(0, 1, 0, 1))
            axes.set_xlim(0, 1)
            axes.set_ylim(0, 1 + strip / size)
            if index < len(labels) and labels[index]:
                axes.text(0.5, 1 + strip / 2 / size, labels[index], ha="center", va="center", color="white",
                          fontsize=9)
            axes.set_facecolor("black")
            axes.set_axis_off()
        if row_titles is not None:
            figure.text(margin / 2 / width, (top + size / 2) / height, row_titles[row], ha="center",
                        va="center", color="white", fontsize=10, linespacing=1.3)
    figure.patch.set_facecolor("black")
    figure.savefig(output, facecolor="black")
    plt.close(figure)
