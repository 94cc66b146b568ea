"""Bad input at the entry points beyond the kernels: pb.fit, MERL files, the explorer and the
command line. Each call returns a finite, fully written result or raises a ValueError/TypeError
naming the argument (README "Bad input"); each test here failed before its fix."""

from __future__ import annotations

import os
import threading

import numpy as np
import pytest

import principled_brdf as pb
from conftest import random_direction_pairs, seeded_rng


def pairs(n, key="bad-entry"):
    return random_direction_pairs(seeded_rng(key), n, min_cos=0.05)


# ---------------------------------------------------------------------------------------------
# pb.fit


def test_fit_a_batch_with_a_problem_without_data_fits_the_others():
    wi, wo = pairs(400)
    truth = pb.Material(base_color=(0.6, 0.3, 0.2), roughness=0.4)
    measured = pb.reference.eval(truth, wi, wo)
    batch = np.stack([measured, np.full_like(measured, np.nan), measured])
    start = dict(roughness=0.7)
    result = pb.fit(wi, wo, batch, init=start, fit=["base_color", "roughness"])
    assert list(result.success) == [True, False, True]
    assert result.message[1].startswith("no data")
    assert result.cost[1] == 0.0 and result.iterations[1] == 0 and np.isnan(result.residuals[1]).all()
    np.testing.assert_array_equal(result.slots[1], np.asarray(pb.Material(**start).packed(()), float).reshape(-1))
    np.testing.assert_allclose(result.material.roughness[[0, 2]], 0.4, atol=1e-4)
    assert np.isfinite(result.slots).all() and np.isfinite(result.cost).all()
    single = pb.fit(wi, wo, np.full_like(measured, np.nan), fit=["roughness"])  # one problem, no data
    assert not single.success and single.message.startswith("no data") and single.cost == 0.0


@pytest.mark.parametrize("loss", ["relative", "log", "linear"])
def test_fit_a_black_texel_is_as_dark_as_the_model_allows(loss):
    wi, wo = pairs(400, "bad-entry-black")
    measured = pb.reference.eval(pb.Material(roughness=0.3), wi, wo)
    batch = np.stack([np.zeros_like(measured), measured])
    result = pb.fit(wi, wo, batch, loss=loss, fit=["base_color", "roughness", "specular", "metallic"])
    assert result.success.all() and np.isfinite(result.cost).all() and np.isfinite(result.residuals).all()
    black = pb.reference.eval(result.material.replace(**{k: np.asarray(getattr(result.material, k))[0]
                                                        for k in pb.PARAMETERS}), wi, wo)
    facing = (wi[:, 2] > 0.5) & (wo[:, 2] > 0.5)  # away from grazing, where Schlick's Fresnel keeps some specular
    assert black[facing].max() < 0.02 * measured[facing].mean()
    assert np.all(result.material.base_color[0] < 1e-3)
    np.testing.assert_allclose(result.material.roughness[1], 0.3, atol=1e-3)


@pytest.mark.parametrize("bounds, error, match", [
    ({"roughness": 0.3}, TypeError, r"bounds\['roughness'\]: expected a \(lower, upper\) pair"),
    ({"roughness": (0.1, 0.2, 0.3)}, ValueError, r"bounds\['roughness'\]: expected a \(lower, upper\) pair"),
    ({"roughness": ("a", "b")}, TypeError, r"bounds\['roughness'\]"),
    ({"roughness": (None, 1.0)}, TypeError, r"bounds\['roughness'\]"),
    ({"roughness": (float("nan"), 0.5)}, ValueError, r"bounds\['roughness'\].*NaN"),
    ({"roughness": (0.6, 0.5)}, ValueError, r"bounds\['roughness'\]"),
    ([("roughness", (0.0, 1.0))], TypeError, "bounds: expected a mapping"),
])
def test_fit_malformed_bounds_name_bounds(bounds, error, match):
    wi, wo = pairs(50)
    with pytest.raises(error, match=match):
        pb.fit(wi, wo, pb.reference.eval(pb.Material(), wi, wo), bounds=bounds)


