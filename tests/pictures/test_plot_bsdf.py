"""pb.plot over the whole sphere for the 2015 models: the transmitted lobe below
the surface in polar_lobes, reflectance and transmittance in albedo_curves."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import principled_brdf as pb  # noqa: E402

GLASS = pb.Material(base_color=(1.0, 1.0, 1.0), spec_trans=1.0, roughness=0.3, ior=1.5)
LEAF = pb.Material(base_color=(0.3, 0.6, 0.1), roughness=0.5, diff_trans=1.2)


def lines(ax):
    return {line.get_label(): line for line in ax.get_lines()}


@pytest.mark.parametrize("model, material, lobe", [("disney2015", GLASS, "transmission"),
                                                   ("disney2015_thin", LEAF, "diffuse_transmission")])
def test_polar_lobes_draws_the_transmitted_lobe_below_the_surface(model, material, lobe):
    fig = plt.figure()
    ax = pb.plot.polar_lobes(material, 30, model=model, ax=fig.add_subplot(projection="polar"))
    drawn = lines(ax)
    angle, radius = (np.asarray(v) for v in drawn[lobe].get_data())
    below = np.abs(angle) > np.pi / 2
    assert radius[below].max() > 0 and np.all(radius[~below] == 0)
    # the curve is pb.eval_lobes at the plotted directions
    wi = np.stack([np.sin(angle), np.zeros_like(angle), np.cos(angle)], axis=-1)
    wo = np.array([np.sin(np.radians(30)), 0.0, np.cos(np.radians(30))])
    expected = getattr(pb.eval_lobes(material, wi, wo, model=model), lobe) @ np.array([0.2126, 0.7152, 0.0722])
    np.testing.assert_allclose(radius, expected, rtol=1e-6, atol=1e-9)
    assert ax.get_thetamin() == -180.0 or np.isclose(np.degrees(np.ptp(angle)), 360.0)
    plt.close(fig)


def test_polar_lobes_of_a_brdf_keep_the_upper_half_and_its_angles():
    fig = plt.figure()
    ax = pb.plot.polar_lobes(pb.Material(), 30, ax=fig.add_subplot(projection="polar"))
    angle = np.asarray(lines(ax)["total"].get_xdata())
    assert np.isclose(angle.min(), -np.pi / 2) and np.isclose(angle.max(), np.pi / 2)
    with pytest.raises(ValueError, match="theta_o"):
        pb.plot.polar_lobes(pb.Material(), 120)
    plt.close(fig)


def test_albedo_curves_split_reflectance_and_transmittance_from_either_side():
    fig, ax = plt.subplots()
    angles = np.array([10.0, 45.0, 80.0, 100.0, 150.0])
    pb.plot.albedo_curves(GLASS, angles=angles, samples=4096, model="disney2015", ax=ax)
    drawn = lines(ax)
    total, reflected, transmitted = (np.asarray(drawn[k].get_ydata()) for k in ("total", "reflectance", "transmittance"))
    np.testing.assert_allclose(reflected + transmitted, total, rtol=1e-6)
    # radiance mode from outside: the light from inside arrives compressed by 1/η², T_D / η² ~ 0.43 near the normal
    np.testing.assert_allclose(transmitted[0], (1 - 0.04) / 1.5**2, atol=0.03)
    assert np.all(reflected > 0)
    assert reflected[-2] > reflected[0]  # inside, near the critical angle, most is reflected
    with pytest.raises(ValueError, match="angles"):
        pb.plot.albedo_curves(GLASS, angles=[90.0], model="disney2015")
    with pytest.raises(ValueError, match="angles"):
        pb.plot.albedo_curves(pb.Material(), angles=[100.0])
    plt.close(fig)


def test_brdf_slice_of_the_light_that_passes_through():
    fig, ax = plt.subplots()
    pb.plot.brdf_slice(LEAF, model="disney2015_thin", transmission=True, log=False, resolution=32, ax=ax)
    plotted = np.ma.filled(ax.images[-1].get_array(), np.nan)
    _, _, wi, wo = pb.plot.slice_directions(32, 90.0)
    expected = pb.eval(LEAF, (wi * [1, 1, -1]).astype(np.float32), wo.astype(np.float32), model="disney2015_thin")
    expected = expected @ np.array([0.2126, 0.7152, 0.0722])
    shown = ~np.isnan(plotted)
    assert shown.mean() > 0.5 and np.nanmax(plotted) > 0
    np.testing.assert_allclose(plotted[shown], expected[shown], rtol=1e-5, atol=1e-7)
    with pytest.raises(ValueError, match="transmission"):
        pb.plot.brdf_slice(pb.Material(), transmission=True)
    plt.close(fig)
