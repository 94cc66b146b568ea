"""pb.measured: the MERL format, Rusinkiewicz's angles, fitting to a table."""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb
from principled_brdf import measured as merl
from conftest import random_direction_pairs, seeded_rng

CELLS = 90 * 90 * 180


def test_half_difference_angles_round_trip_and_reciprocity():
    rng = seeded_rng("merl-angles")
    wi, wo = random_direction_pairs(rng, 5000, min_cos=0.01)
    theta_h, phi_h, theta_d, phi_d = merl.wiwo_to_half_diff(wi, wo)
    back_wi, back_wo = merl.half_diff_to_wiwo(theta_h, phi_h, theta_d, phi_d)
    np.testing.assert_allclose(back_wi, wi, atol=1e-12)
    np.testing.assert_allclose(back_wo, wo, atol=1e-12)
    half = (wi + wo) / np.linalg.norm(wi + wo, axis=-1, keepdims=True)
    np.testing.assert_allclose(np.cos(theta_h), half[:, 2], atol=1e-13)
    np.testing.assert_allclose(np.cos(theta_d), np.sum(wi * half, axis=-1), atol=1e-13)  # θd is the angle wi-h
    swapped = merl.wiwo_to_half_diff(wo, wi)  # reciprocity: φd moves by π, nothing else
    np.testing.assert_allclose(swapped[2], theta_d, atol=1e-12)
    defined = np.sin(theta_d) > 1e-6  # φd means nothing where wi = wo
    assert defined.mean() > 0.5
    np.testing.assert_allclose(np.cos(swapped[3] - phi_d)[defined], -1.0, atol=1e-9)


def test_indices_follow_the_format():
    """i_θh = floor(sqrt(θh / (π/2)) 90), i_θd = floor(θd / (π/2) 90), i_φd = floor(φd / π 180)
    with φd folded into [0, π), each clamped."""
    theta_h = np.array([0.0, (10.5 / 90) ** 2 * np.pi / 2, np.pi / 2, 2.0])
    theta_d = np.array([0.0, 45.2 / 90 * np.pi / 2, np.pi / 2, 0.1])
    phi_d = np.array([0.0, np.pi + 3.5 / 180 * np.pi, -0.5 * np.pi, np.pi - 1e-12])
    i_h, i_d, i_p = merl._indices(theta_h, theta_d, phi_d)
    assert list(i_h) == [0, 10, 89, 89]
    assert list(i_d) == [0, 45, 89, 5]
    assert list(i_p) == [0, 3, 90, 179]  # φd = π + 3.5° -> 3.5°; φd = -90° -> 270° -> 90°


def test_save_and_load_a_model_exactly(tmp_path):
    material = pb.presets.get("gold")
    path = tmp_path / "gold.binary"
    merl.save_merl(path, lambda wi, wo: pb.reference.eval(material, wi, wo))
    assert path.stat().st_size == 12 + 3 * CELLS * 8
    header = np.fromfile(path, dtype="<i4", count=3)
    assert tuple(header) == (90, 90, 180)
    table = merl.load_merl(path)
    wi, wo = merl.merl_pairs()
    expected = pb.reference.eval(material, wi, wo)
    np.testing.assert_allclose(table.values(), expected, rtol=1e-15, atol=0)  # scale in, scale out
    # the format's nearest cell, queried at the centres, is the cell itself
    above = (wi[:, 2] > 0) & (wo[:, 2] > 0)
    np.testing.assert_array_equal(table.eval(wi[above], wo[above]), table.values()[above])
    np.testing.assert_allclose(table.eval(wi[above], wo[above], interpolation="linear"), table.values()[above],
                               rtol=1e-12, atol=1e-300)
    assert not np.any(table.eval(wi[~above][:10], wo[~above][:10]))


