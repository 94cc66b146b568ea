"""Writes the README's gallery (docs/gallery/*.png) with the library's own plots.

    python examples/gallery.py [output directory [picture names...]]

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
    spheres = [pb.render.render_sphere(pb.presets.get(name), 128, environment="studio") for name in names]
    demo.write_picture(path, spheres, list(names), columns=5)


def metals(path: str) -> None:
    roughness = np.linspace(0.05, 1.0, 6)
    names = ("gold", "copper", "chrome")
    materials = [pb.presets.get(name).replace(roughness=r) for name in names for r in roughness]
    labels = [f"{name}, r = {r:.2f}" for name in names for r in roughness]
    demo.write_picture(path, [pb.render.render_sphere(m, 128, environment="studio") for m in materials], labels,
                       columns=6)


ENVIRONMENT_PRESETS = ("chrome", "gold", "copper", "car_paint", "white_plastic", "blue_rubber")


def environments(path: str) -> None:
    """The built-in maps as panoramas, then presets under the sky, the studio and outdoors."""
    spheres, titles = [], []
    for environment in ("sky", "studio", "outdoor"):
        spheres += [pb.render.render_sphere(pb.presets.get(name), 128, environment=environment)
                    for name in ENVIRONMENT_PRESETS]
        titles.append(environment)
    labels = list(ENVIRONMENT_PRESETS) + [""] * (len(spheres) - len(ENVIRONMENT_PRESETS))
    demo.write_picture(path, spheres, labels, columns=len(ENVIRONMENT_PRESETS), row_titles=titles)


# (label, model, parameters): the demo picture's row of the 2015 BSDF with water beside the glass
GLASS = demo.GLASS_ROW[:3] + (
    ("water, ior 1.33", "disney2015", dict(base_color=(0.85, 0.95, 1.0), spec_trans=1.0, roughness=0.02, ior=1.33)),
) + demo.GLASS_ROW[3:]


def glass(path: str) -> None:
    """The 2015 BSDF's solids and thin shells in the studio and outdoors: light refracted through
    each sphere and out again, every event drawn by pb.sample."""
    spheres, titles = [], []
    for environment in ("studio", "outdoor"):
        spheres += [pb.render.render_sphere(pb.Material(**params), 128, model=model, environment=environment,
                                            samples=2048) for _, model, params in GLASS]
        titles.append(environment)
    labels = [label for label, _, _ in GLASS] + [""] * len(GLASS)
    demo.write_picture(path, spheres, labels, columns=len(GLASS), row_titles=titles)


# (label, model, parameters): materials that light passes through, and the leaf without it
BACKLIT = tuple(row for row in demo.GLASS_ROW if row[1] == "disney2015_thin") + (
    ("leaf, diff_trans 0", "disney2015_thin", dict(demo.GLASS_ROW[4][2], diff_trans=0.0)),
    demo.GLASS_ROW[1], demo.GLASS_ROW[2],
)
# turned about the vertical axis so that the sun (outdoors) and the key light (studio), up and to the
# left of the camera, stand behind the subject, 37° and 30° above the horizon
BACKLIGHT_TURN = 130.0


def backlit(path: str) -> None:
    """Thin sheets and glass with the light behind them: the built-in maps turned by
    Environment.turned, the sun or the key light shining through each sphere at the viewer."""
    spheres, titles = [], []
    for name, title in (("outdoor", "sun behind"), ("studio", "key light behind")):
        lighting = pb.render.environment_of(name).turned(BACKLIGHT_TURN)
        spheres += [pb.render.render_sphere(pb.Material(**params), 128, model=model, environment=lighting,
                                            samples=1024) for _, model, params in BACKLIT]
        titles.append(title)
    labels = [label for label, _, _ in BACKLIT] + [""] * len(BACKLIT)
    demo.write_picture(path, spheres, labels, columns=len(BACKLIT), row_titles=titles)


def environment_maps(path: str) -> None:
    """The studio and outdoor maps side by side, tone mapped (each 256 x 512, a 2 x 2 mean of the map)."""
    panoramas = []
    for name in ("studio", "outdoor"):
        image = pb.render.environment_of(name).image
        panoramas.append(image.reshape(256, 2, 512, 2, 3).mean(axis=(1, 3)))
    gap = np.zeros((256, 8, 3))
    pb.render.save_image(path, np.concatenate([panoramas[0], gap, panoramas[1]], axis=1))


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


def main(directory: str, only: list[str] | None = None) -> None:
    """Write every picture, or those named in ``only``."""
    os.makedirs(directory, exist_ok=True)
    pictures = [("demo", lambda path: demo.run(pairs=1 << 16, output=path, repeats=1, report=lambda message: None)),
                ("presets", presets), ("metals", metals), ("environments", environments),
                ("environment_maps", environment_maps), ("glass", glass), ("backlit", backlit), ("plots", plots), ("parameter_sweep", sweep),
                ("microfacet_family", family)]
    for name, draw in pictures:
        if only and name not in only:
            continue
        path = os.path.join(directory, f"{name}.png")
        draw(path)
        shrink(path)
        print(f"wrote {path} ({os.path.getsize(path) // 1024} KB)")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "docs", "gallery"),
         sys.argv[2:])