def test_fit_equal_bounds_hold_the_parameter():
    wi, wo = pairs(400)
    truth = pb.Material(base_color=(0.6, 0.3, 0.2), roughness=0.4, metallic=0.3)
    measured = pb.reference.eval(truth, wi, wo)
    result = pb.fit(wi, wo, measured, init=dict(base_color=(0.6, 0.3, 0.2), metallic=0.6),
                    fit=["roughness", "metallic"], bounds={"roughness": (0.4, 0.4)})
    assert result.success and result.names == ("metallic",)
    assert result.material.roughness == 0.4 and result.material.metallic == pytest.approx(0.3, abs=1e-4)
    held = pb.fit(wi, wo, measured, fit=["roughness"], bounds={"roughness": (0.25, 0.25)})  # nothing left to fit
    assert held.success and held.names == () and held.material.roughness == 0.25 and held.iterations == 0
    assert held.message.startswith("nothing to fit") and np.isfinite(held.cost) and held.cost > 0


@pytest.mark.parametrize("value, error", [(0, ValueError), (-3, ValueError), (1.5, TypeError), (True, TypeError)])
def test_fit_max_iterations_is_a_positive_integer(value, error):
    wi, wo = pairs(50)
    with pytest.raises(error, match="max_iterations"):
        pb.fit(wi, wo, pb.reference.eval(pb.Material(), wi, wo), max_iterations=value)


@pytest.mark.parametrize("shape", [(7,), (50, 3), (2, 50), (1, 50, 1)])
def test_fit_wrongly_shaped_weights_name_weights(shape):
    wi, wo = pairs(50)
    with pytest.raises(ValueError, match=r"weights: expected shape \(50,\)"):
        pb.fit(wi, wo, pb.reference.eval(pb.Material(), wi, wo), weights=np.ones(shape))


def test_concurrent_fits_restore_the_blas_threads(monkeypatch):
    """Two fits that overlap, the first one in leaving first: the BLAS limit afterwards is the one before."""
    threadpoolctl = pytest.importorskip("threadpoolctl")
    import scipy.optimize

    def blas_threads():
        return [info["num_threads"] for info in threadpoolctl.threadpool_info() if info["user_api"] == "blas"]

    if not blas_threads():
        pytest.skip("no BLAS that threadpoolctl controls")
    wi, wo = pairs(200)
    measured = pb.reference.eval(pb.Material(roughness=0.3), wi, wo)
    original = scipy.optimize.least_squares
    first_inside, second_inside, first_done = threading.Event(), threading.Event(), threading.Event()
    errors = []

    def least_squares(*args, **kwargs):  # runs inside the fit's BLAS limit
        if threading.current_thread().name == "first":
            first_inside.set()
            assert second_inside.wait(60)
        else:
            second_inside.set()
            assert first_done.wait(60)
        return original(*args, **kwargs)

    def run(name):
        try:
            pb.fit(wi, wo, measured, fit=["roughness"], max_iterations=5)
        except BaseException as error:  # reported below
            errors.append(error)
        finally:
            if name == "first":
                first_done.set()

    monkeypatch.setattr(scipy.optimize, "least_squares", least_squares)
    before = blas_threads()
    if max(before) < 2:
        pytest.skip("BLAS runs on one thread already")
    first = threading.Thread(target=run, args=("first",), name="first")
    first.start()
    assert first_inside.wait(60)
    second = threading.Thread(target=run, args=("second",), name="second")
    second.start()
    first.join(60)
    second.join(60)
    assert not errors, errors
    assert blas_threads() == before


# ---------------------------------------------------------------------------------------------
# MERL files

MERL_CELLS = 90 * 90 * 180


def write_merl(path, stored):
    with open(path, "wb") as f:
        np.asarray((90, 90, 180), dtype="<i4").tofile(f)
        np.asarray(stored, dtype="<f8").tofile(f)


def test_load_merl_from_a_file_descriptor_leaves_it_open(tmp_path):
    stored = np.full((3, 90, 90, 180), 1500.0)
    stored[1, 2, 3, 4] = -1.0  # no data
    path = tmp_path / "grey.binary"
    write_merl(path, stored)
    descriptor = os.open(path, os.O_RDONLY)
    try:
        table = pb.measured.load_merl(descriptor)
        os.fstat(descriptor)  # still open: an OSError (EBADF) otherwise
        assert os.lseek(descriptor, 0, os.SEEK_CUR) == path.stat().st_size
    finally:
        os.close(descriptor)
    assert np.isnan(table.table[1, 2, 3, 4]) and table.table[0, 0, 0, 0] == 1.0
    np.testing.assert_array_equal(pb.measured.load_merl(str(path)).table, table.table, strict=True)


