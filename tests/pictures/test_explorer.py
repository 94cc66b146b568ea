"""pb.explorer(): the ipywidgets BRDF explorer, driven headless.

Each control changes the pictures that show it and no other; the sphere is a
PNG of the stated size; the sliders cannot leave the parameters' domains; the
energy-compensation checkbox follows pb.eval's signature; without ipywidgets
the call says what to install.
"""

from __future__ import annotations

import io
import struct
import sys
import zlib

import numpy as np
import pytest
import traitlets

matplotlib = pytest.importorskip("matplotlib")  # a test extra: always there under `make test`
matplotlib.use("Agg")
import ipywidgets  # noqa: E402 - a test extra: a missing one fails here, it is not skipped
import matplotlib.image as mpimg  # noqa: E402

import principled_brdf as pb  # noqa: E402
from principled_brdf import explorer_app as explorer_module  # noqa: E402 - pb.explorer is the function

OUTPUTS = ("sphere", "polar", "slice", "albedo")


@pytest.fixture(scope="module")
def shared():
    ex = pb.explorer(resolution=64)
    yield ex
    ex.close()


@pytest.fixture
def explorer(shared):
    """The module's explorer, every control back to where pb.explorer() put it (one update)."""
    shared.reset()
    return shared


def snapshot(ex) -> dict:
    return {name: ex.images[name].value for name in OUTPUTS}


def changed(before: dict, after: dict) -> set:
    return {name for name in OUTPUTS if before[name] != after[name]}


def png_size(data: bytes) -> tuple:
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    length, kind = struct.unpack(">I4s", data[8:16])
    assert kind == b"IHDR" and length == 13
    width, height = struct.unpack(">II", data[16:24])
    assert zlib.crc32(data[12:29]) & 0xFFFFFFFF == struct.unpack(">I", data[29:33])[0]
    return width, height


def pixels(data: bytes) -> np.ndarray:
    return mpimg.imread(io.BytesIO(data), format="png")


