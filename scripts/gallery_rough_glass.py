#!/usr/bin/env python3
"""Writes the gallery's pictures of rough glass with and without the energy
compensation (docs/energy-compensation.md):

- docs/gallery/rough_glass_furnace.png: white glass spheres (η 1.5) of roughness
  0.3, 0.6 and 1 in a uniform white environment, without the compensation (top:
  grey discs, the light lost between microfacets) and with it (bottom: they
  vanish into the background);
- docs/gallery/rough_glass_studio.png: the same spheres, lightly tinted, in the
  studio map, without and with.

Usage: python scripts/gallery_rough_glass.py [--samples 1024] [--resolution 160]
(needs the installed package and matplotlib; a few minutes on two cores).
"""

from __future__ import annotations

import argparse
import pathlib

import numpy as np

import principled_brdf as pb

ROOT = pathlib.Path(__file__).resolve().parent.parent
ROUGHNESSES = (0.3, 0.6, 1.0)


def white(direction):
    return np.ones(np.shape(direction), np.float32)


def spheres(base_color, environment, resolution, samples, background):
    """Rows without and with the compensation, one sphere a roughness: linear RGB images."""
    inside = pb.render.sphere_frames(resolution)[0]
    rows = []
    for compensated in (False, True):
        row = []
        for roughness in ROUGHNESSES:
            glass = pb.Material(base_color=base_color, spec_trans=1.0, roughness=roughness, ior=1.5)
            image = pb.render.render_sphere(glass, resolution, model="disney2015", environment=environment,
                                            light_intensity=0.0, samples=samples, energy_compensation=compensated)
            if background is not None:
                image = np.where(inside[..., None], image, background)
            row.append(image)
        rows.append(row)
    return rows


def figure(rows, path, title):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, len(ROUGHNESSES), figsize=(2.4 * len(ROUGHNESSES), 5.2), dpi=100)
    for r, (row, label) in enumerate(zip(rows, ("without", "with energy_compensation=True"))):
        for c, image in enumerate(row):
            ax = axes[r, c]
            ax.imshow(pb.render.to_srgb8(image))
            ax.set_xticks([])
            ax.set_yticks([])
            if r == 0:
                ax.set_title(f"roughness {ROUGHNESSES[c]:g}", fontsize=10)
            if c == 0:
                ax.set_ylabel(label, fontsize=9)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", type=int, default=1024)
    parser.add_argument("--resolution", type=int, default=160)
    args = parser.parse_args()
    gallery = ROOT / "docs" / "gallery"
    furnace = spheres((1.0, 1.0, 1.0), white, args.resolution, args.samples, background=1.0)
    figure(furnace, gallery / "rough_glass_furnace.png", "white rough glass (η 1.5) in a uniform white environment")
    studio = spheres((0.92, 0.96, 1.0), "studio", args.resolution, args.samples, background=None)
    figure(studio, gallery / "rough_glass_studio.png", "rough glass (η 1.5) in the studio")


if __name__ == "__main__":
    main()
