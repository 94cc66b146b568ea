"""Lighting by latitude-longitude maps (pb.render with an Environment): multiple
importance sampling gives the right integral, beats BSDF sampling where the light is
small, reads maps from arrays and files, and the built-in studio shows metals as metals.

References are independent of the renderer: Gauss-Legendre quadrature of the float64
reference (``pb.reference.eval``) over the hemisphere or over the light's pixels, and
the renderer's other estimator (BSDF samples alone, a callable environment) at many
more samples.
"""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb
from principled_brdf import procedural_environments
from principled_brdf.environment import Environment, uv_to_directions

# roughness 1: the quadratures below resolve the specular lobe (Schlick's FH leaves one even at specular 0)
ROUGH = pb.Material(base_color=(0.8, 0.5, 0.3), roughness=1.0, specular=0.0)
GLOSSY = pb.Material(base_color=(1.0, 0.766, 0.336), metallic=1.0, roughness=0.2, clearcoat=0.5)


def pixel_views(resolution: int) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
    """(mask of the sphere, view directions of its pixels in their local frames (n, 3), the
    pixels' frames as camera-space tangent, bitangent, normal columns (n, 3, 3))."""
    inside, to_local = pb.render.sphere_frames(resolution)
    wo = to_local((0.0, 0.0, 1.0)).astype(np.float64)[inside]
    frames = np.stack([to_local(e).astype(np.float64)[inside] for e in np.eye(3)], axis=-2)  # [n, k, j]
    return inside, wo, frames


