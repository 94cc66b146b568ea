"""Pictures of data: render_sphere takes measured data (MerlBRDF) and any callable
f(wi, wo) beside a Material, estimated by a cosine lobe's draws and the map's,
weighted by the power heuristic. Held to the Material's own picture (the
model's sampler) through the float64 reference as the callable, so that a wrong
pdf, cosine or frame shows as a wrong mean or a wrong picture."""

import numpy as np
import pytest

import principled_brdf as pb
from principled_brdf.cli import main
from principled_brdf.render import render_sphere

GOLD = pb.Material(base_color=(0.9, 0.6, 0.25), metallic=1.0, roughness=0.35)
PLASTIC = pb.Material(base_color=(0.8, 0.3, 0.2), roughness=0.4, specular=0.5)
RESOLUTION = 40


def reference_of(material):
    return lambda wi, wo: pb.reference.eval(material, wi, wo)


def agreement(material, picture):
    """(largest relative error of the channels' means over the sphere, relative L2 per pixel)"""
    expected = render_sphere(material, RESOLUTION, environment=picture["environment"], samples=256)
    inside = expected.sum(axis=-1) > 0.0
    got = picture["image"]
    means = np.abs(got[inside].mean(axis=0) / expected[inside].mean(axis=0) - 1.0).max()
    return means, np.linalg.norm(got - expected) / np.linalg.norm(expected)


@pytest.mark.parametrize("material", [GOLD, PLASTIC], ids=["gold", "plastic"])
@pytest.mark.parametrize("environment", ["sky", "studio"])
def test_a_callable_renders_as_the_material_does(material, environment):
    image = render_sphere(reference_of(material), RESOLUTION, environment=environment, samples=256)
    assert image.shape == (RESOLUTION, RESOLUTION, 3) and image.dtype == np.float32
    means, per_pixel = agreement(material, {"image": image, "environment": environment})
    assert means < 0.02, means  # (a wrong cosine, pdf or frame is tens of per cent)
    assert per_pixel < 0.12, per_pixel


def test_measured_data_renders_as_the_material_it_was_made_from(tmp_path):
    path = tmp_path / "gold.binary"
    pb.measured.save_merl(path, reference_of(GOLD))
    image = render_sphere(pb.measured.load_merl(path), RESOLUTION, environment="studio", samples=256)
    means, per_pixel = agreement(GOLD, {"image": image, "environment": "studio"})
    assert means < 0.02, means  # (the nearest cell of 1° in θd and 2° in φd, beside the noise)
    assert per_pixel < 0.15, per_pixel


def test_the_key_light_alone_is_f_cos():
    light = np.array([-0.5, 0.6, 0.75])
    data = render_sphere(reference_of(PLASTIC), RESOLUTION, environment=None, light=light)
    model = render_sphere(PLASTIC, RESOLUTION, environment=None, light=light)
    np.testing.assert_allclose(data, model, rtol=2e-5, atol=1e-6)


def test_cells_without_data_add_nothing():
    def half_missing(wi, wo):
        f = pb.reference.eval(PLASTIC, wi, wo)
        return np.where(wi[..., :1] > 0.0, np.nan, f)
    image = render_sphere(half_missing, RESOLUTION, environment="sky", samples=64)
    full = render_sphere(reference_of(PLASTIC), RESOLUTION, environment="sky", samples=64)
    assert np.isfinite(image).all() and (image >= 0.0).all()
    assert 0.2 < image.sum() / full.sum() < 0.8
    nothing = render_sphere(lambda wi, wo: np.full(np.broadcast(wi, wo).shape, np.nan), RESOLUTION)
    assert not nothing.any()


@pytest.mark.parametrize("returned, error, words", [
    (lambda shape: -np.ones(shape), ValueError, "-1.0"),
    (lambda shape: np.full(shape, np.inf), ValueError, "inf"),
    (lambda shape: np.ones(shape[:-1]), ValueError, "shape"),
    (lambda shape: np.full(shape, "x"), TypeError, "returned"),
])
def test_a_callable_returning_bad_values_is_a_named_error(returned, error, words):
    with pytest.raises(error, match=words) as raised:
        render_sphere(lambda wi, wo: returned(np.broadcast(wi, wo).shape), 8, samples=4)
    assert str(raised.value).startswith("material:")


def test_what_only_a_material_has_is_refused_for_data():
    data = reference_of(PLASTIC)
    with pytest.raises(ValueError, match="energy_compensation"):
        render_sphere(data, 8, energy_compensation=True)
    with pytest.raises(ValueError, match="ambient"):
        render_sphere(data, 8, ambient=0.1)
    with pytest.raises(TypeError, match="material"):
        render_sphere(3, 8)


def test_the_command_line_renders_a_merl_file(tmp_path, capsys):
    path = tmp_path / "plastic.binary"
    pb.measured.save_merl(path, reference_of(PLASTIC))
    output = tmp_path / "plastic.npy"
    assert main(["render", "--merl", str(path), "--environment", "sky", "--resolution", "24", "--samples", "16",
                 "--output", str(output)]) == 0
    expected = render_sphere(pb.measured.load_merl(path), 24, environment="sky", samples=16)
    np.testing.assert_array_equal(np.load(output), expected)
    assert "MERL" in capsys.readouterr().out
    assert main(["render", "--merl", str(path), "--preset", "gold", "--output", str(tmp_path / "x.png")]) == 2
    assert "--merl" in capsys.readouterr().err and not (tmp_path / "x.png").exists()


def test_lit_sphere_takes_data():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ax = pb.plot.lit_sphere(reference_of(PLASTIC), resolution=16, environment_samples=8)
    drawn = np.asarray(ax.get_images()[0].get_array())
    assert drawn.shape == (16, 16, 4)
    expected = pb.render.to_srgb8(render_sphere(reference_of(PLASTIC), 16, samples=8))
    inside = drawn[..., 3] > 0
    assert np.abs(drawn[inside, :3].astype(float) - expected[inside].astype(float)).max() <= 1
    plt.close(ax.figure)
    with pytest.raises(TypeError, match="material"):
        pb.plot.lit_sphere(3, resolution=16)


def test_render_environment_takes_data_as_render_sphere_without_its_key_light():
    data = reference_of(GOLD)
    alone = pb.render.render_environment(data, 24, "studio", samples=16)
    assert alone.dtype == np.float64 and alone.shape == (24, 24, 3) and alone.max() > 0.1
    np.testing.assert_array_equal(alone.astype(np.float32),
                                  render_sphere(data, 24, environment="studio", samples=16, light_intensity=0.0))