def test_import_does_not_import_ipywidgets():
    import subprocess

    code = ("import sys, principled_brdf as pb; assert callable(pb.explorer); "
            "assert 'ipywidgets' not in sys.modules and 'matplotlib' not in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60)


def test_builds_with_every_picture_and_the_documented_parts():
    ex = pb.explorer()
    try:
        assert ex.resolution == 192 and ex.model.value == "disney2014" and ex.preset.value == explorer_module.CUSTOM
        assert ex.material == pb.Material()
        assert set(ex.images) == set(OUTPUTS) and set(ex.timings) == set(OUTPUTS)
        assert set(ex.sliders) == {name for name, info in pb.PARAMETERS.items() if info.slots == 1}
        for name in OUTPUTS:
            data = ex.images[name].value
            image = pixels(data)
            assert image.ndim == 3 and image[..., :3].std() > 0.02, name  # not blank
        assert png_size(ex.images["sphere"].value) == (192, 192)
        assert isinstance(ex.widget, ipywidgets.Widget)
        assert "application/vnd.jupyter.widget-view+json" in ex._repr_mimebundle_()
        assert "ms" in ex.status.value and 0.0 < ex.last_update_seconds
    finally:
        ex.close()


def test_sphere_is_a_png_of_the_stated_size(explorer):
    data = explorer.images["sphere"].value
    assert png_size(data) == (64, 64)
    image = pixels(data)
    assert image.shape == (64, 64, 4)
    assert image[0, 0, 3] == 0 and image[32, 32, 3] == 1.0  # transparent off the sphere
    # the pixels are render_sphere's (key light and the sky by default), through to_srgb8
    light = explorer_module._direction(explorer.light_theta.value, explorer.light_phi.value)
    linear = pb.render.render_sphere(explorer.material, 64, light=light, samples=explorer_module._SKY_SAMPLES)
    np.testing.assert_array_equal(np.round(image[..., :3] * 255).astype(np.uint8), pb.render.to_srgb8(linear))
    explorer.sky.value = False  # the key light alone, with a little ambient so the unlit side is not black
    linear = pb.render.render_sphere(explorer.material, 64, light=light, ambient=0.03, environment=None)
    image = pixels(explorer.images["sphere"].value)
    np.testing.assert_array_equal(np.round(image[..., :3] * 255).astype(np.uint8), pb.render.to_srgb8(linear))
    for name in ("polar", "slice", "albedo"):
        width, height = png_size(explorer.images[name].value)
        assert width > 200 and height > 150


@pytest.mark.parametrize("control, value, expected", [
    ("roughness", 0.15, set(OUTPUTS)),
    ("metallic", 1.0, set(OUTPUTS)),
    ("light_theta", 20.0, {"sphere", "polar", "slice"}),  # the light is marked on the polar plot and the slice
    ("light_phi", 300.0, {"sphere", "polar", "slice"}),
    ("view_theta", 70.0, {"polar", "slice", "albedo"}),  # the sphere is seen from +z whatever the view
    ("exposure", 1.0, {"sphere"}),
    ("log_radius", True, {"polar"}),
    ("sky", False, {"sphere"}),
    ("environment", "studio", {"sphere"}),
    ("model", "disney2012", set(OUTPUTS)),
    ("model", "disney2015", set(OUTPUTS)),
    ("preset", "gold", set(OUTPUTS)),
    ("base_color", "#3060c0", set(OUTPUTS)),
])
def test_each_control_changes_the_pictures_that_show_it(explorer, control, value, expected):
    widget = explorer.sliders[control] if control in explorer.sliders else getattr(explorer, control)
    before = snapshot(explorer)
    widget.value = value
    assert changed(before, snapshot(explorer)) == expected
    assert set(explorer.refresh()) == set()  # nothing left to draw


def test_the_2015_models_read_their_parameters_and_grey_out_the_rest(explorer):
    """spec_trans is greyed out (and held at 0) for the BRDFs; subsurface for the 2015 models, so that a
    preset with subsurface stays drawable; glass in the studio passes light (the sphere is not dark)."""
    assert explorer.sliders["spec_trans"].disabled and not explorer.sliders["subsurface"].disabled
    explorer.sliders["spec_trans"].value = 1.0
    assert float(explorer.material.spec_trans) == 0.0 and set(explorer.refresh()) == set()
    with explorer.hold():
        explorer.sliders["subsurface"].value = 0.5
        explorer.model.value = "disney2015"
        explorer.environment.value = "outdoor"
    assert explorer.sliders["subsurface"].disabled and not explorer.sliders["spec_trans"].disabled
    assert float(explorer.material.spec_trans) == 1.0 and float(explorer.material.subsurface) == 0.0
    image = pixels(explorer.images["sphere"].value)
    assert image[..., :3].mean() > 0.1
    explorer.model.value = "disney2015_thin"
    assert not explorer.sliders["diff_trans"].disabled


def test_the_2015_models_are_seen_from_below_in_the_polar_plot_and_the_albedo(explorer):
    explorer.sliders["spec_trans"].value = 1.0  # (greyed out: counts once the model reads it)
    with explorer.hold():
        explorer.model.value = "disney2015"
        explorer.view_theta.value = 150.0  # from inside the solid
    assert explorer.view_theta.value == 150.0
    polar = explorer._polar
    angles = np.asarray(polar["lines"]["total"].get_xdata())
    assert np.isclose(np.degrees(angles.min()), -180.0, atol=1.0) and np.isclose(np.degrees(angles.max()), 180.0, atol=1.0)
    transmitted = np.asarray(polar["lines"]["transmission"].get_ydata())
    assert polar["lines"]["transmission"].get_visible() and transmitted.max() > 0
    albedo_angles = np.asarray(explorer._albedo["lines"]["total"].get_xdata())
    assert albedo_angles.max() == 180.0 and not np.any(albedo_angles == 90.0)
    for name in ("polar", "slice", "albedo"):
        width, height = png_size(explorer.images[name].value)
        assert width > 200 and height > 150
    explorer.model.value = "disney2014"  # back to a BRDF: the view comes back above the surface
    assert explorer.view_theta.value == 90.0 and explorer.view_theta.max == 90.0
    angles = np.asarray(explorer._polar["lines"]["total"].get_xdata())
    assert np.degrees(angles.max()) < 90.0


def test_no_op_changes_redraw_nothing(explorer):
    before = snapshot(explorer)
    explorer.sliders["roughness"].value = explorer.sliders["roughness"].value
    explorer.model.value = "disney2014"
    assert changed(before, snapshot(explorer)) == set()
    # there and back again: the same bytes (every picture is deterministic, the albedo seeded)
    explorer.sliders["roughness"].value = 0.8
    explorer.log_radius.value = True
    assert changed(before, snapshot(explorer)) == set(OUTPUTS)
    explorer.sliders["roughness"].value = 0.5
    explorer.log_radius.value = False
    assert snapshot(explorer) == before
    assert explorer.refresh() == {}


def test_under_a_map_the_light_moves_the_plots_and_not_the_sphere(explorer):
    """A map brings its own lights (no key light): the light's direction is still f's in the
    polar plot and the slice, and the sphere is not drawn again for it."""
    explorer.environment.value = "studio"
    before = snapshot(explorer)
    explorer.light_phi.value = 200.0
    explorer.light_theta.value = 30.0
    assert changed(before, snapshot(explorer)) == {"polar", "slice"}
    explorer.sky.value = False  # the key light alone: now it lights the sphere
    before = snapshot(explorer)
    explorer.light_phi.value = 100.0
    assert changed(before, snapshot(explorer)) == {"sphere", "polar", "slice"}


def test_the_sphere_refines_pass_after_pass(explorer):
    """Each pass its own lattice shift, twice the first's samples, the picture their mean
    weighted by samples; a change starts afresh."""
    explorer.environment.value = "studio"
    first = explorer.sphere_samples
    assert first == explorer_module._MAP_SAMPLES
    one = explorer.images["sphere"].value
    assert explorer.refine(2) == 5 * first
    assert explorer.images["sphere"].value != one
    light = explorer_module._direction(explorer.light_theta.value, explorer.light_phi.value)
    passes = [pb.render.render_sphere(explorer.material, 64, light=light, environment="studio", samples=s, seed=k)
              for k, s in enumerate((first, 2 * first, 2 * first))]
    mean = (passes[0] * first + passes[1] * (2 * first) + passes[2] * (2 * first)) / (5 * first)
    expected = explorer_module._rgba(mean, explorer._inside, 1.0)
    np.testing.assert_array_equal(pixels(explorer.images["sphere"].value), pixels(pb.render.png_bytes(expected)))
    assert f"{5 * first} samples/px (refining)" in explorer.status.value
    explorer.sliders["roughness"].value = 0.3
    assert explorer.sphere_samples == first


def test_glass_starts_fast_and_refines_while_the_kernel_is_idle(explorer):
    """In a running event loop (a notebook's kernel) the passes come by themselves."""
    import asyncio

    async def change_then_rest():
        explorer.model.value = "disney2015"
        explorer.sliders["spec_trans"].value = 1.0
        assert explorer.sphere_samples == explorer_module._THROUGH_SAMPLES
        await asyncio.sleep(2.0)
        return explorer.sphere_samples
    assert asyncio.run(change_then_rest()) > explorer_module._THROUGH_SAMPLES
    # and nothing refines a sphere without sampling: the key light alone on a BRDF
    explorer.model.value = "disney2014"
    explorer.sky.value = False
    assert explorer.refine(3) == explorer.sphere_samples == explorer_module._SKY_SAMPLES


def test_the_front_ends_float_echo_redraws_nothing(explorer):
    """The browser sends a slider's value back through JavaScript's float formatting: 130 as
    130.00000000000003. On the slider's grid within 1e-9 of a step, it is the grid value."""
    explorer.light_phi.value = 130.0
    before = snapshot(explorer)
    explorer.light_phi.value = 130.00000000000003
    assert explorer.light_phi.value == 130.0
    explorer.sliders["roughness"].value = 0.29000000000000004
    assert explorer.sliders["roughness"].value == 0.29
    explorer.sliders["roughness"].value = 0.5
    assert snapshot(explorer) == before and explorer.refresh() == {}
    explorer.sliders["roughness"].value = 0.333  # off the grid: kept as given
    assert explorer.sliders["roughness"].value == 0.333


def test_static_output_carries_the_pictures(explorer):
    """nbconvert, GitHub and other pages without the widget's JavaScript show the pictures."""
    import base64

    bundle = explorer._repr_mimebundle_()
    assert "application/vnd.jupyter.widget-view+json" in bundle
    assert base64.b64decode(bundle["image/png"]) == explorer.images["sphere"].value
    html = bundle["text/html"]
    for name in OUTPUTS:
        encoded = base64.b64encode(explorer.images[name].value).decode()
        assert f'alt="{name}"' in html and encoded in html
    assert bundle["text/plain"].startswith("Explorer(Material(")


def test_preset_sets_every_slider_in_one_update(explorer, monkeypatch):
    calls = []
    real = explorer_module.Explorer.refresh
    monkeypatch.setattr(explorer_module.Explorer, "refresh", lambda self: calls.append(1) or real(self))
    explorer.preset.value = "car_paint"
    assert len(calls) == 1
    expected = pb.presets.get("car_paint")
    assert explorer.material == expected
    assert explorer.base_color.value == explorer_module._hex(expected.base_color)
    # a slider moved by hand: no longer the preset
    explorer.sliders["clearcoat"].value = 0.3
    assert explorer.preset.value == explorer_module.CUSTOM
    assert explorer.material == expected.replace(clearcoat=0.3)
    # a preset beyond a slider's UI range widens it (the domain goes on)
    explorer.set_material(pb.Material(sheen=2.5, roughness=1.5))
    assert explorer.sliders["sheen"].value == 2.5 and explorer.sliders["sheen"].max >= 2.5
    assert explorer.material.roughness == 1.5


def test_color_picker_is_srgb(explorer):
    explorer.base_color.value = "#ff8000"
    np.testing.assert_allclose(explorer.material.base_color, pb.srgb_to_linear(np.array([255, 128, 0], np.uint8)))
    explorer.base_color.value = "#fff"
    np.testing.assert_array_equal(explorer.material.base_color, (1.0, 1.0, 1.0))
    explorer.base_color.value = "red"  # the picker's text field takes CSS names too
    np.testing.assert_array_equal(explorer.material.base_color, (1.0, 0.0, 0.0))
    # a preset's linear color is kept exactly, not rounded through the picker's 8 bits
    explorer.preset.value = "gold"
    np.testing.assert_array_equal(explorer.material.base_color, pb.presets.get("gold").base_color)
    explorer.base_color.value = "#c08040"  # a color picked: no longer the preset
    assert explorer.preset.value == explorer_module.CUSTOM


def test_sliders_keep_to_the_parameters_domains(explorer):
    with explorer.hold():
        check_slider_domains(explorer)
    assert explorer.material == pb.Material(base_color=pb.Material().base_color, **{
        name: pb.PARAMETERS[name].lower for name in explorer.sliders})  # at the lower bounds: a valid material
    with pytest.raises(traitlets.TraitError):
        explorer.model.value = "disney2099"
    with pytest.raises(traitlets.TraitError):
        explorer.preset.value = "unobtainium"
    with explorer.hold():
        for slider in (explorer.light_theta, explorer.view_theta):
            assert (slider.min, slider.max) == (0.0, 90.0)
            slider.value = 90.0  # on the horizon: f = 0, the pictures still draw
    assert "below the horizon" in explorer._slice["ax"].get_title()


def check_slider_domains(explorer):
    for name, slider in explorer.sliders.items():
        info = pb.PARAMETERS[name]
        assert slider.min == info.lower
        if np.isfinite(info.upper):
            assert slider.max == info.upper
            slider.value = info.upper + 1.0
            assert slider.value == info.upper
        else:
            assert slider.max >= 1.0
        slider.value = info.lower - 1.0
        assert slider.value == info.lower, name


def test_arguments():
    ex = pb.explorer("gold", model="disney2012", resolution=32)
    try:
        assert ex.preset.value == "gold" and ex.model.value == "disney2012"
        assert ex.material == pb.presets.get("gold")
        assert png_size(ex.images["sphere"].value) == (32, 32)
    finally:
        ex.close()
    with pytest.raises(ValueError, match="model"):
        pb.explorer(model="disney2099")
    with pytest.raises(ValueError, match="resolution"):
        pb.explorer(resolution=1)
    with pytest.raises(TypeError, match="resolution"):
        pb.explorer(resolution=64.0)
    with pytest.raises(ValueError, match="material: .*unknown preset"):
        pb.explorer("unobtainium")
    with pytest.raises(TypeError, match="material"):
        pb.explorer(42)
    with pytest.raises(ValueError, match="uniform"):
        pb.explorer(pb.Material(roughness=np.array([0.1, 0.2])))


def test_energy_compensation_checkbox_reaches_every_picture(monkeypatch):
    real_eval_lobes, real_albedo, real_render = (explorer_module._eval_lobes, explorer_module._albedo,
                                                 pb.render.render_sphere)
    seen = []

    def recorded(name, function):
        def call(*args, energy_compensation, **options):
            seen.append((name, energy_compensation))
            return function(*args, energy_compensation=energy_compensation, **options)
        return call

    monkeypatch.setattr(explorer_module, "_eval_lobes", recorded("lobes", real_eval_lobes))
    monkeypatch.setattr(explorer_module, "_albedo", recorded("albedo", real_albedo))
    monkeypatch.setattr(pb.render, "render_sphere", recorded("sphere", real_render))
    ex = pb.explorer(resolution=32)
    try:
        assert isinstance(ex.energy_compensation, ipywidgets.Checkbox)
        assert ex.energy_compensation in ex.widget.children[0].children
        assert sorted(seen) == [("albedo", False), ("lobes", False), ("lobes", False), ("sphere", False)]
        seen.clear()
        before = ex.images["albedo"].value
        ex.energy_compensation.value = True
        # the sphere, the polar plot, the slice and the albedo, each with the real kernels
        assert sorted(seen) == [("albedo", True), ("lobes", True), ("lobes", True), ("sphere", True)]
        assert ex.images["albedo"].value != before
    finally:
        ex.close()


def test_without_ipywidgets_the_call_says_what_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "ipywidgets", None)  # import ipywidgets raises ImportError
    with pytest.raises(ImportError, match="pip install ipywidgets"):
        pb.explorer()


def test_update_time(explorer):
    # every picture redrawn after a material change; generous for a loaded CI machine (about 0.3 s idle)
    explorer.sliders["roughness"].value = 0.3
    assert set(explorer.timings) == set(OUTPUTS)
    assert explorer.last_update_seconds < 5.0
