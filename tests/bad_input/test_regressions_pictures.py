"""Regressions of the pictures' entry points (docs/bad-input.md, docs/rendering-and-plots.md,
docs/command-line.md): callable environments, environment maps and their helpers, what
``environment=`` and the key light mean, albedo and MERL arguments, and the command line's
``--output`` and demo ``--resolution``. Each test failed before its fix; all are quick
(tiny pictures, few samples, the jobs that must not start replaced by a failure)."""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb
from principled_brdf import procedural_environments
from principled_brdf.environment import MAX_MAP_PIXELS, Environment

WHITE_METAL = pb.Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=0.5)
GLASS = pb.Material(base_color=(1.0, 1.0, 1.0), spec_trans=1.0, roughness=0.05, ior=1.5)


def white_furnace(direction):
    return np.ones(np.shape(direction), np.float32)


def disc(image, radius=0.8):
    """The pixels within ``radius`` of the sphere's centre (away from the grazing rim)."""
    n = image.shape[-2]
    coords = (np.arange(n) + 0.5) / n * 2 - 1
    x, y = np.meshgrid(coords, coords)
    return image[..., x * x + y * y < radius * radius, :]


# ---------------------------------------------------------------------------------------------
# A callable environment's radiance is checked as a map's pixels are


def nan_at_the_zenith(direction):
    radiance = np.ones(np.shape(direction), np.float32)
    radiance[np.asarray(direction)[..., 1] > 0.5] = np.nan
    return radiance


@pytest.mark.parametrize("model, material", [("disney2014", pb.Material()), ("disney2015", GLASS)])
@pytest.mark.parametrize("environment, match", [
    (nan_at_the_zenith, r"environment: the callable returned nan at direction \[.*\]"),
    (lambda d: -np.ones(np.shape(d)), r"environment: the callable returned -1.0 at direction"),
    (lambda d: np.full(np.shape(d), np.inf), r"environment: the callable returned inf at direction"),
    (lambda d: np.ones(np.shape(d)[:-1]), r"environment: expected radiance of shape \(.*, 3\).*got \("),
    (lambda d: np.ones(np.shape(d)[:-1] + (4,)), r"environment: expected radiance of shape"),
])
def test_a_callable_environment_s_radiance_is_checked(model, material, environment, match):
    with pytest.raises(ValueError, match=match):
        pb.render.render_sphere(material, 8, model=model, environment=environment, samples=4)
    with pytest.raises(ValueError, match=match):
        pb.render.render_environment(material, 8, environment, samples=4, model=model)


def test_a_callable_environment_of_strings_is_a_type_error():
    with pytest.raises(TypeError, match=r"environment: the callable returned <U1 values"):
        pb.render.render_sphere(pb.Material(), 8, environment=lambda d: np.full(np.shape(d), "a"), samples=2)


# ---------------------------------------------------------------------------------------------
# Environment maps check their arguments


@pytest.fixture(scope="module")
def small_map():
    return Environment(np.random.default_rng(3).uniform(0.1, 2.0, size=(8, 16, 3)))


@pytest.mark.parametrize("u, match", [
    ([[np.nan, 0.5]], r"u\[0, 0\]: nan is not a finite number"),
    ([[0.5, 0.2], [1.5, 0.5]], r"u\[1, 0\]: 1.5 is outside its domain \[0, 1\]"),
    ([[0.5, -0.25]], r"u\[0, 1\]: -0.25 is outside its domain \[0, 1\]"),
    ([0.5, 0.5, 0.5], r"u: expected uniforms of shape \(\.\.\., 2\), got \(3,\)"),
    (0.5, r"u: expected uniforms of shape"),
])
def test_environment_sample_checks_its_uniforms(small_map, u, match):
    with pytest.raises(ValueError, match=match):
        small_map.sample(u)


def test_environment_sample_takes_the_ends_of_0_1(small_map):
    directions, pdf, radiance = small_map.sample([[0.0, 0.0], [1.0, 1.0], [1.0, 0.5]])
    assert np.all(np.isfinite(directions)) and np.all(np.isfinite(pdf)) and np.all(pdf >= 0.0)
    np.testing.assert_allclose(np.linalg.norm(directions, axis=-1), 1.0, atol=1e-6)
    assert np.all(radiance > 0.0)


@pytest.mark.parametrize("directions, error, match", [
    ([[0.0, np.nan, 1.0]], ValueError, r"directions\[0, 1\]: nan is not a finite number"),
    ([[0.0, 0.0, 1.0], [0.0, 0.0, 1.5]], ValueError, r"directions\[1\]: length 1.5 is not 1 \(within 0.001\)"),
    ([[0.0, 1.0]], ValueError, r"directions: expected shape \(\.\.\., 3\)"),
    ([["a", "b", "c"]], TypeError, r"directions: expected real numbers"),
])
def test_environment_lookups_check_their_directions(small_map, directions, error, match):
    for call in (small_map, small_map.pdf, small_map.lookup):
        with pytest.raises(error, match=match):
            call(directions)