def test_missing_cells_and_linear_interpolation(tmp_path):
    table = np.full((3, 90, 90, 180), 0.5)
    table[:, 10, 20, 30] = np.nan
    table[:, :, :, :] += np.linspace(0.0, 1.0, 180)  # linear in φd index
    brdf = merl.MerlBRDF(table)
    path = tmp_path / "t.binary"
    merl.save_merl(path, brdf)
    stored = np.fromfile(path, dtype="<f8", offset=12).reshape(3, 90, 90, 180)
    assert np.all(stored[:, 10, 20, 30] == -1.0)
    loaded = merl.load_merl(path)
    assert np.isnan(loaded.table[:, 10, 20, 30]).all()
    np.testing.assert_allclose(loaded.table[:, 11], table[:, 11], rtol=1e-15)
    # halfway between two φd centres of a cell row: the mean of the two
    theta_h = (40.5 / 90) ** 2 * np.pi / 2
    theta_d = 30.5 / 90 * np.pi / 2
    wi, wo = merl.half_diff_to_wiwo(theta_h, 0.3, theta_d, (50.0 + 1.0) / 180 * np.pi)
    f = loaded.eval(wi, wo, interpolation="linear")
    np.testing.assert_allclose(f, 0.5 * (table[:, 40, 30, 50] + table[:, 40, 30, 51]), rtol=1e-9)


def test_wrong_files_say_what_was_expected(tmp_path):
    short = tmp_path / "short.binary"
    np.asarray([90, 90, 180], "<i4").tofile(short)
    with pytest.raises(ValueError, match="expected 34992012 bytes"):
        merl.load_merl(short)
    wrong = tmp_path / "wrong.binary"
    np.asarray([90, 90, 360], "<i4").tofile(wrong)
    with pytest.raises(ValueError, match=r"expected a MERL header of three int32 dimensions \(90, 90, 180\)"):
        merl.load_merl(wrong)
    with pytest.raises(ValueError, match="table: expected shape"):
        merl.MerlBRDF(np.zeros((3, 90, 90)))
    with pytest.raises(TypeError, match="brdf: expected a MerlBRDF or a callable"):
        merl.save_merl(tmp_path / "x.binary", 3)


def test_fit_a_material_to_a_merl_table(tmp_path):
    """A table made from a known material, read back and fitted (log loss on the cells above the horizon)."""
    truth = pb.Material(base_color=(0.6, 0.25, 0.1), roughness=0.3, specular=0.5, metallic=0.0)
    path = tmp_path / "truth.binary"
    merl.save_merl(path, lambda wi, wo: pb.reference.eval(truth, wi, wo))
    table = merl.load_merl(path)
    wi, wo = merl.merl_pairs()
    values = table.values()
    use = (wi[:, 2] > 0.02) & (wo[:, 2] > 0.02)
    use &= np.arange(CELLS) % 97 == 0  # a subsample keeps the test fast
    result = pb.fit(wi[use], wo[use], values[use], fit=["base_color", "roughness"], init=dict(metallic=0.0))
    assert result.success
    np.testing.assert_allclose(result.slots[[0, 1, 2, 7]], [0.6, 0.25, 0.1, 0.3], atol=2e-4)


def test_merl_pairs_are_the_cells_centres_bit_for_bit():
    """merl_pairs computes half_diff_to_wiwo on the grid's axes: the same bits, for any φh and
    step; values(step=) picks the same cells in the same order."""
    i_h, i_d, i_p = np.meshgrid(np.arange(0, 90, 7), np.arange(0, 90, 5), np.arange(0, 180, 11), indexing="ij")
    theta_h = ((i_h + 0.5) / 90) ** 2 * (0.5 * np.pi)
    theta_d, phi_d = (i_d + 0.5) / 90 * (0.5 * np.pi), (i_p + 0.5) / 180 * np.pi
    for phi_h in (0.0, 0.7, -2.5):
        wi, wo = merl.merl_pairs(phi_h, step=(7, 5, 11))
        expected = merl.half_diff_to_wiwo(theta_h.ravel(), phi_h, theta_d.ravel(), phi_d.ravel())
        np.testing.assert_array_equal(wi, expected[0])
        np.testing.assert_array_equal(wo, expected[1])
    table = merl.MerlBRDF(np.random.default_rng(2).uniform(0, 1, (3,) + merl.MERL_SHAPE))
    cells = (i_h * 90 + i_d) * 180 + i_p
    np.testing.assert_array_equal(table.values(step=(7, 5, 11)), table.values()[cells.ravel()])
    assert merl.merl_pairs(step=3)[0].shape == (30 * 30 * 60, 3)
    with pytest.raises(ValueError, match="step: expected strides >= 1"):
        merl.merl_pairs(step=(1, 0, 1))
    with pytest.raises(TypeError, match="step: expected a positive integer or three"):
        table.values(step=(1, 2))
