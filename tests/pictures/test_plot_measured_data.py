"""The plots draw measured data and any f(wi, wo) as well as a Material
(docs/rendering-and-plots.md): the same picture for a material given either
way, data gaps masked, the albedo of measured data by quadrature."""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb

matplotlib = pytest.importorskip("matplotlib")
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

GOLD = pb.Material(base_color=(1.0, 0.71, 0.29), metallic=1.0, roughness=0.3)


def lambertian(color):
    return lambda wi, wo: np.broadcast_to(np.asarray(color) / np.pi, np.broadcast_shapes(wi.shape, wo.shape))


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def test_a_slice_of_a_callable_is_the_slice_of_the_material():
    by_material = pb.plot.brdf_slice(GOLD, resolution=48).images[-1].get_array()
    by_callable = pb.plot.brdf_slice(lambda wi, wo: pb.reference.eval(GOLD, wi, wo), resolution=48)
    np.testing.assert_allclose(by_callable.images[-1].get_array(), by_material, rtol=2e-5)


def test_a_slice_of_measured_data_masks_the_cells_without_data():
    wi, wo = pb.measured.merl_pairs()
    table = pb.measured.MerlBRDF(np.full((3,) + pb.measured.MERL_SHAPE, 0.1))
    table.table[:, :, 45:, :] = np.nan  # no data for θd >= 45°
    image = pb.plot.brdf_slice(table, resolution=32, log=False).images[-1].get_array()
    rows_with_data = ~np.ma.getmaskarray(image).all(axis=1)
    assert rows_with_data[:14].all() and not rows_with_data[-14:].any()
    assert np.allclose(image.compressed(), np.dot(pb.plot.CHANNELS["luminance"], [0.1] * 3))


def test_polar_lobes_of_a_callable_draw_the_total():
    ax = pb.plot.polar_lobes(lambda wi, wo: pb.reference.eval(GOLD, wi, wo), 30.0)
    lines = {line.get_label(): line for line in ax.lines}
    assert "total" in lines and "specular" not in lines
    reference = {line.get_label(): line for line in pb.plot.polar_lobes(GOLD, 30.0, lobes=False).lines}
    np.testing.assert_allclose(lines["total"].get_ydata(), reference["total"].get_ydata(), rtol=2e-5, atol=1e-12)


def test_albedo_of_measured_data_by_quadrature():
    white = lambertian([0.8, 0.5, 0.2])
    ax = pb.plot.albedo_curves(white, angles=[0.0, 45.0, 80.0], channel="r")
    np.testing.assert_allclose(ax.lines[0].get_ydata(), 0.8, rtol=1e-9)
    # a table of gold against the library's own Monte Carlo albedo
    table = pb.measured.MerlBRDF(pb.reference.eval(GOLD, *pb.measured.merl_pairs()).T.reshape(
        (3,) + pb.measured.MERL_SHAPE))
    measured = pb.plot.albedo_curves(table, angles=[0.0, 40.0]).lines[0].get_ydata()
    library = pb.plot.albedo_curves(GOLD, angles=[0.0, 40.0], samples=1 << 16, lobes=False).lines[0].get_ydata()
    np.testing.assert_allclose(measured, library, rtol=0.03)


@pytest.mark.parametrize("bad, message", [(lambda wi, wo: np.ones(3), r"material: expected the callable to return"),
                                          (lambda wi, wo: -np.ones(wi.shape), r"material: the callable returned -1.0"),
                                          (3.0, r"material: expected a principled_brdf.Material, a preset name, a "
                                                r"MerlBRDF or a callable")])
def test_bad_sources_are_named(bad, message):
    with pytest.raises((ValueError, TypeError), match=message):
        pb.plot.brdf_slice(bad, resolution=8)