def hemisphere_quadrature(nodes: int = 64) -> tuple[np.ndarray, np.ndarray]:
    """Local directions and weights of a Gauss-Legendre rule in (cos θ, φ) over the upper hemisphere."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    cos_theta, phi = np.meshgrid(0.5 * (x + 1.0), np.pi * (x + 1.0), indexing="ij")
    sin_theta = np.sqrt(1.0 - cos_theta**2)
    directions = np.stack([sin_theta * np.cos(phi), sin_theta * np.sin(phi), cos_theta], axis=-1)
    return directions.reshape(-1, 3), (np.outer(0.5 * w, np.pi * w) * cos_theta).ravel()  # weights hold cos θ


def test_a_constant_map_gives_radiance_times_the_directional_albedo():
    environment = Environment(np.full((2, 4, 3), 0.7))
    inside, wo, _ = pixel_views(12)
    wi, weight = hemisphere_quadrature()
    expected = np.array([0.7 * weight @ pb.reference.eval(ROUGH, wi, np.broadcast_to(o, wi.shape)) for o in wo])
    rendered = pb.render.render_environment(ROUGH, 12, environment, samples=1024)[inside]
    error = (rendered - expected) / expected
    assert np.sqrt(np.mean(error**2)) < 5e-3 and np.abs(error).max() < 2e-2, (np.abs(error).max(), error.std())
    assert abs(error.mean()) < 1e-3  # no bias: the pixels' errors average out


def test_a_small_bright_light_gives_the_quadrature_of_its_pixels():
    image = np.full((32, 64, 3), 0.01)
    image[10:12, 40:42] = (60.0, 50.0, 40.0)  # about 2.5 x 5.6 degrees: a small lamp up and to the right
    environment = Environment(image)
    inside, wo, frames = pixel_views(10)
    # the integral over the map, pixel by pixel: the lamp's pixels split 16 x 16, the dim rest 2 x 2
    expected = np.zeros((len(wo), 3))
    for rows, columns, split in (((10, 12), (40, 42), 16), ((0, 32), (0, 64), 2)):
        v = (np.arange(rows[0] * split, rows[1] * split) + 0.5) / (32 * split)
        u = (np.arange(columns[0] * split, columns[1] * split) + 0.5) / (64 * split)
        uv = np.stack(np.meshgrid(u, v), axis=-1).reshape(-1, 2)
        directions = uv_to_directions(uv).astype(np.float64)
        radiance = environment(directions).astype(np.float64)
        if split == 2:  # the rest of the map: the lamp's pixels are counted above
            radiance[radiance[:, 0] > 1.0] = 0.0
        solid_angle = np.sin(np.pi * uv[:, 1]) * (np.pi / (32 * split)) * (2.0 * np.pi / (64 * split))
        for p, (o, frame) in enumerate(zip(wo, frames)):
            local = directions @ frame  # camera space to the pixel's frame: [k] . frame[k, j]
            f = pb.reference.eval(ROUGH, local, np.broadcast_to(o, local.shape), cosine=True)
            expected[p] += (f * radiance * solid_angle[:, None]).sum(axis=0)
    rendered = pb.render.render_environment(ROUGH, 10, environment, samples=512)[inside]
    lit = expected[:, 0] > 0.05 * expected[:, 0].max()
    error = (rendered[lit] - expected[lit]) / expected[lit]
    assert np.sqrt(np.mean(error**2)) < 1e-2 and abs(error.mean()) < 3e-3, (np.abs(error).max(), error.mean())
    # and BSDF samples alone, at as many samples, are far worse at a small lamp (why the map is sampled)
    alone = pb.render.render_environment(ROUGH, 10, lambda d: environment(d), samples=512)[inside]
    error_alone = (alone[lit] - expected[lit]) / expected[lit]
    assert np.sqrt(np.mean(error_alone**2)) > 4 * np.sqrt(np.mean(error**2))


@pytest.mark.parametrize("energy_compensation", [False, True])
def test_mis_agrees_with_bsdf_sampling_alone_for_a_glossy_material(energy_compensation):
    studio = procedural_environments.studio(64)
    options = dict(energy_compensation=energy_compensation)
    inside, _, _ = pixel_views(12)
    mis = pb.render.render_environment(GLOSSY, 12, studio, samples=2048, **options)[inside]
    brute = pb.render.render_environment(GLOSSY, 12, lambda d: studio(d), samples=1 << 15, **options)[inside]
    # the noise of each, from a second seed
    mis_noise = mis - pb.render.render_environment(GLOSSY, 12, studio, samples=2048, seed=1, **options)[inside]
    scale = brute.mean()
    assert abs(mis.sum() / brute.sum() - 1.0) < 3e-3
    assert np.sqrt(np.mean((mis - brute) ** 2)) < 2.0 * np.sqrt(np.mean(mis_noise**2)) + 5e-3 * scale


def test_maps_from_arrays_exr_and_hdr_files_light_alike(tmp_path):
    image = np.zeros((16, 32, 3), np.float32)
    image[3:6, 20:26] = (4.0, 3.0, 2.0)
    image[8:] = 0.05
    from_array = pb.render.render_sphere(ROUGH, 16, environment=image, samples=16)
    assert from_array[pb.render.sphere_frames(16)[0]].mean() > 0.01
    import OpenEXR

    with OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}, {"RGB": image}) as exr:
        exr.write(str(tmp_path / "map.exr"))
    np.testing.assert_array_equal(pb.render.render_sphere(ROUGH, 16, environment=tmp_path / "map.exr", samples=16),
                                  from_array)
    separate = {name: image[..., k].copy() for k, name in enumerate("RGB")}
    with OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}, separate) as exr:
        exr.write(str(tmp_path / "channels.exr"))
    np.testing.assert_array_equal(Environment.read(tmp_path / "channels.exr").image, image)
    cv2 = pytest.importorskip("cv2")  # the hdr extra
    assert cv2.imwrite(str(tmp_path / "map.hdr"), image[..., ::-1])
    read = Environment.read(str(tmp_path / "map.hdr")).image
    np.testing.assert_allclose(read, image, rtol=1e-2, atol=1e-3)  # RGBE keeps 8 bits of mantissa


def test_a_map_brings_its_own_lights_and_the_key_light_is_off_unless_asked():
    studio = procedural_environments.studio(32)
    plain = pb.render.render_sphere(ROUGH, 16, environment=studio, samples=8)
    np.testing.assert_array_equal(plain, pb.render.render_sphere(ROUGH, 16, environment=studio, samples=8,
                                                                 light_intensity=0.0))
    keyed = pb.render.render_sphere(ROUGH, 16, environment=studio, samples=8, light_intensity=3.0)
    assert keyed.sum() > plain.sum() * 1.2
    # the sky keeps its key light
    np.testing.assert_array_equal(pb.render.render_sphere(ROUGH, 16, samples=8),
                                  pb.render.render_sphere(ROUGH, 16, samples=8, light_intensity=3.0))


def luminance(srgb8: np.ndarray) -> np.ndarray:
    return srgb8.astype(np.float64) / 255.0 @ np.array([0.2126, 0.7152, 0.0722])


@pytest.fixture(scope="module")
def studio_metals():
    names = ("gold", "copper", "chrome")
    inside = pb.render.sphere_frames(64)[0]
    pictures = {}
    for name in names:
        linear = [pb.render.render_sphere(pb.presets.get(name), 64, environment="studio", samples=128, seed=seed)
                  for seed in (0, 1)]
        pictures[name] = (pb.render.to_srgb8(linear[0]), linear[0], linear[1])
    return inside, pictures


def test_studio_metals_are_neither_black_nor_blown_out_nor_noisy(studio_metals):
    inside, pictures = studio_metals
    for name, (srgb, linear, other_seed) in pictures.items():
        y = luminance(srgb)[inside]
        assert 0.12 < y.mean() < 0.6, (name, y.mean())
        assert np.mean(srgb[inside].max(axis=-1) == 255) < 0.15, name  # highlights, not a white disc
        assert y.max() > 0.8, name  # and the highlights are there
        # noise: two seeds differ little next to the picture's own contrast
        noise = np.sqrt(np.mean((linear[inside] - other_seed[inside]) ** 2))
        assert noise < 0.1 * linear[inside].std(), (name, noise / linear[inside].std())


def test_studio_metals_show_their_colour(studio_metals):
    inside, pictures = studio_metals
    means = {name: linear[inside].mean(axis=0) for name, (_, linear, _) in pictures.items()}
    gold, copper, chrome = (means[name] / means[name][0] for name in ("gold", "copper", "chrome"))
    assert 0.6 < gold[1] < 0.8 and gold[2] < 0.3, gold  # saturated and warm: blue well below green below red
    assert copper[1] < 0.62 and copper[2] < 0.5, copper  # orange-red
    assert abs(chrome[1] - 1.0) < 0.15 and abs(chrome[2] - 1.0) < 0.3, chrome  # near neutral


def test_studio_chrome_reflects_the_lights_crisply(studio_metals):
    inside, pictures = studio_metals
    y = luminance(pictures["chrome"][0])
    interior = inside & np.roll(inside, 1, 0) & np.roll(inside, -1, 0) & np.roll(inside, 1, 1) & np.roll(inside, -1, 1)
    step = np.maximum(np.abs(np.diff(y, axis=0, append=0.0)), np.abs(np.diff(y, axis=1, append=0.0)))[interior]
    assert np.median(y[inside]) < 0.3 and np.mean(y[inside] > 0.8) > 0.02  # dark surround, bright lights
    assert np.sum(step > 0.4) >= 8  # the softboxes' edges jump from dark to bright within a pixel


def test_a_sphere_looks_the_same_alone_or_in_a_batch():
    studio = procedural_environments.studio(32)
    roughness = np.array([0.1, 0.5, 1.0])
    batch = pb.render.render_sphere(GLOSSY.replace(roughness=roughness[:, None, None]), 16, environment=studio,
                                    samples=8)
    for k, r in enumerate(roughness):
        np.testing.assert_allclose(batch[k], pb.render.render_sphere(GLOSSY.replace(roughness=r), 16,
                                                                     environment=studio, samples=8),
                                   rtol=1e-5, atol=1e-7)


def test_a_turned_map_moves_its_lights_about_the_vertical_axis():
    """turned(180) brings the sun from behind the viewer to behind the subject: the radiance
    in the mirrored direction is the sun's; turns add, a whole turn is the map itself."""
    outdoor = procedural_environments.outdoor(64)
    sun = np.array(procedural_environments.SUN_DIRECTION) / np.linalg.norm(procedural_environments.SUN_DIRECTION)
    behind = (sun * [-1.0, 1.0, -1.0]).astype(np.float32)[None]
    turned = outdoor.turned(180)
    np.testing.assert_array_equal(turned(behind), outdoor(sun.astype(np.float32)[None]))
    assert turned(behind).max() > 100 * outdoor(behind).max()
    np.testing.assert_array_equal(outdoor.turned(90).turned(-90).image, outdoor.image)
    np.testing.assert_array_equal(outdoor.turned(360).image, outdoor.image)
    # a quarter turn moves +z (behind the viewer) to -x: phi grows from +z through -x
    quarter = outdoor.turned(90)
    column = (np.arange(128) + 0.5) / 128
    ring = uv_to_directions(np.stack([column, np.full(128, 0.75)], axis=-1))  # below the horizon: the tiles
    np.testing.assert_array_equal(quarter(ring), np.roll(outdoor(ring), 32, axis=0))
    with pytest.raises(ValueError, match="degrees"):
        outdoor.turned(float("nan"))
