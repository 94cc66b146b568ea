"""principled_brdf.plot: the notebook pictures (matplotlib, Agg backend).

Each function: draws without error, returns the documented object (Axes,
polar Axes, Figure), draws into a passed ``ax``, makes a picture that is not
blank, shows the numbers the kernel gives (probed against pb.eval, pb.albedo,
pb.render), and rejects bad arguments naming them.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

import principled_brdf as pb  # noqa: E402
import principled_brdf.plot as pbplot  # noqa: E402

REC709 = np.array([0.2126, 0.7152, 0.0722])
LOBE_NAMES = ("diffuse", "sheen", "specular", "clearcoat")

# A material with every lobe switched on, and a rough, diffuse-dominated white dielectric.
EVERYTHING = pb.Material(base_color=(0.6, 0.3, 0.2), roughness=0.4, sheen=1.0, clearcoat=0.6, clearcoat_gloss=0.3,
                         specular_tint=0.5)
ROUGH_WHITE = pb.Material(base_color=(1.0, 1.0, 1.0), roughness=1.0, specular=0.0)


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def assert_png_not_blank(figure: Figure, tmp_path, name: str) -> None:
    path = tmp_path / f"{name}.png"
    figure.savefig(path, dpi=60)
    assert path.stat().st_size > 3000
    pixels = mpimg.imread(path)
    assert pixels.ndim == 3 and pixels[..., :3].std() > 0.02


def image_of(ax) -> np.ndarray:
    assert len(ax.images) == 1
    return ax.images[0].get_array()  # a masked array where the plot masks pixels


def line(ax, label: str):
    found = [l for l in ax.get_lines() if l.get_label() == label]
    assert len(found) == 1, f"no single line labelled {label!r}: {[l.get_label() for l in ax.get_lines()]}"
    return np.asarray(found[0].get_xdata(), float), np.asarray(found[0].get_ydata(), float)


def srgb8_to_linear(values) -> np.ndarray:
    c = np.asarray(values, dtype=np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def slice_pair(theta_h, theta_d, phi_d):
    """wi, wo at (θh, θd, φd) in degrees, φh = 0, built from the half vector's frame."""
    th, td, pd = np.radians([theta_h, theta_d, phi_d])
    h = np.array([np.sin(th), 0.0, np.cos(th)])
    t = np.array([np.cos(th), 0.0, -np.sin(th)])  # tangent of h in the plane of incidence
    b = np.array([0.0, 1.0, 0.0])
    wi = np.sin(td) * np.cos(pd) * t + np.sin(td) * np.sin(pd) * b + np.cos(td) * h
    wo = 2.0 * (wi @ h) * h - wi
    return wi, wo


def test_import_does_not_need_matplotlib():
    code = ("import sys, principled_brdf, principled_brdf.plot; "
            "assert 'matplotlib' not in sys.modules, 'matplotlib imported at module import'")
    subprocess.run([sys.executable, "-c", code], check=True, timeout=60)


# --------------------------------------------------------------------------
# brdf_slice


def test_brdf_slice_draws_a_log_image_with_colorbar(tmp_path):
    ax = pbplot.brdf_slice(EVERYTHING, resolution=64)
    assert isinstance(ax, Axes)
    data = image_of(ax)
    assert data.shape == (64, 64)
    assert np.all(np.isfinite(np.ma.getdata(data)))
    assert np.ma.count_masked(data) == 0  # φd = 90: both directions above the horizon everywhere
    assert np.log(np.ma.getdata(data)).std() > 0.5
    assert len(ax.figure.axes) == 2  # the colorbar
    assert "θh" in ax.get_xlabel() and "θd" in ax.get_ylabel()
    assert_png_not_blank(ax.figure, tmp_path, "slice")


@pytest.mark.parametrize("phi_d", [90.0, 30.0])
def test_brdf_slice_values_are_pb_eval_at_probed_angles(phi_d):
    n = 90  # pixel centres at 0.5, 1.5, ... 89.5 degrees
    ax = pbplot.brdf_slice(EVERYTHING, resolution=n, phi_d=phi_d)
    data = image_of(ax)
    for row, col in [(5, 2), (40, 10), (20, 70), (80, 3), (60, 60)]:
        theta_h, theta_d = col + 0.5, row + 0.5
        wi, wo = slice_pair(theta_h, theta_d, phi_d)
        below = wi[2] <= 0 or wo[2] <= 0
        assert bool(np.ma.getmaskarray(data)[row, col]) == below, (row, col)
        if not below:
            expected = float(pb.eval(EVERYTHING, wi, wo) @ REC709)
            assert data[row, col] == pytest.approx(expected, rel=2e-4), (row, col)
    if phi_d == 30.0:
        mask = np.ma.getmaskarray(data)
        assert mask[-1, -1] and not mask[0, 0]  # the below-horizon corner is masked, top right
        assert np.all(np.isfinite(np.ma.getdata(data)))


