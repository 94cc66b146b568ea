"""Writes the README's gallery (docs/gallery/*.png) with the library's own plots.

    python examples/gallery.py [output directory]

Every picture comes from a public function (pb.plot, pb.render, the demo's
picture), at its default settings unless a caption says otherwise, so the
gallery shows what a user gets.
"""

from __future__ import annotations

import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import principled_brdf as pb  # noqa: E402
from principled_brdf import demo  # noqa: E402

DPI = 80


def presets(path: str) -> None:
    names = pb.presets.names()
    spheres = [pb.render.render_sphere(pb.presets.get(name), 128, samples=256) for name in names]
    demo.write_picture(path, spheres, list(names), columns=5)


def metals(path: str) -> None:
    roughness = np.linspace(0.05, 1.0, 6)
    materials = [pb.presets.get(name).replace(roughness=r) for name in ("gold", "chrome") for r in roughness]
    labels = [f"{name}, r = {r:.2f}" for name in ("gold", "chrome") for r in roughness]
    demo.write_picture(path, [pb.render.render_sphere(m, 128, samples=256) for m in materials], labels, columns=6)


def plots(path: str) -> None:
    material = pb.presets.get("car_paint")
    fig = plt.figure(figsize=(14, 7.6), layout="constrained")
    grid = fig.add_gridspec(2, 3)
    pb.plot.polar_lobes(material, 45, ax=fig.add_subplot(grid[0, 0], projection="polar"))
    pb.plot.polar_lobes(material, 45, log=True, ax=fig.add_subplot(grid[1, 0], projection="polar"))
    pb.plot.brdf_slice(material, ax=fig.add_subplot(grid[0, 1]))
    pb.plot.brdf_slice(material, channel="rgb", ax=fig.add_subplot(grid[1, 1]))
    pb.plot.albedo_curves(material, ax=fig.add_subplot(grid[0, 2]))
    pb.plot.lit_sphere(material, ax=fig.add_subplot(grid[1, 2]))
    fig.suptitle("car_paint: lobes in the plane of incidence (linear, log radius), the (θh, θd) slice "
                 "(luminance, color), directional albedo, lit sphere")
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def sweep(path: str) -> None:
    fig = pb.plot.parameter_sweep(resolution=48)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def family(path: str) -> None:
    fig = pb.plot.microfacet_family(0.3)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)


def shrink(path: str) -> None:
    """To a 256-color palette (dithered): a third of the size, no visible change at this size."""
    from PIL import Image  # matplotlib's own dependency

    with Image.open(path) as image:
        rgb = image.convert("RGB")
    palette = rgb.quantize(256, method=Image.Quantize.MEDIANCUT)
    rgb.quantize(palette=palette, dither=Image.Dither.FLOYDSTEINBERG).save(path, optimize=True)


def main(directory: str) -> None:
    os.makedirs(directory, exist_ok=True)
    pictures = [("demo", lambda path: demo.run(pairs=1 << 16, output=path, repeats=1, report=lambda message: None)),
                ("presets", presets), ("metals", metals), ("plots", plots), ("parameter_sweep", sweep),
                ("microfacet_family", family)]
    for name, draw in pictures:
        path = os.path.join(directory, f"{name}.png")
        draw(path)
        shrink(path)
        print(f"wrote {path} ({os.path.getsize(path) // 1024} KB)")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "docs", "gallery"))