@pytest.mark.parametrize("value", [np.inf, -np.inf, np.nan])
def test_load_merl_refuses_stored_values_that_are_not_finite(tmp_path, value):
    stored = np.full((3, 90, 90, 180), 1500.0)
    stored[2, 10, 20, 30] = value
    stored[0, 0, 0, 0] = -1.0  # no data, which is fine
    path = tmp_path / "bad.binary"
    write_merl(path, stored)
    cell = r"bad\.binary: channel 2 \(blue\), cell \(θh 10, θd 20, φd 30\)"
    with pytest.raises(ValueError, match=cell + ".*not finite"):
        pb.measured.load_merl(path)


@pytest.mark.parametrize("path", [1.5, True, None, ["x.binary"]])
def test_load_merl_path_of_the_wrong_type(path):
    with pytest.raises(TypeError, match="path: expected a path or an open file descriptor"):
        pb.measured.load_merl(path)


# ---------------------------------------------------------------------------------------------
# The explorer


@pytest.fixture(scope="module")
def explorer():
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    pytest.importorskip("ipywidgets")
    ex = pb.explorer(resolution=32)
    yield ex
    ex.close()


@pytest.mark.parametrize("control", ["roughness", "light_theta", "view_phi", "exposure"])
@pytest.mark.parametrize("value", [float("nan"), float("inf"), -float("inf")])
def test_explorer_refuses_values_that_are_not_finite_and_keeps_working(explorer, control, value):
    import traitlets

    explorer.reset()
    slider = explorer.sliders[control] if control in explorer.sliders else getattr(explorer, control)
    kept = slider.value
    with pytest.raises(ValueError, match=f"{control}: {value!r} is not a finite number") as error:
        slider.value = value
    assert isinstance(error.value, traitlets.TraitError)  # as the widgets' own refusals
    assert slider.value == kept
    before = explorer.images["sphere"].value
    explorer.sliders["metallic"].value = 0.9  # later changes draw as before
    assert explorer.images["sphere"].value != before
    assert explorer.material.metallic == 0.9


def test_explorer_refuses_values_beyond_what_the_pictures_take(explorer):
    explorer.reset()
    explorer.exposure.max = 1e6  # a wider range than the explorer's
    with pytest.raises(ValueError, match="exposure: 1000.0 is beyond 64"):
        explorer.exposure.value = 1e3
    explorer.sliders["specular"].max = 1e30
    with pytest.raises(ValueError, match="specular: 1e\\+30 is beyond 1e\\+20"):
        explorer.sliders["specular"].value = 1e30
    with pytest.raises(ValueError, match="material: specular"):
        explorer.set_material(pb.Material(specular=1e21))
    explorer.reset()
    assert explorer.refresh() == {} and explorer.material == pb.Material()


def test_explorer_after_close_ignores_changes():
    pytest.importorskip("matplotlib").use("Agg")
    pytest.importorskip("ipywidgets")
    ex = pb.explorer(resolution=16)
    ex.close()
    ex.sliders["roughness"].value = 0.9  # was a KeyError from the dropped figures
    ex.base_color.value = "#ff0000"
    ex.preset.value = "gold"
    ex.light_theta.value = 10.0
    assert ex.refresh() == {}
    ex.set_material("chrome")
    ex.reset()
    ex.close()  # twice: nothing more


# ---------------------------------------------------------------------------------------------
# The command line and pb.render


@pytest.fixture
def no_work(monkeypatch):
    """The jobs themselves fail the test: a refused option never starts one (nor hangs the test)."""
    import principled_brdf.benchmark
    import principled_brdf.demo

    def job(*args, **kwargs):
        raise AssertionError("the job started")

    monkeypatch.setattr(pb.render, "render_sphere", job)
    monkeypatch.setattr(pb.render, "_sample", job)
    monkeypatch.setattr(principled_brdf.demo, "run", job)
    monkeypatch.setattr(principled_brdf.benchmark, "compare_with_numpy", job)


def exit_status(capsys, args):
    from principled_brdf.cli import main

    try:
        status = main(args)
    except SystemExit as stop:  # argparse's errors
        status = stop.code
    return status, capsys.readouterr().err