def test_brdf_slice_of_a_rough_diffuse_material_is_smooth():
    data = np.ma.getdata(image_of(pbplot.brdf_slice(ROUGH_WHITE, resolution=64, phi_d=90.0)))
    log = np.log(data)
    # neighbouring pixels (1.4 degrees apart) differ by 2 % at most below 60 degrees (towards the
    # horizon the Fresnel factors rise quickly), and nowhere is there a kink or a peak
    # (a glossy material has first and second differences of 3 in log f at the specular peak)
    assert np.abs(np.diff(log[:42, :42], axis=0)).max() < 0.02
    assert np.abs(np.diff(log[:42, :42], axis=1)).max() < 0.02
    assert np.abs(np.diff(log, axis=0)).max() < 0.2 and np.abs(np.diff(log, axis=1)).max() < 0.2
    assert np.abs(np.diff(log, 2, axis=0)).max() < 0.03 and np.abs(np.diff(log, 2, axis=1)).max() < 0.03
    assert data.max() / data.min() < 10.0


def test_brdf_slice_rgb_channel_and_existing_axes():
    fig, (left, right) = plt.subplots(1, 2)
    assert pbplot.brdf_slice(EVERYTHING, resolution=32, channel="rgb", phi_d=30, ax=left) is left
    rgba = image_of(left)
    assert rgba.shape == (32, 32, 4) and np.all(np.isfinite(rgba)) and rgba[..., :3].std() > 0.05
    assert pbplot.brdf_slice("gold", resolution=32, channel="r", log=False, ax=right) is right
    assert len(fig.axes) == 4  # two panels, each with a color bar (grey for rgb: the brightness scale)


def test_a_linear_slice_is_not_black_and_exposure_brightens():
    # car paint's clearcoat peak is 10,000 times its body: scaled to the peak, a linear slice is black
    ax = pbplot.brdf_slice("car_paint", resolution=64, log=False)
    data, norm = np.ma.getdata(image_of(ax)), ax.images[-1].norm
    assert norm.vmax == pytest.approx(np.percentile(data, 90))
    assert np.mean(norm(data) > 0.1) > 0.25
    rgb = image_of(pbplot.brdf_slice("car_paint", resolution=64, channel="rgb", log=False))[..., :3]
    brighter = image_of(pbplot.brdf_slice("car_paint", resolution=64, channel="rgb", log=False, exposure=4))[..., :3]
    assert np.mean(rgb.max(-1) > 0.2) > 0.25
    assert np.all(brighter >= rgb - 1e-12) and brighter.mean() > rgb.mean() * 1.3
    # the color bar of an exposed slice is in f's units: its top is the range divided by the exposure
    ax = pbplot.brdf_slice("car_paint", resolution=64, log=False, exposure=4)
    assert ax.images[-1].norm.vmax == pytest.approx(norm.vmax / 4)
    with pytest.raises(ValueError, match="percentile"):
        pbplot.brdf_slice("car_paint", resolution=8, percentile=0)
    with pytest.raises(ValueError, match="exposure"):
        pbplot.brdf_slice("car_paint", resolution=8, exposure=0)


def test_brdf_slice_bad_arguments():
    with pytest.raises(ValueError, match="channel"):
        pbplot.brdf_slice(EVERYTHING, channel="hue")
    with pytest.raises(ValueError, match="resolution"):
        pbplot.brdf_slice(EVERYTHING, resolution=1)
    with pytest.raises(TypeError, match="material"):
        pbplot.brdf_slice({"roughness": 0.5})
    with pytest.raises(ValueError, match="model"):
        pbplot.brdf_slice(EVERYTHING, resolution=8, model="phong")
    with pytest.raises(TypeError, match="ax"):
        pbplot.brdf_slice(EVERYTHING, resolution=8, ax="left")
    with pytest.raises(ValueError, match="vmin"):
        pbplot.brdf_slice(EVERYTHING, resolution=8, vmin=0.0)
    assert plt.get_fignums() == []  # every check comes before any figure is made


# --------------------------------------------------------------------------
# polar_lobes


