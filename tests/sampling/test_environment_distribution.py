"""The 2D piecewise-constant distribution (principled_brdf.piecewise) and the
latitude-longitude map's density built on it (principled_brdf.environment).

The expected densities are written here from the definitions (a cell's density is
its value over the table's mean; per steradian, ``pdf_uv / (2π² sin θ)``), and the
samples are checked against them by Pearson's chi-square on every cell and on
sub-cells (uniform within a cell), by exact placement for a one-pixel map, and by
quadrature of the density over the sphere.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from conftest import seeded_rng
from principled_brdf.environment import Environment, directions_to_uv, uv_to_directions
from principled_brdf.piecewise import PiecewiseConstant2D

# the chi-square tests below are one family of three: Šidák over them
SIGNIFICANCE = 1.0 - (1.0 - 0.01) ** (1.0 / 3)
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])


def random_map(rows: int, columns: int, key: str) -> np.ndarray:
    """Radiance with a bright spot, zero pixels and a whole zero row (the cases inversion must skip)."""
    rng = seeded_rng(key)
    image = rng.uniform(0.0, 1.0, (rows, columns, 3)) ** 3
    image[rng.uniform(size=(rows, columns)) < 0.2] = 0.0
    image[1] = 0.0
    image[rows // 2, columns // 3] = 50.0
    return image


def plain_inverse(cdf: np.ndarray, u: np.ndarray) -> np.ndarray:
    """The last cell whose lower boundary is at or below u, for one cumulative distribution."""
    return np.clip(np.searchsorted(cdf, u, side="right") - 1, 0, len(cdf) - 2)


def test_cells_are_drawn_in_proportion_to_their_values_and_uniformly_within():
    table = random_map(8, 16, "cells")[..., 0]
    distribution = PiecewiseConstant2D(table)
    n = 400_000
    points, density = distribution.sample(seeded_rng("cells", "u").uniform(size=(n, 2)))
    assert np.all((points >= 0.0) & (points < 1.0))
    row, column = (points[:, 1] * 8).astype(int), (points[:, 0] * 16).astype(int)
    assert np.all(table[row, column] > 0.0), "a cell of value 0 was drawn"
    np.testing.assert_allclose(density, table[row, column] / table.mean(), rtol=1e-12)
    # every cell, then each cell split 2 x 2 (the density is constant inside a cell)
    for split in (1, 2):
        fine = np.repeat(np.repeat(table, split, axis=0), split, axis=1)
        counts = np.zeros(fine.shape)
        np.add.at(counts, ((points[:, 1] * 8 * split).astype(int), (points[:, 0] * 16 * split).astype(int)), 1)
        used = fine > 0.0
        expected = n * fine[used] / fine.sum()
        assert stats.chisquare(counts[used], expected).pvalue > SIGNIFICANCE


def test_the_guide_table_inverts_as_a_plain_binary_search():
    table = random_map(6, 40, "guide")[..., 1]
    table[3, 5:30] = 0.0  # a long run of empty cells inside one row
    distribution = PiecewiseConstant2D(table)
    u = seeded_rng("guide", "u").uniform(size=(200_000, 2))
    u[:1000, 0] = np.repeat(distribution.conditional_cdf[2, :-1], 1000 // 40 + 1)[:1000]  # exactly on boundaries
    points, _ = distribution.sample(u)
    row = plain_inverse(distribution.marginal_cdf, u[:, 1])
    column = np.array([plain_inverse(distribution.conditional_cdf[r], x) for r, x in zip(row, u[:, 0])])
    np.testing.assert_array_equal((points[:, 1] * 6).astype(int), row)
    np.testing.assert_array_equal((points[:, 0] * 40).astype(int), column)


def test_an_all_zero_table_is_the_uniform_density():
    distribution = PiecewiseConstant2D(np.zeros((3, 4)))
    points, density = distribution.sample(seeded_rng("zero").uniform(size=(1000, 2)))
    np.testing.assert_array_equal(density, 1.0)
    assert stats.kstest(points[:, 0], "uniform").pvalue > 1e-3


def test_the_map_density_is_luminance_times_sin_theta_per_du_dv_over_2_pi_squared_sin_theta():
    image = random_map(16, 32, "map")
    environment = Environment(image)
    rows = np.arange(16)
    weight = (image @ LUMINANCE) * np.sin(np.pi * (rows + 0.5) / 16)[:, None]
    v = seeded_rng("map", "directions").normal(size=(5000, 3))
    directions = v / np.linalg.norm(v, axis=-1, keepdims=True)
    uv, sin_theta = directions_to_uv(directions)
    row, column = np.minimum((uv[:, 1] * 16).astype(int), 15), (uv[:, 0] * 32).astype(int)
    expected = weight[row, column] / weight.mean() / (2.0 * np.pi**2 * np.hypot(directions[:, 0], directions[:, 2]))
    np.testing.assert_allclose(environment.pdf(directions), expected, rtol=1e-5)
    np.testing.assert_array_equal(environment(directions), image[row, column].astype(np.float32))


def test_the_map_density_integrates_to_one_over_the_sphere():
    environment = Environment(random_map(16, 32, "integral"))
    # midpoint rule on a grid 8 x finer than the pixels: exact for a density constant on each pixel's (u, v)
    n_v, n_u = 16 * 8, 32 * 8
    u, v = np.meshgrid((np.arange(n_u) + 0.5) / n_u, (np.arange(n_v) + 0.5) / n_v)
    theta = np.pi * v
    directions = np.stack([-np.sin(theta) * np.sin(2 * np.pi * u), np.cos(theta), np.sin(theta) * np.cos(2 * np.pi * u)],
                          axis=-1)
    solid_angle = np.sin(theta) * (np.pi / n_v) * (2.0 * np.pi / n_u)
    assert abs(np.sum(environment.pdf(directions) * solid_angle) - 1.0) < 1e-3


def test_sampled_directions_carry_their_own_density_and_radiance():
    image = random_map(16, 32, "consistent")
    environment = Environment(image)
    directions, pdf, radiance = environment.sample(seeded_rng("consistent", "u").uniform(size=(20_000, 2)))
    np.testing.assert_allclose(np.linalg.norm(directions, axis=-1), 1.0, atol=1e-6)
    inside = np.abs(directions[:, 1]) < 0.999  # away from the poles, where sin θ rounds
    np.testing.assert_allclose(pdf[inside], environment.pdf(directions[inside]), rtol=2e-3)
    np.testing.assert_array_equal(radiance[inside], environment(directions[inside]))


def test_a_one_bright_pixel_map_is_sampled_exactly_there():
    image = np.zeros((32, 64, 3))
    image[9, 41] = (3.0, 2.0, 1.0)
    environment = Environment(image)
    directions, pdf, radiance = environment.sample(seeded_rng("one pixel").uniform(size=(5000, 2)))
    uv, _ = directions_to_uv(directions)
    assert np.all((uv[:, 1] * 32).astype(int) == 9) and np.all((uv[:, 0] * 64).astype(int) == 41)
    np.testing.assert_array_equal(radiance, np.float32([3.0, 2.0, 1.0]) * np.ones((5000, 1), np.float32))
    # the pixel's whole probability over its solid angle: 1 / (2π² sin θ du dv) at each point
    expected = 32 * 64 / (2.0 * np.pi**2 * np.sin(np.pi * uv[:, 1]))
    np.testing.assert_allclose(pdf, expected, rtol=1e-4)


def test_uv_and_directions_are_inverse_and_the_panorama_faces_minus_z():
    uv = seeded_rng("uv").uniform(0.01, 0.99, size=(1000, 2))
    back, _ = directions_to_uv(uv_to_directions(uv))
    np.testing.assert_allclose(back, uv, atol=2e-6)
    np.testing.assert_allclose(uv_to_directions([[0.5, 0.5], [0.75, 0.5], [0.0, 0.5], [0.3, 0.0]]),
                               [[0, 0, -1], [1, 0, 0], [0, 0, 1], [0, 1, 0]], atol=1e-6)


@pytest.mark.parametrize("table, message", [
    (np.ones(4), r"function: expected a \(rows, columns\) table"),
    (np.array([[1.0, -1.0]]), r"function\[0, 1\]: -1.0 is outside its domain"),
    (np.array([[1.0, np.nan]]), r"function\[0, 1\]: nan is not a finite number"),
])
def test_bad_tables_are_refused_naming_the_element(table, message):
    with pytest.raises(ValueError, match=message):
        PiecewiseConstant2D(table)
