"""Spheres of the 2015 materials in pictures (render.py, _sphere_paths.py): light
refracted into a solid sphere and out again, through a thin shell, each event
drawn by pb.sample. The furnace test (a white, clear object in a uniform
environment shows the environment's radiance: nothing is absorbed, and the
η² of radiance going in is given back going out) would catch a wrong weight,
a lost path or the wrong transport mode; the others a black, blown-out or
noise-dominated picture and a sheet that does not pass light.
"""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb
from principled_brdf import _sphere_paths

RESOLUTION = 24


def white_furnace(direction):
    return np.ones(np.shape(direction), np.float32)


def disc(image, radius=0.8):
    """The pixels within ``radius`` of the sphere's centre (away from the grazing rim)."""
    n = image.shape[0]
    coords = (np.arange(n) + 0.5) / n * 2 - 1
    x, y = np.meshgrid(coords, coords)
    return image[x * x + y * y < radius * radius]


@pytest.mark.parametrize("model, material, lowest", [
    ("disney2015", dict(base_color=(1, 1, 1), spec_trans=1.0, roughness=0.05, ior=1.5), 0.97),
    ("disney2015", dict(base_color=(1, 1, 1), spec_trans=1.0, roughness=0.3, ior=1.33), 0.93),
    ("disney2015_thin", dict(base_color=(1, 1, 1), spec_trans=1.0, roughness=0.2, ior=1.5), 0.95),
])
def test_a_clear_white_sphere_in_a_white_furnace_shows_the_furnace(model, material, lowest):
    image = pb.render.render_sphere(pb.Material(**material), RESOLUTION, model=model, environment=white_furnace,
                                    light_intensity=0.0, samples=256)
    pixels = disc(image)
    assert np.all(np.isfinite(pixels))
    mean = pixels.mean()
    # what the rough interfaces lose by scattering more than once, and the paths cut at MAX_BOUNCES
    assert lowest <= mean <= 1.01, mean
    assert np.percentile(pixels, 99) <= 1.15, np.percentile(pixels, 99)


def test_without_the_paths_inside_glass_would_be_dark(monkeypatch):
    """The same furnace with the paths inside cut off: the reflection alone, a few per cent."""
    glass = pb.Material(base_color=(1, 1, 1), spec_trans=1.0, roughness=0.05, ior=1.5)
    monkeypatch.setattr(_sphere_paths, "MAX_BOUNCES", 0)
    image = pb.render.render_sphere(glass, RESOLUTION, model="disney2015", environment=white_furnace,
                                    light_intensity=0.0, samples=64)
    assert disc(image).mean() < 0.2


def behind_only(direction):
    """Light from behind the sphere (z < 0, away from the viewer) alone."""
    d = np.asarray(direction, np.float32)
    return np.repeat((d[..., 2:3] < -0.3).astype(np.float32) * 2.0, 3, axis=-1)


def test_a_thin_leaf_glows_when_lit_from_behind():
    """The centre of a leaf shell lit from behind alone: through the back face, across, and out
    through the front, green; opaque (diff_trans 0) it reflects what is in front, nothing."""
    leaf = pb.Material(base_color=(0.3, 0.6, 0.1), roughness=0.5, diff_trans=1.2)
    lit, opaque = (disc(pb.render.render_sphere(m, RESOLUTION, model="disney2015_thin", environment=behind_only,
                                                light_intensity=0.0, samples=128), radius=0.5)
                   for m in (leaf, leaf.replace(diff_trans=0.0)))
    assert lit[:, 1].mean() > 0.1 and opaque.mean() < 0.2 * lit.mean(), (lit.mean(axis=0), opaque.mean(axis=0))
    green = lit.mean(axis=0)
    assert green[1] > 1.5 * green[0] and green[1] > 3 * green[2], green


@pytest.mark.parametrize("environment", ["studio", "outdoor"])
def test_glass_under_the_maps_is_neither_black_nor_blown_out_nor_noisy(environment):
    glass = pb.Material(base_color=(0.95, 0.97, 1.0), spec_trans=1.0, roughness=0.1, ior=1.5)
    images = [pb.render.render_sphere(glass, 32, model="disney2015", environment=environment, samples=64, seed=seed)
              for seed in (1, 2)]
    display = [pb.render.tone_map(disc(image)) for image in images]
    luminance = [d @ [0.2126, 0.7152, 0.0722] for d in display]
    assert 0.05 < luminance[0].mean() < 0.9, luminance[0].mean()
    assert np.mean(luminance[0] > 0.99) < 0.1  # not blown out
    # two independent renders differ by noise alone: small against the picture's own contrast
    noise = np.sqrt(np.mean((luminance[0] - luminance[1]) ** 2) / 2)
    assert noise < 0.25 * luminance[0].std() + 0.01, (noise, luminance[0].std())


def test_a_batch_of_2015_spheres_renders_each_as_alone():
    materials = pb.Material(base_color=(1, 1, 1), spec_trans=np.array([1.0, 0.0])[:, None, None], roughness=0.2)
    batch = pb.render.render_sphere(materials, 16, model="disney2015", environment="studio", samples=16)
    alone = pb.render.render_sphere(pb.Material(base_color=(1, 1, 1), spec_trans=1.0, roughness=0.2), 16,
                                    model="disney2015", environment="studio", samples=16)
    np.testing.assert_allclose(batch[0], alone, rtol=1e-5, atol=1e-6)