def test_environment_read_names_its_path():
    for path in (None, 3.5, ["map.exr"]):
        with pytest.raises(TypeError, match=r"^path: expected a path"):
            Environment.read(path)
        with pytest.raises(TypeError, match=r"^path: expected a path"):
            pb.environment.read_map(path)


@pytest.mark.parametrize("radiance", [procedural_environments.studio_radiance,
                                      procedural_environments.outdoor_radiance])
def test_the_built_in_radiance_functions_refuse_nan_and_non_unit_directions(radiance):
    with pytest.raises(ValueError, match=r"d\[1, 0\]: nan is not a finite number"):
        radiance(np.array([[0.0, 1.0, 0.0], [np.nan, 0.0, 1.0]]))
    with pytest.raises(ValueError, match=r"d\[0\]: length 2 is not 1"):
        radiance(np.array([[0.0, 2.0, 0.0]]))
    assert np.all(np.isfinite(radiance(np.array([[0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]))))


def test_a_built_in_map_s_height_is_checked_before_the_map_is_made(monkeypatch):
    """Beyond MAX_HEIGHT the map would pass MAX_MAP_PIXELS: refused naming ``height``, before
    gigabytes of map are made."""
    def made(*args):
        raise AssertionError("the map was made")

    monkeypatch.setattr(procedural_environments, "_map", made)
    highest = procedural_environments.MAX_HEIGHT
    assert highest * 2 * highest <= MAX_MAP_PIXELS < (highest + 1) * 2 * (highest + 1)
    for make in (procedural_environments.studio, procedural_environments.outdoor):
        for height in (highest + 1, 8192):
            with pytest.raises(ValueError, match=rf"^height: expected 2 to {highest} rows.*got {height}"):
                make(height)


# ---------------------------------------------------------------------------------------------
# environment= and the key light mean one thing in every entry point


def test_no_environment_is_no_environment_in_render_environment_too():
    for none in (None, False):
        image = pb.render.render_environment(pb.Material(), 8, none, samples=4)
        assert image.shape == (8, 8, 3) and not image.any()
    batch = pb.render.render_environment(pb.Material(roughness=np.array([0.2, 0.5])[:, None, None]), 8, None)
    assert batch.shape == (2, 8, 8, 3) and not batch.any()
    # the default is the sky, as in render_sphere
    np.testing.assert_array_equal(pb.render.render_environment(pb.Material(), 8, samples=4),
                                  pb.render.render_environment(pb.Material(), 8, "sky", samples=4))
    with pytest.raises(TypeError, match=r"^material: expected a principled_brdf.Material"):
        pb.render.render_environment("gold", 8, None)


def test_a_white_lossless_sphere_in_a_callable_furnace_reads_one():
    """A callable environment brings its own light, as a map does: no key light unless asked."""
    image = pb.render.render_sphere(WHITE_METAL, 16, environment=white_furnace, samples=64, energy_compensation=True)
    pixels = disc(image)
    assert abs(pixels.mean() - 1.0) < 0.02, pixels.mean()
    keyed = pb.render.render_sphere(WHITE_METAL, 16, environment=white_furnace, samples=64, energy_compensation=True,
                                    light_intensity=3.0)
    assert disc(keyed).mean() > pixels.mean() + 0.1  # the key light adds to a callable when asked
    np.testing.assert_array_equal(image, pb.render.render_sphere(WHITE_METAL, 16, environment=white_furnace,
                                                                 samples=64, energy_compensation=True,
                                                                 light_intensity=0.0))


def test_the_sky_keeps_its_key_light_however_it_is_named():
    reference = pb.render.render_sphere(pb.Material(), 8, samples=4)
    for sky in ("sky", True, pb.render.sky_environment):
        np.testing.assert_array_equal(pb.render.render_sphere(pb.Material(), 8, environment=sky, samples=4), reference)


# ---------------------------------------------------------------------------------------------
# albedo and the MERL helpers


@pytest.mark.parametrize("cos_theta_o, model, match", [
    ([0.5, 0.0], "disney2014", r"^cos_theta_o\[1\]: 0.0 is outside its domain \(0, 1\]"),
    ([[0.5, 1.0], [-0.0, 0.3]], "disney2012", r"^cos_theta_o\[1, 0\]: -0.0 is outside its domain"),
    ([0.5, -0.5, 0.0], "disney2015", r"^cos_theta_o\[2\]: 0.0 is outside its domain \[-1, 1\] without 0"),
    (0.0, "disney2014", r"^cos_theta_o: 0.0 is outside its domain"),
])
def test_albedo_names_the_element_at_grazing_incidence(cos_theta_o, model, match):
    with pytest.raises(ValueError, match=match):
        pb.albedo(pb.Material(), cos_theta_o, model=model, samples=4)


@pytest.mark.parametrize("phi_h", [True, False, np.bool_(True), np.array(True), np.array([True])])
def test_merl_pairs_refuses_booleans_for_its_angle(phi_h):
    with pytest.raises(TypeError, match=r"^phi_h: expected an angle in radians"):
        pb.measured.merl_pairs(phi_h, step=30)


def test_half_diff_to_wiwo_refuses_booleans_for_its_angles():
    for k, name in enumerate(("theta_h", "phi_h", "theta_d", "phi_d")):
        angles = [0.1, 0.2, 0.3, 0.4]
        angles[k] = True
        with pytest.raises(TypeError, match=rf"^{name}: expected an angle in radians"):
            pb.measured.half_diff_to_wiwo(*angles)
    wi, wo = pb.measured.half_diff_to_wiwo(0.1, 0.2, 0.3, np.array([0.4, 0.5]))  # numbers still pass
    assert wi.shape == wo.shape == (2, 3)


def test_save_merl_names_a_path_that_is_not_one(tmp_path):
    for path in (None, True, 2.5):
        with pytest.raises(TypeError, match=r"^path: expected a path"):
            pb.measured.save_merl(path, "not a brdf either")  # (the path is checked first)


# ---------------------------------------------------------------------------------------------
# The command line: --output checked before the work, demo --resolution bounded by its work


def exit_status(capsys, args):
    from principled_brdf.cli import main

    try:
        status = main(args)
    except SystemExit as stop:  # argparse's errors
        status = stop.code
    return status, capsys.readouterr().err


def last_line(err):
    return [line for line in err.splitlines() if line.strip() and not line.startswith(("usage:", " "))][-1]



@pytest.mark.parametrize("command", [["render", "--resolution", "8"], ["demo", "--pairs", "1000", "--repeats", "1"]])
@pytest.mark.parametrize("output", ["/proc/principled_brdf.png", "/no/such/folder/x.png"])
def test_an_unwritable_output_is_refused_before_the_work(capsys, no_work, command, output):
    status, err = exit_status(capsys, command + ["--output", output])
    assert status == 2
    line = last_line(err)
    assert "--output" in line and output in line and "Traceback" not in err, err


def test_an_output_that_is_a_folder_is_refused(capsys, no_work, tmp_path):
    (tmp_path / "folder.png").mkdir()
    status, err = exit_status(capsys, ["render", "--output", str(tmp_path / "folder.png")])
    assert status == 2 and "--output" in last_line(err) and "it is a folder" in last_line(err), err


def test_an_error_writing_the_output_names_it(capsys, monkeypatch, tmp_path):
    def refuse(path, *args, **kwargs):
        raise PermissionError(13, "Permission denied", path)

    monkeypatch.setattr(pb.render, "save_image", refuse)
    output = str(tmp_path / "x.png")
    status, err = exit_status(capsys, ["render", "--resolution", "4", "--samples", "1", "--output", output])
    assert status == 2
    assert last_line(err).endswith(f"error: argument --output: cannot write {output!r}: Permission denied"), err


def test_the_demo_s_picture_is_bounded_by_its_work(capsys, no_work, monkeypatch):
    import principled_brdf.demo as demo

    highest = demo.MAX_PICTURE_RESOLUTION
    per_sphere = demo.PICTURE_SAMPLES * demo.PICTURE_SPHERES
    assert highest**2 * per_sphere <= demo.MAX_PICTURE_WORK < (highest + 1) ** 2 * per_sphere
    for resolution in (highest + 1, 1024):
        status, err = exit_status(capsys, ["demo", "--resolution", str(resolution)])
        assert status == 2
        line = last_line(err)
        assert "--resolution" in line and f"at most {highest} pixels per sphere" in line, err
    # within the bound the job starts (here: fails at once)
    with pytest.raises(AssertionError, match="the job started"):
        exit_status(capsys, ["demo", "--resolution", str(highest)])
    # and the Python entry point keeps the same bound
    monkeypatch.undo()  # (demo.run itself, not no_work's stand-in)
    with pytest.raises(ValueError, match=rf"^resolution: expected 8 to {highest} pixels per sphere, got 1024"):
        demo.run(resolution=1024)