def test_polar_lobes_total_is_the_sum_of_the_lobes(tmp_path):
    ax = pbplot.polar_lobes(EVERYTHING, 40.0, resolution=181)
    assert isinstance(ax, Axes) and ax.name == "polar"
    angles, total = line(ax, "total")
    assert angles.shape == (181,) and np.all(np.isfinite(total)) and total.std() > 0
    assert angles[0] == pytest.approx(-np.pi / 2) and angles[-1] == pytest.approx(np.pi / 2)
    lobe_sum = sum(line(ax, name)[1] for name in LOBE_NAMES)
    np.testing.assert_allclose(lobe_sum, total, rtol=1e-5, atol=1e-7)
    assert_png_not_blank(ax.figure, tmp_path, "polar")


def test_polar_lobes_values_and_peak():
    theta_o = 35.0
    glossy = pb.Material(base_color=(0.5, 0.5, 0.5), roughness=0.2)
    ax = pbplot.polar_lobes(glossy, theta_o, resolution=721, cosine=True)
    angles, total = line(ax, "total")
    wo = np.array([np.sin(np.radians(theta_o)), 0.0, np.cos(np.radians(theta_o))])
    for k in (100, 250, 600):
        wi = np.array([np.sin(angles[k]), 0.0, np.cos(angles[k])])
        expected = float(pb.eval(glossy, wi, wo, cosine=True) @ REC709)
        assert total[k] == pytest.approx(expected, rel=1e-5)
    # the specular peak is at the mirror direction, on the other side of the normal
    assert np.degrees(angles[np.argmax(line(ax, "specular")[1])]) == pytest.approx(-theta_o, abs=1.0)
    assert total[0] == 0.0 and total[-1] == 0.0  # on the horizon
    # no sheen or clearcoat: those lines are left out
    assert {l.get_label() for l in ax.get_lines()} == {"diffuse", "specular", "total", "wo"}


def test_polar_lobes_log_radius_and_the_total_beside_a_single_lobe():
    # a rough white dielectric: the total is nearly all diffuse, so it is drawn as a wider band
    # beneath the lobes, where it stays visible
    ax = pbplot.polar_lobes(ROUGH_WHITE, 30, resolution=181)
    total, lobe = (next(l for l in ax.get_lines() if l.get_label() == name) for name in ("total", "diffuse"))
    assert np.median(lobe.get_ydata() / np.maximum(total.get_ydata(), 1e-30)) > 0.9
    assert total.get_linewidth() >= 2 * lobe.get_linewidth() and total.get_zorder() < lobe.get_zorder()
    # log radius: log10 f over `decades` below the peak, ticks labelled in 1/sr
    linear = pbplot.polar_lobes("car_paint", 45, resolution=181)
    logged = pbplot.polar_lobes("car_paint", 45, resolution=181, log=True, decades=3)
    f, r = line(linear, "total")[1], line(logged, "total")[1]
    floor = np.log10(f.max()) - 3
    np.testing.assert_allclose(r, np.maximum(np.log10(np.maximum(f, 1e-300)) - floor, 0.0), rtol=1e-12)
    labels = [t.get_text() for t in logged.yaxis.get_ticklabels()]
    assert 3 <= len(labels) <= 4 and all(float(text) > 0 for text in labels)  # one per decade
    assert 2 <= len(linear.yaxis.get_ticklocs()) <= 6  # a few readable radius ticks
    with pytest.raises(ValueError, match="decades"):
        pbplot.polar_lobes("car_paint", 45, log=True, decades=0)


def test_polar_lobes_into_existing_polar_axes_and_total_only():
    fig = plt.figure()
    ax = fig.add_subplot(projection="polar")
    assert pbplot.polar_lobes("car_paint", 10, lobes=False, resolution=91, ax=ax) is ax
    assert {l.get_label() for l in ax.get_lines()} == {"total", "wo"}


def test_polar_lobes_bad_arguments():
    with pytest.raises(ValueError, match="ax"):
        pbplot.polar_lobes(EVERYTHING, 30, ax=plt.figure().add_subplot())
    with pytest.raises(ValueError, match="theta_o"):
        pbplot.polar_lobes(EVERYTHING, 90)
    with pytest.raises(ValueError, match="resolution"):
        pbplot.polar_lobes(EVERYTHING, 30, resolution=1)
    with pytest.raises(ValueError, match="channel"):
        pbplot.polar_lobes(EVERYTHING, 30, channel="alpha")
    with pytest.raises(TypeError, match="material"):
        pbplot.polar_lobes(0.5, 30)


# --------------------------------------------------------------------------
# lit_sphere


