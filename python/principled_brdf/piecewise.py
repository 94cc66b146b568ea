"""The 2D piecewise-constant distribution (Pharr, Jakob & Humphreys, *Physically Based
Rendering*, 3rd ed., section 13.6.7): a density over the unit square proportional to a
table of non-negative values, sampled by inverting the marginal distribution over rows
and then the conditional distribution within the chosen row.

The table ``function`` has shape ``(rows, columns)``; a point ``(u, v)`` of ``[0, 1)²``
lies in cell ``(floor(v rows), floor(u columns))`` (u along a row, v down the rows, as in
an image). The density of a cell is ``function[cell] / mean(function)``, so it integrates
to 1; an all-zero table is the uniform density. :class:`principled_brdf.environment.Environment`
builds one from a latitude-longitude map's luminance times ``sin θ``.
"""

from __future__ import annotations

import typing

import numpy as np

from . import _validate

if typing.TYPE_CHECKING:
    from numpy.typing import NDArray

    from ._typing import Float64Array, RealArrayLike

__all__ = ["PiecewiseConstant2D"]


def _cumulative(weights: Float64Array) -> Float64Array:
    """The cumulative distribution along the last axis, ``(..., n + 1)`` from 0 to exactly 1;
    a run of zero weights is the uniform distribution."""
    n = weights.shape[-1]
    sums = weights.sum(axis=-1, keepdims=True)
    uniform = np.broadcast_to(np.full(n, 1.0 / n), weights.shape)
    normalized = np.where(sums > 0.0, weights / np.where(sums > 0.0, sums, 1.0), uniform)
    cdf = np.concatenate([np.zeros(weights.shape[:-1] + (1,)), np.cumsum(normalized, axis=-1)], axis=-1)
    cdf[..., -1] = 1.0
    return np.minimum(cdf, 1.0)


_GUIDE_BUCKETS_PER_CELL = 4  # guide-table buckets per cell: at most 1 / 4 of the draws need a binary search


class _RowInverse:
    """Inversion of the cumulative distributions ``cdf`` ``(rows, n + 1)``, one per row.

    The cell of ``u`` in row ``r`` is the last ``i`` with ``cdf[r, i] <= u`` (so an empty cell,
    two equal boundaries, is never chosen). A guide table (Devroye 1986, section III.2.4)
    of ``K = 4 n`` buckets per row records the cells at the two ends of each bucket
    ``[b / K, (b + 1) / K)``: where they agree, the bucket lies inside one cell and that is
    the answer; the rest (at most ``n`` boundaries in ``K`` equal buckets: a quarter of the
    draws) is a binary search of the row's distribution."""

    def __init__(self, cdf: Float64Array) -> None:
        rows, cells = cdf.shape[0], cdf.shape[1] - 1
        self.cells = cells
        self.buckets = _GUIDE_BUCKETS_PER_CELL * cells
        edges = np.arange(self.buckets + 1) / self.buckets
        guide = np.empty((rows, self.buckets), np.int32)
        for r in range(rows):
            first = np.clip(np.searchsorted(cdf[r], edges[:-1], side="right") - 1, 0, cells - 1)  # a bucket's start
            last = np.clip(np.searchsorted(cdf[r], edges[1:], side="left") - 1, 0, cells - 1)  # just below its end
            guide[r] = np.where(first == last, first, -1)  # -1: the bucket holds a boundary, search
        self.guide = guide.ravel()
        self.lower = cdf[:, :-1].ravel()  # each cell's lower boundary, and its inverse width (0 if empty)
        width = np.diff(cdf, axis=-1).ravel()
        self.inverse_width = np.divide(1.0, width, out=np.zeros_like(width), where=width > 0.0)
        # each row offset by twice its index: one search of the flattened array serves every row
        self.flat = (cdf + 2.0 * np.arange(rows)[:, None]).ravel()

    def __call__(self, row: NDArray[np.int64], u: Float64Array) -> tuple[NDArray[np.int64], Float64Array]:
        """``(cell, position in [0, 1) within the cell)`` of uniforms ``u`` in rows ``row``."""
        bucket = np.minimum((u * self.buckets).astype(np.int64), self.buckets - 1)
        cell = self.guide[row * self.buckets + bucket].astype(np.int64)
        search = np.flatnonzero(cell < 0)
        found = np.searchsorted(self.flat, 2.0 * row[search] + u[search], side="right") - 1
        cell[search] = np.clip(found - row[search] * (self.cells + 1), 0, self.cells - 1)
        index = row * self.cells + cell
        offset = (u - self.lower[index]) * self.inverse_width[index]
        return cell, np.clip(offset, 0.0, np.nextafter(1.0, 0.0))