@pytest.mark.parametrize("args, option, message", [
    (["render", "--samples", "65536", "--resolution", "1024"], "--samples", "at most 16384 per pixel"),
    (["render", "--samples", "65537"], "--samples", "at most 65536 samples per pixel"),
    (["render", "--samples", "0"], "--samples", "positive integer"),
    (["render", "--resolution", "1"], "--resolution", "at least 2 pixels"),
    (["render", "--exposure", "1e300"], "--exposure", "at most 1e+20"),
    (["render", "--param", "roughness=1e5"], "--param", "roughness: 100000.0 is beyond 10000"),
    (["render", "--param", "specular=1e30"], "--param", "specular: 1e+30 is beyond 1e+20"),
    (["demo", "--repeats", "100000000"], "--repeats", "at most 100 repeats"),
    (["bench", "--repeats", "101"], "--repeats", "at most 100 repeats"),
    (["bench", "--repeats", "1e8"], "--repeats", "positive integer"),
    (["demo", "--pairs", str(1 << 27), "--repeats", "17"], "--repeats", "at most 16 repeats"),
])
def test_cli_numeric_options_are_bounded(capsys, tmp_path, no_work, args, option, message):
    output = tmp_path / "x.png"
    status, err = exit_status(capsys, args + (["--output", str(output)] if args[0] == "render" else []))
    assert status == 2
    lines = [line for line in err.splitlines() if line.strip() and not line.startswith(("usage:", " "))]
    assert len(lines) == 1 and "error" in lines[0] and option in lines[0] and message in lines[0], err
    assert not output.exists()


def test_cli_light_of_extreme_magnitude_is_a_direction(capsys, tmp_path):
    for light in ("1e308,1e308,1e308", "5e-324,5e-324,5e-324"):
        output = tmp_path / "x.npy"
        status, err = exit_status(capsys, ["render", "--light", light, "--resolution", "8", "--samples", "2",
                                           "--output", str(output)])
        assert status == 0, err
        expected = pb.render.render_sphere(pb.Material(), 8, light=(1.0, 1.0, 1.0), samples=2)
        np.testing.assert_array_equal(np.load(output), expected)


@pytest.mark.parametrize("kwargs, error, match", [
    (dict(resolution=1024, samples=65536), ValueError, "samples: 65536 per pixel over 1048576 pixels"),
    (dict(resolution=64, samples=1 << 17), ValueError, "samples: expected 1 to 65536"),
    (dict(resolution=64, samples=0), ValueError, "samples: expected 1 to 65536"),
    (dict(resolution=64, samples=-5, environment=None), ValueError, "samples: expected 1 to 65536"),
    (dict(resolution=64, samples=8.0), TypeError, "samples: expected an integer"),
])
def test_render_refuses_unbounded_samples(monkeypatch, kwargs, error, match):
    def sample(*args, **kwargs):  # the refused job would start here: fail now rather than run for hours
        raise AssertionError("the job started")

    monkeypatch.setattr(pb.render, "_sample", sample)
    with pytest.raises(error, match=match):
        pb.render.render_sphere(pb.Material(), **kwargs)
    if "environment" not in kwargs:
        with pytest.raises(error, match=match):
            pb.render.render_environment(pb.Material(), kwargs["resolution"], samples=kwargs["samples"])


def test_render_counts_every_sphere_of_a_batch(monkeypatch):
    def job(*args, **kwargs):
        raise AssertionError("the job started")

    monkeypatch.setattr(pb.render, "sphere_frames", job)
    batch = pb.Material(roughness=np.full((1 << 12, 1, 1), 0.5))  # 4096 spheres of 2048² pixels: 2^34 pixels
    with pytest.raises(ValueError, match="samples: 2 per pixel over 17179869184 pixels"):
        pb.render.render_sphere(batch, 2048, samples=2)


def test_render_light_of_extreme_magnitude():
    expected = pb.render.render_sphere(pb.Material(), 8, light=(1.0, 1.0, 1.0), samples=2)
    for light in ((1e308, 1e308, 1e308), (5e-324, 5e-324, 5e-324)):
        np.testing.assert_array_equal(pb.render.render_sphere(pb.Material(), 8, light=light, samples=2), expected)


@pytest.mark.parametrize("change, match", [
    (dict(weights=np.r_[np.ones(10), 1e300, np.ones(39)]), r"weights\[10\]: 1e\+300 is not a weight"),
    (dict(weights=np.r_[np.ones(3), np.nan, np.ones(46)]), r"weights\[3\]: nan is not a weight"),
    (dict(weights=np.r_[np.ones(3), -1.0, np.ones(46)]), r"weights\[3\]: -1.0 is not a weight"),
    (dict(scale=1e300), r"measured\[0, 0\]: .* is beyond 3.402823e\+38"),
])
def test_fit_values_whose_squares_overflow_are_refused(change, match):
    """The cost (half the sum of weighted squared residuals) of these was inf."""
    wi, wo = pairs(50)
    measured = pb.reference.eval(pb.Material(), wi, wo) * change.pop("scale", 1.0)
    with pytest.raises(ValueError, match=match):
        pb.fit(wi, wo, measured, loss="linear", **change)