def test_lit_sphere_is_render_sphere_in_srgb(tmp_path):
    material = pb.presets.get("car_paint")
    ax = pbplot.lit_sphere(material, resolution=48)
    assert isinstance(ax, Axes)
    rgba = image_of(ax)
    assert rgba.shape == (48, 48, 4) and rgba.dtype == np.uint8
    expected = pb.render.to_srgb8(pb.render.render_sphere(material, 48))
    np.testing.assert_array_equal(rgba[..., :3], expected)
    inside, _ = pb.render.sphere_frames(48)
    np.testing.assert_array_equal(rgba[..., 3] > 0, inside)  # transparent off the sphere
    assert rgba[..., :3][inside].std() > 5
    assert_png_not_blank(ax.figure, tmp_path, "sphere")


def test_lit_sphere_environment_matches_the_albedo():
    # A constant environment L = 1 with the light off shows the directional albedo E(wo);
    # at the centre of the sphere wo is (nearly) the normal.
    n, exposure = 64, 0.5
    ax = pbplot.lit_sphere(ROUGH_WHITE, resolution=n, light_intensity=0.0, environment=lambda w: np.ones_like(w),
                           environment_samples=32, exposure=exposure, seed=3)
    # the picture is tone mapped: compare display-referred linear values
    centre = srgb8_to_linear(image_of(ax)[n // 2 - 4: n // 2 + 4, n // 2 - 4: n // 2 + 4, :3])
    expected = pb.render.tone_map(pb.albedo(ROUGH_WHITE, 1.0, samples=1 << 15).total, exposure)
    np.testing.assert_allclose(centre.mean(axis=(0, 1)), expected, rtol=0.03)


def test_lit_sphere_sky_is_the_default_seeded_and_brightens():
    fig, axes = plt.subplots(1, 4)
    material = pb.presets.get("gold")
    plain = image_of(pbplot.lit_sphere(material, resolution=40, environment=None, ax=axes[0]))
    sky = image_of(pbplot.lit_sphere(material, resolution=40, environment_samples=8, ax=axes[1]))
    again = image_of(pbplot.lit_sphere(material, resolution=40, environment="sky", environment_samples=8, ax=axes[2]))
    other_seed = image_of(pbplot.lit_sphere(material, resolution=40, environment_samples=8, seed=1, ax=axes[3]))
    np.testing.assert_array_equal(sky, again)
    assert not np.array_equal(sky, other_seed)
    inside = plain[..., 3] > 0
    assert sky[..., :3][inside].astype(float).mean() > plain[..., :3][inside].astype(float).mean() + 20


def test_the_default_sky_picture_is_less_noisy_than_independent_samples():
    # Lattice points: a rough dielectric under the sky at the default 64 samples is closer to a
    # 4096-sample picture than one from as many independent uniforms (about half the error).
    material = pb.Material(base_color=(0.8, 0.8, 0.8), roughness=0.4)
    n, samples = 48, pb.render.DEFAULT_SAMPLES
    inside = pb.render.sphere_frames(n)[0]
    converged = pb.render.render_environment(material, n, samples=4096, seed=5)
    lattice = pb.render.render_environment(material, n, samples=samples)
    to_local = pb.render.sphere_frames(n)[1]
    wo, frame = to_local((0, 0, 1)), [to_local(e) for e in np.eye(3)]
    independent = np.zeros_like(lattice)
    for k in range(samples):  # the same estimator with pb.sample's own uniforms
        drawn = pb.sample(material, wo, seed=k)
        direction = np.stack([sum(drawn.wi[..., j] * frame[c][..., j] for j in range(3)) for c in range(3)], -1)
        independent += drawn.weight * pb.render.sky_environment(direction) / samples
    def error(image):
        return np.abs(image - converged)[inside].mean() / converged[inside].mean()
    assert error(lattice) < 0.04 and error(lattice) < 0.6 * error(independent), (error(lattice), error(independent))


def test_lit_sphere_per_pixel_material():
    n = 32
    roughness = np.tile(np.linspace(0.05, 1.0, n), (n, 1))
    material = pb.Material(roughness=roughness, base_color=(0.5, 0.5, 0.5))
    rgba = image_of(pbplot.lit_sphere(material, resolution=n, environment=None))
    np.testing.assert_array_equal(rgba[..., :3], pb.render.to_srgb8(pb.render.render_sphere(material, n, environment=None)))
    lit = image_of(pbplot.lit_sphere(material, resolution=n, environment_samples=4))
    np.testing.assert_array_equal(lit[..., :3], pb.render.to_srgb8(pb.render.render_sphere(material, n, samples=4)))
    inside = rgba[..., 3] > 0
    assert np.all(lit[..., :3][inside].astype(int) >= rgba[..., :3][inside])  # the sky only adds light


def test_lit_sphere_bad_arguments():
    with pytest.raises(ValueError, match="resolution"):
        pbplot.lit_sphere(EVERYTHING, resolution=0)
    with pytest.raises(TypeError, match="material"):
        pbplot.lit_sphere(None)
    with pytest.raises(ValueError, match="material"):
        pbplot.lit_sphere("no_such_preset")
    with pytest.raises(ValueError, match="material"):
        pbplot.lit_sphere(pb.Material(roughness=np.full((5, 5), 0.3)), resolution=8)
    with pytest.raises(ValueError, match="environment: .*got 'indoor'"):
        pbplot.lit_sphere(EVERYTHING, resolution=8, environment="indoor")
    with pytest.raises(TypeError, match="environment: .*got int"):
        pbplot.lit_sphere(EVERYTHING, resolution=8, environment=3)
    with pytest.raises(ValueError, match="exposure"):
        pbplot.lit_sphere(EVERYTHING, resolution=8, exposure=-1.0)
    with pytest.raises(ValueError, match="environment_samples"):
        pbplot.lit_sphere(EVERYTHING, resolution=8, environment=True, environment_samples=0)
    with pytest.raises(ValueError, match="model"):
        pbplot.lit_sphere(EVERYTHING, resolution=8, model="disney2016")
    assert plt.get_fignums() == []


# --------------------------------------------------------------------------
# albedo_curves


def test_albedo_curves_of_a_white_rough_dielectric(tmp_path):
    white = pb.Material(base_color=(1.0, 1.0, 1.0), roughness=0.5)
    ax = pbplot.albedo_curves(white, samples=4096)
    assert isinstance(ax, Axes)
    angles, total = line(ax, "total")
    np.testing.assert_allclose(angles, np.linspace(0, 89, 46))
    assert np.all(np.isfinite(total)) and total.std() > 0
    # Burley's diffuse is not energy conserving: E is about 1.04 at normal incidence, 1.2 at grazing
    assert np.all(total > 0.9) and np.all(total < 1.3)
    lobe_sum = sum(line(ax, name)[1] for name in ("diffuse", "specular"))
    np.testing.assert_allclose(lobe_sum, total, rtol=1e-6)
    expected = pb.albedo(white, np.cos(np.radians(angles)), samples=4096).total @ REC709
    np.testing.assert_allclose(total, expected, rtol=1e-12)
    assert len(ax.collections) == 3  # ±2 standard-error bands: total, diffuse, specular
    assert "θo" in ax.get_xlabel()
    assert_png_not_blank(ax.figure, tmp_path, "albedo")


def test_albedo_curves_bands_cover_the_mean_and_existing_axes():
    fig, ax = plt.subplots()
    assert pbplot.albedo_curves("satin_cloth", angles=[0, 30, 60, 80], samples=512, channel="r", ax=ax) is ax
    _, total = line(ax, "total")
    band = ax.collections[0].get_paths()[0].vertices[:, 1]
    assert band.min() < total.min() and band.max() > total.max()
    assert {l.get_label() for l in ax.get_lines()} == {"total", "diffuse", "sheen", "specular"}


def test_albedo_curves_bad_arguments():
    with pytest.raises(ValueError, match="angles"):
        pbplot.albedo_curves(EVERYTHING, angles=[0, 90])
    with pytest.raises(ValueError, match="angles"):
        pbplot.albedo_curves(EVERYTHING, angles=[[10, 20]])
    with pytest.raises(ValueError, match="samples"):
        pbplot.albedo_curves(EVERYTHING, angles=[10], samples=1)
    with pytest.raises(ValueError, match="channel"):
        pbplot.albedo_curves(EVERYTHING, angles=[10], channel="rgb")
    with pytest.raises(TypeError, match="material"):
        pbplot.albedo_curves([0.5], angles=[10])
    assert plt.get_fignums() == []


# --------------------------------------------------------------------------
# parameter_sweep


def test_parameter_sweep_grid(tmp_path):
    steps, n = 5, 24
    fig = pbplot.parameter_sweep(steps=steps, resolution=n)
    assert isinstance(fig, Figure)
    assert len(fig.axes) == len(pbplot.SCALAR_PARAMETERS) == 10
    assert [ax.get_ylabel() for ax in fig.axes] == list(pbplot.SCALAR_PARAMETERS)
    strips = [image_of(ax) for ax in fig.axes]
    cell = strips[0].shape[1] // steps
    assert all(s.shape == (cell, steps * cell, 4) for s in strips)
    for name, strip in zip(pbplot.SCALAR_PARAMETERS, strips):
        first, last = strip[:, :cell, :3].astype(float), strip[:, -cell:, :3].astype(float)
        assert first.std() > 5
        if name not in ("sheen", "sheen_tint"):  # a faint grazing lobe: little change with this light
            assert np.abs(first - last).max() > 5, name
    assert_png_not_blank(fig, tmp_path, "sweep")


def test_parameter_sweep_cells_are_render_sphere():
    base = pb.Material(base_color=(0.2, 0.5, 0.8), roughness=0.3)
    steps, n = 4, 20
    fig = pbplot.parameter_sweep(base, parameters=("roughness", "clearcoat_gloss"), steps=steps, resolution=n,
                                 ranges={"roughness": (0.2, 0.8)})
    strips = [image_of(ax) for ax in fig.axes]
    cell = strips[0].shape[1] // steps
    pad = (cell - n) // 2
    for j, value in enumerate(np.linspace(0.2, 0.8, steps)):
        sphere = strips[0][pad:pad + n, j * cell + pad: j * cell + pad + n, :3]
        expected = pb.render.to_srgb8(pb.render.render_sphere(base.replace(roughness=value), n))
        assert np.abs(sphere.astype(int) - expected).max() <= 1, j
    # clearcoat_gloss row: the base has no clearcoat, so the row turns it on to show the gloss
    j = steps - 1
    sphere = strips[1][pad:pad + n, j * cell + pad: j * cell + pad + n, :3]
    expected = pb.render.to_srgb8(pb.render.render_sphere(base.replace(clearcoat=1.0, clearcoat_gloss=1.0), n))
    assert np.abs(sphere.astype(int) - expected).max() <= 1


def test_parameter_sweep_bad_arguments():
    with pytest.raises(ValueError, match="parameters"):
        pbplot.parameter_sweep(parameters=("base_color",))
    with pytest.raises(ValueError, match="parameters"):
        pbplot.parameter_sweep(parameters=("shininess",))
    with pytest.raises(ValueError, match="steps"):
        pbplot.parameter_sweep(steps=1)
    with pytest.raises(ValueError, match="resolution"):
        pbplot.parameter_sweep(resolution=1)
    with pytest.raises(ValueError, match="ranges"):
        pbplot.parameter_sweep(parameters=("metallic",), ranges={"metallic": (0.0, 2.0)}, resolution=8, steps=2)
    with pytest.raises(ValueError, match="ranges"):
        pbplot.parameter_sweep(parameters=("metallic",), ranges={"roughness": (0.0, 1.0)}, resolution=8, steps=2)
    with pytest.raises(TypeError, match="base"):
        pbplot.parameter_sweep(base=3.0)
    with pytest.raises(ValueError, match="base"):
        pbplot.parameter_sweep(base=pb.Material(roughness=[0.1, 0.2]))
    assert plt.get_fignums() == []


# --------------------------------------------------------------------------
# blend_demo


def test_blend_demo_default_checker_shows_both_materials(tmp_path):
    a, b = pb.presets.get("gold"), pb.presets.get("blue_rubber")
    n = 64
    ax = pbplot.blend_demo(a, b, resolution=n)
    assert isinstance(ax, Axes)
    rgba = image_of(ax)
    only_a = pb.render.to_srgb8(pb.render.render_sphere(a, n))
    only_b = pb.render.to_srgb8(pb.render.render_sphere(b, n))
    inside = rgba[..., 3] > 0
    from_a = np.all(rgba[..., :3] == only_a, axis=-1) & inside
    from_b = np.all(rgba[..., :3] == only_b, axis=-1) & inside
    assert from_a.sum() > 0.3 * inside.sum() and from_b.sum() > 0.3 * inside.sum()
    assert_png_not_blank(ax.figure, tmp_path, "blend")


def test_blend_demo_mask_and_existing_axes():
    n = 32
    fig, ax = plt.subplots()
    mask = np.zeros((n, n))
    mask[:, n // 2:] = 1.0  # right half is b
    assert pbplot.blend_demo("gold", "blue_rubber", mask=mask, resolution=n, ax=ax) is ax
    rgba = image_of(ax)
    gold = pb.render.to_srgb8(pb.render.render_sphere(pb.presets.get("gold"), n))
    rubber = pb.render.to_srgb8(pb.render.render_sphere(pb.presets.get("blue_rubber"), n))
    np.testing.assert_array_equal(rgba[:, : n // 2, :3], gold[:, : n // 2])
    np.testing.assert_array_equal(rgba[:, n // 2:, :3], rubber[:, n // 2:])


def test_blend_demo_bad_arguments():
    with pytest.raises(TypeError, match="^a:"):
        pbplot.blend_demo(1.0, "gold")
    with pytest.raises(TypeError, match="^b:"):
        pbplot.blend_demo("gold", object())
    with pytest.raises(ValueError, match="mask"):
        pbplot.blend_demo("gold", "chrome", mask=np.zeros((3, 3)), resolution=8)
    with pytest.raises(ValueError, match="mask"):
        pbplot.blend_demo("gold", "chrome", mask=np.full((8, 8), 2.0), resolution=8)
    with pytest.raises(TypeError, match="mask"):
        pbplot.blend_demo("gold", "chrome", mask="stripes", resolution=8)
    with pytest.raises(ValueError, match="resolution"):
        pbplot.blend_demo("gold", "chrome", resolution=1)
    assert plt.get_fignums() == []


# --------------------------------------------------------------------------
# energy compensation (Kulla & Conty 2017; docs/energy-compensation.md)

WHITE_METAL = pb.Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=1.0)


def test_energy_compensation_brightens_a_rough_white_metal_sphere():
    # a constant white environment, light off: each pixel shows the albedo at its view angle,
    # 0.31 (normal) to less at grazing without the lobe, about 1 with it
    n, white = 32, (lambda w: np.ones_like(w))
    inside = pb.render.sphere_frames(n)[0]
    plain, compensated = (pb.render.render_sphere(WHITE_METAL, n, light_intensity=0.0, environment=white, samples=16,
                                                  energy_compensation=flag) for flag in (False, True))
    assert np.all(compensated[inside] >= plain[inside])
    assert compensated[inside].mean() > 2.0 * plain[inside].mean()
    centre = (slice(n // 2 - 2, n // 2 + 2),) * 2
    np.testing.assert_allclose(plain[centre].mean(), 1.0 - np.log(2.0), atol=0.03)  # E = 1 - ln 2 at the normal
    np.testing.assert_allclose(compensated[centre].mean(), 1.0, atol=0.03)
    # plot.lit_sphere passes the option through: its image is render_sphere's in sRGB
    fig, axes = plt.subplots(1, 2)
    shown = [image_of(pbplot.lit_sphere(WHITE_METAL, resolution=n, environment_samples=8, ax=ax,
                                        energy_compensation=flag)) for ax, flag in zip(axes, (False, True))]
    expected = pb.render.to_srgb8(pb.render.render_sphere(WHITE_METAL, n, samples=8, energy_compensation=True))
    np.testing.assert_array_equal(shown[1][..., :3], expected)
    assert shown[1][..., :3][inside].astype(float).mean() > shown[0][..., :3][inside].astype(float).mean() + 20


def test_albedo_curves_with_energy_compensation_pass_the_white_furnace():
    fig, axes = plt.subplots(1, 2)
    angles = np.array([0.0, 30.0, 60.0, 80.0])
    plain = pbplot.albedo_curves(WHITE_METAL, angles=angles, samples=1 << 13, ax=axes[0])
    compensated = pbplot.albedo_curves(WHITE_METAL, angles=angles, samples=1 << 13, ax=axes[1],
                                       energy_compensation=True)
    _, without = line(plain, "total")
    _, with_lobe = line(compensated, "total")
    np.testing.assert_allclose(with_lobe, 1.0, atol=1e-2)
    assert np.all(without < 0.7)
    np.testing.assert_allclose(without[0], 1.0 - np.log(2.0), atol=1e-2)
    _, lobe = line(compensated, "multiple_scattering")  # the lost energy, drawn as its own lobe
    np.testing.assert_allclose(lobe, with_lobe - without, atol=2e-2)
    assert "multiple_scattering" not in [l.get_label() for l in plain.get_lines()]


# --------------------------------------------------------------------------
# microfacet_family


def test_microfacet_family_draws_every_distribution(tmp_path):
    fig = pbplot.microfacet_family(0.3, resolution=91)
    assert isinstance(fig, Figure) and len(fig.axes) == 2
    d_ax, lambda_ax = fig.axes
    d_labels = [l.get_label() for l in d_ax.get_lines()]
    assert d_labels == ["GGX", "Beckmann", "Blinn-Phong (n = 20.2)", "Student-t γ = 1.6", "Student-t γ = 4",
                        "exponential power p = 0.5", "exponential power p = 2", "GTR γ = 1 (GTR1)", "GTR γ = 1.5"]
    assert [l.get_label() for l in lambda_ax.get_lines()] == d_labels[:7]  # GTR has no closed-form Λ
    for ax in (d_ax, lambda_ax):
        assert ax.get_yscale() == "log"
        for drawn in ax.get_lines():
            y = np.asarray(drawn.get_ydata(), float)
            assert y.size > 10 and np.all(np.isfinite(y)) and np.all(y > 0.0), drawn.get_label()
    # the values are pb.microfacet's
    theta, d = line(d_ax, "GGX")
    h = np.stack([np.sin(np.radians(theta)), 0 * theta, np.cos(np.radians(theta))], -1)
    np.testing.assert_allclose(d, pb.microfacet.GGX(0.3).d(h), rtol=1e-12)
    theta, lam = line(lambda_ax, "Student-t γ = 4")
    w = np.stack([np.sin(np.radians(theta)), 0 * theta, np.cos(np.radians(theta))], -1)
    np.testing.assert_allclose(lam, pb.microfacet.StudentT(0.3, gamma=4.0).lambda_(w), rtol=1e-12)
    assert d_ax.get_legend() is not None
    assert_png_not_blank(fig, tmp_path, "family")


def test_microfacet_family_into_existing_axes():
    fig, axes = plt.subplots(1, 2)
    assert pbplot.microfacet_family(0.5, student_t_gammas=[3.0], exponential_power_ps=[], gtr_gammas=[1.0],
                                    resolution=16, legend=False, axes=(axes[0], axes[1])) is fig
    assert len(axes[0].get_lines()) == 5 and len(axes[1].get_lines()) == 4
    assert axes[0].get_legend() is None


def test_microfacet_family_bad_arguments():
    cases = [
        (dict(alpha=0.0), ValueError, "alpha"), (dict(alpha=1.5), ValueError, "alpha"),
        (dict(alpha="rough"), TypeError, "alpha"),
        (dict(student_t_gammas=[1.5]), ValueError, r"student_t_gammas\[0\]"),
        (dict(student_t_gammas=3.0), TypeError, "student_t_gammas"),
        (dict(exponential_power_ps=[1.0, 20.0]), ValueError, r"exponential_power_ps\[1\]"),
        (dict(gtr_gammas=[0.0]), ValueError, r"gtr_gammas\[0\]"),
        (dict(resolution=2), ValueError, "resolution"), (dict(decades=0.0), ValueError, "decades"),
        (dict(axes="left"), TypeError, "axes"),
    ]
    for kwargs, error, name in cases:
        with pytest.raises(error, match=name):
            pbplot.microfacet_family(**kwargs)
    fig = plt.figure()
    with pytest.raises(ValueError, match=r"axes\[1\]"):
        pbplot.microfacet_family(axes=(fig.add_subplot(1, 2, 1), fig.add_subplot(1, 2, 2, projection="polar")))
    plt.close(fig)
    assert plt.get_fignums() == []


@pytest.mark.parametrize("draw", [
    lambda r: pbplot.brdf_slice(EVERYTHING, resolution=r),
    lambda r: pbplot.lit_sphere(EVERYTHING, resolution=r),
    lambda r: pbplot.blend_demo("gold", "blue_rubber", resolution=r),
    lambda r: pbplot.parameter_sweep(resolution=r),
    lambda r: pbplot.slice_directions(r),
    lambda r: pb.render.render_sphere(EVERYTHING, r),
    lambda r: pb.render.sphere_frames(r),
], ids=["brdf_slice", "lit_sphere", "blend_demo", "parameter_sweep", "slice_directions", "render_sphere",
        "sphere_frames"])
def test_one_resolution_rule_for_every_picture(draw):
    for bad in (1, pb.render.MAX_RESOLUTION + 1):
        with pytest.raises(ValueError, match=rf"^resolution: expected 2 to 16384 pixels, got {bad}$"):
            draw(bad)
    for bad in (True, 64.0, "64"):
        with pytest.raises(TypeError, match="^resolution: expected an integer"):
            draw(bad)


def test_one_rule_for_number_options():
    ones = np.ones((2, 2, 3))
    for call in (lambda e: pb.render.tone_map(ones, exposure=e), lambda e: pb.render.to_srgb8(ones, exposure=e),
                 lambda e: pbplot.lit_sphere(EVERYTHING, resolution=8, exposure=e)):
        with pytest.raises(ValueError, match=r"^exposure: -1.0 is outside its domain \[0, inf\)$"):
            call(-1.0)
        with pytest.raises(ValueError, match="^exposure: nan is not a finite number$"):
            call(float("nan"))
        with pytest.raises(TypeError, match="^exposure: expected a real number"):
            call(True)
        with pytest.raises(ValueError, match=r"^exposure: expected one number, got shape \(2,\)$"):
            call([1.0, 2.0])
        call(np.float32(2.0))
        call(np.array(2.0))
    with pytest.raises(ValueError, match=r"^exposure: 0.0 is outside its domain \(0, inf\)$"):
        pbplot.brdf_slice(EVERYTHING, resolution=8, exposure=0)
    with pytest.raises(ValueError, match=r"^theta_o: 90.0 is outside its domain \(-90, 90\)$"):
        pbplot.polar_lobes(EVERYTHING, 90.0)