class PiecewiseConstant2D:
    """A density on ``[0, 1)²`` proportional to ``function`` (``(rows, columns)``, finite
    and non-negative): :meth:`sample` maps uniforms to points by inversion, :meth:`pdf`
    gives the density of any point."""

    def __init__(self, function: RealArrayLike) -> None:
        table = _validate.as_real_array("function", function)
        if table.ndim != 2 or table.shape[0] < 1 or table.shape[1] < 1:
            raise ValueError(f"function: expected a (rows, columns) table, got shape {table.shape}")
        _validate.require_in_domain("function", table, 0.0, np.inf)
        self.function = table
        self.shape = table.shape
        mean = float(table.mean())
        #: the density of each cell (it integrates to 1 over the unit square)
        self.density = table / mean if mean > 0.0 else np.ones_like(table)
        self.marginal_cdf = _cumulative(table.sum(axis=1))  # over rows
        self.conditional_cdf = _cumulative(table)  # over the columns of each row
        self._marginal = _RowInverse(self.marginal_cdf[None, :])
        self._conditional = _RowInverse(self.conditional_cdf)

    def sample(self, u: RealArrayLike) -> tuple[Float64Array, Float64Array]:
        """``(points (..., 2) as (u, v), pdf (...))`` for uniforms ``u`` of shape ``(..., 2)``
        in [0, 1): the row from the marginal distribution by ``u[..., 1]``, the column from
        that row's conditional distribution by ``u[..., 0]``."""
        points, cell = self.sample_cells(u)
        return points, self.density.ravel()[cell]

    def sample_cells(self, u: RealArrayLike) -> tuple[Float64Array, NDArray[np.int64]]:
        """:meth:`sample`'s points and the flat index ``row * columns + column`` of their cells."""
        uniforms = np.asarray(u, dtype=np.float64)
        if uniforms.ndim == 0 or uniforms.shape[-1] != 2:
            raise ValueError(f"u: expected uniforms of shape (..., 2), got {uniforms.shape}")
        rows, columns = self.shape
        flat = uniforms.reshape(-1, 2)
        row, row_offset = self._marginal(np.zeros(len(flat), np.int64), flat[:, 1])
        column, column_offset = self._conditional(row, flat[:, 0])
        points = np.stack([(column + column_offset) / columns, (row + row_offset) / rows], axis=-1)
        return points.reshape(uniforms.shape), (row * columns + column).reshape(uniforms.shape[:-1])

    def pdf(self, points: RealArrayLike) -> Float64Array:
        """The density at ``points`` ``(..., 2)`` as ``(u, v)`` in [0, 1] (1 counts as the last cell)."""
        return self.density.ravel()[self.cell(points)]

    def cell(self, points: RealArrayLike) -> NDArray[np.int64]:
        """The flat index ``row * columns + column`` of the cells of ``points`` ``(..., 2)``."""
        uv = np.asarray(points)
        rows, columns = self.shape
        column = np.minimum((uv[..., 0] * columns).astype(np.int64), columns - 1)
        row = np.minimum((uv[..., 1] * rows).astype(np.int64), rows - 1)
        return row * columns + column
