"""Measured BRDFs in the MERL format (Matusik et al. 2003), docs/fitting.md.

A MERL file holds three int32 dimensions (90, 90, 180) for (θh, θd, φd) and
then three blocks (red, green, blue) of 90 · 90 · 180 float64 values, cell
``(i_θh · 90 + i_θd) · 180 + i_φd``; a stored value times its channel's scale
(1/1500, 1.15/1500, 1.66/1500) is f in 1/sr, and a negative value marks a
cell without data. The indices:

    i_θh = floor(sqrt(θh / (π/2)) · 90)   (finer near the specular peak)
    i_θd = floor(θd / (π/2) · 90)
    i_φd = floor(φd / π · 180),  φd folded into [0, π) by reciprocity (φd >= π -> φd - π)

each clamped to its range; (θh, φh, θd, φd) are Rusinkiewicz's half and
difference angles (``wiwo_to_half_diff``). All arrays here are float64.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np

from . import _validate

if TYPE_CHECKING:
    from collections.abc import Callable
    from typing import Any, Literal

    from numpy.typing import NDArray

    from ._typing import Float64Array, RealArrayLike

__all__ = ["MerlBRDF", "load_merl", "save_merl", "merl_pairs", "wiwo_to_half_diff", "half_diff_to_wiwo",
           "MERL_SHAPE", "MERL_SCALE"]

MERL_SHAPE = (90, 90, 180)  # (θh, θd, φd) cells
MERL_SCALE = np.array([1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0])  # stored value x scale = f in 1/sr
_CELLS = MERL_SHAPE[0] * MERL_SHAPE[1] * MERL_SHAPE[2]
_HEADER_BYTES = 3 * 4
_FILE_BYTES = _HEADER_BYTES + 3 * _CELLS * 8
_HALF_PI = 0.5 * np.pi
_CENTRE_SNAP = 1e-9  # in cells: trilinear weights this close to 0 or 1 are taken as 0 or 1


def _rotate_z(v: Float64Array, angle: Float64Array) -> Float64Array:
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * v[..., 0] - s * v[..., 1], s * v[..., 0] + c * v[..., 1], v[..., 2]], axis=-1)


def _rotate_y(v: Float64Array, angle: Float64Array) -> Float64Array:
    c, s = np.cos(angle), np.sin(angle)
    return np.stack([c * v[..., 0] + s * v[..., 2], v[..., 1], -s * v[..., 0] + c * v[..., 2]], axis=-1)


def wiwo_to_half_diff(wi: RealArrayLike,
                      wo: RealArrayLike) -> tuple[Float64Array, Float64Array, Float64Array, Float64Array]:
    """Rusinkiewicz's angles (θh, φh, θd, φd) of unit directions ``(..., 3)``:
    h = normalize(wi + wo) at (θh, φh), and wi in the frame of h (rotated by
    -φh about n, then by -θh about the bitangent) at (θd, φd); φ in (-π, π]."""
    wi = _validate.directions("wi", wi).astype(np.float64)
    wo = _validate.directions("wo", wo).astype(np.float64)
    wi, wo = np.broadcast_arrays(wi, wo)
    half = wi + wo
    length = np.linalg.norm(half, axis=-1, keepdims=True)
    opposite = ~(length[..., 0] > 0.0)
    if opposite.any():
        where = _validate.element_name("", _validate.first_true(opposite), opposite.shape)
        raise ValueError(f"wi{where}, wo{where}: opposite directions have no half vector")
    half = half / length
    # polar angles by atan2, which keeps its digits near 0 where arccos does not
    theta_h = np.arctan2(np.hypot(half[..., 0], half[..., 1]), half[..., 2])
    phi_h = np.arctan2(half[..., 1], half[..., 0])
    diff = _rotate_y(_rotate_z(wi, -phi_h), -theta_h)
    theta_d = np.arctan2(np.hypot(diff[..., 0], diff[..., 1]), diff[..., 2])
    phi_d = np.arctan2(diff[..., 1], diff[..., 0])
    return theta_h, phi_h, theta_d, phi_d


def _angles(name: str, value: object) -> Float64Array:
    """Angles in radians: real numbers (not True/False, which are no angle), finite; TypeError or
    ValueError naming the argument."""
    angles = _validate.as_real_array(name, value)
    given = np.asarray(value)  # (as_real_array read it: no error here)
    if given.dtype == np.bool_:
        raise TypeError(f"{name}: expected an angle in radians (a real number or an array of them), got "
                        f"{'booleans' if given.ndim else type(value).__name__}")
    _validate.require_finite(name, angles)
    return angles


def half_diff_to_wiwo(theta_h: RealArrayLike, phi_h: RealArrayLike, theta_d: RealArrayLike,
                      phi_d: RealArrayLike) -> tuple[Float64Array, Float64Array]:
    """(wi, wo) ``(..., 3)`` from Rusinkiewicz's angles, the inverse of :func:`wiwo_to_half_diff`."""
    angles = [_angles(name, value) for name, value in
              (("theta_h", theta_h), ("phi_h", phi_h), ("theta_d", theta_d), ("phi_d", phi_d))]
    theta_h, phi_h, theta_d, phi_d = np.broadcast_arrays(*angles)
    diff = np.stack([np.sin(theta_d) * np.cos(phi_d), np.sin(theta_d) * np.sin(phi_d), np.cos(theta_d)], axis=-1)
    half = np.stack([np.sin(theta_h) * np.cos(phi_h), np.sin(theta_h) * np.sin(phi_h), np.cos(theta_h)], axis=-1)
    wi = _rotate_z(_rotate_y(diff, theta_h), phi_h)
    wo = 2.0 * np.sum(wi * half, axis=-1, keepdims=True) * half - wi
    return wi, wo


def _cell_coordinates(theta_h: Float64Array, theta_d: Float64Array,
                      phi_d: Float64Array) -> tuple[Float64Array, Float64Array, Float64Array]:
    """Continuous cell coordinates (cell i spans [i, i + 1)), φd folded into [0, π)."""
    phi_d = np.where(phi_d < 0.0, phi_d + 2.0 * np.pi, phi_d)
    phi_d = np.where(phi_d >= np.pi, phi_d - np.pi, phi_d)
    x_h = np.sqrt(np.clip(theta_h, 0.0, None) / _HALF_PI) * MERL_SHAPE[0]
    x_d = theta_d / _HALF_PI * MERL_SHAPE[1]
    x_p = phi_d / np.pi * MERL_SHAPE[2]
    return x_h, x_d, x_p


def _indices(theta_h: Float64Array, theta_d: Float64Array, phi_d: Float64Array) -> tuple[NDArray[np.int64], ...]:
    coordinates = _cell_coordinates(theta_h, theta_d, phi_d)
    return tuple(np.clip(np.floor(x).astype(np.int64), 0, size - 1) for x, size in zip(coordinates, MERL_SHAPE))


def _steps(step: int | tuple[int, int, int]) -> tuple[slice, slice, slice]:
    """Every ``step``-th cell along (θh, θd, φd): one stride for all three axes or one per axis."""
    values = step if isinstance(step, tuple) else (step,) * 3
    if len(values) != 3 or any(isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer))
                               for v in values):
        raise TypeError(f"step: expected a positive integer or three (θh, θd, φd), got {step!r}")
    if any(v < 1 for v in values):
        raise ValueError(f"step: expected strides >= 1, got {step!r}")
    return tuple(slice(None, None, int(v)) for v in values)  # type: ignore[return-value]


def merl_pairs(phi_h: float = 0.0, *, step: int | tuple[int, int, int] = 1) -> tuple[Float64Array, Float64Array]:
    """(wi, wo), each ``(90 · 90 · 180, 3)``, at the cells' centres in the file's
    order, with the half vector at azimuth ``phi_h`` (radians; the table holds an
    isotropic BRDF, the same at every φh): the pairs to evaluate a model at, or to
    fit one to a table's :meth:`MerlBRDF.values`. Some lie below the horizon
    (θh + θd > 90°). ``step``: every ``step``-th cell along each axis (an integer),
    or along (θh, θd, φd) (three), in the same order as ``MerlBRDF.values(step=...)``:
    a coarse subset of the table, e.g. ``step=(1, 3, 12)`` keeps every θh cell (the
    specular peak's) and 1 in 36 of the others."""
    phi = _angles("phi_h", phi_h)
    if phi.ndim != 0:
        raise ValueError(f"phi_h: expected one angle in radians, got shape {phi.shape}")
    # half_diff_to_wiwo's arithmetic on the grid's axes: the angles' sines and cosines are taken
    # once per axis and broadcast, which gives its bits at a fraction of its cost
    along_h, along_d, along_p = (np.arange(size, dtype=np.float64)[cells] + 0.5 for size, cells
                                 in zip(MERL_SHAPE, _steps(step)))
    theta_h = ((along_h / MERL_SHAPE[0]) ** 2 * _HALF_PI)[:, None, None]
    theta_d = (along_d / MERL_SHAPE[1] * _HALF_PI)[None, :, None]
    phi_d = (along_p / MERL_SHAPE[2] * np.pi)[None, None, :]
    phi_h = np.float64(phi)
    diff = (np.sin(theta_d) * np.cos(phi_d), np.sin(theta_d) * np.sin(phi_d), np.cos(theta_d))
    half = (np.sin(theta_h) * np.cos(phi_h), np.sin(theta_h) * np.sin(phi_h), np.cos(theta_h))
    c, s = np.cos(theta_h), np.sin(theta_h)
    tilted = (c * diff[0] + s * diff[2], np.broadcast_to(diff[1], (len(along_h),) + diff[1].shape[1:]),
              -s * diff[0] + c * diff[2])  # _rotate_y(diff, θh)
    c, s = np.cos(phi_h), np.sin(phi_h)
    wi = np.stack([c * tilted[0] - s * tilted[1], s * tilted[0] + c * tilted[1], tilted[2]], axis=-1)  # _rotate_z
    wi = wi.reshape(-1, 3)
    half_vectors = np.stack(np.broadcast_arrays(*half), axis=-1)[:, 0, 0]  # (n_h, 3)
    half_vectors = np.repeat(half_vectors, len(along_d) * len(along_p), axis=0)
    wo = 2.0 * np.sum(wi * half_vectors, axis=-1, keepdims=True) * half_vectors - wi
    return wi, wo


class MerlBRDF:
    """A MERL table: ``table`` ``(3, 90, 90, 180)`` of f in 1/sr, NaN where there is no data."""

    table: Float64Array

    def __init__(self, table: RealArrayLike) -> None:
        array = np.array(_validate.as_real_array("table", table), dtype=np.float64)
        if array.shape != (3,) + MERL_SHAPE:
            raise ValueError(f"table: expected shape {(3,) + MERL_SHAPE} (channel, θh, θd, φd), got {array.shape}")
        _require_brdf_values("table", array)
        self.table = array

    def values(self, *, step: int | tuple[int, int, int] = 1) -> Float64Array:
        """f ``(90 · 90 · 180, 3)`` in :func:`merl_pairs`' order, NaN where missing; ``step``
        as for :func:`merl_pairs` (every ``step``-th cell), in the same order."""
        return self.table[(slice(None),) + _steps(step)].reshape(3, -1).T.copy()

    def eval(self, wi: RealArrayLike, wo: RealArrayLike,
             interpolation: Literal["nearest", "linear"] = "nearest") -> Float64Array:
        """f(wi, wo) ``(..., 3)`` in 1/sr from the table: the cell the format's indices name
        (``"nearest"``), or trilinear between cell centres (``"linear"``, φd periodic with
        period π, the other axes clamped; at a cell's centre, within 1e-9 of a cell, that
        cell alone). NaN where a cell used (of weight > 0) has no data; 0 where wi or wo
        lies at or below the horizon."""
        if interpolation not in ("nearest", "linear"):
            raise ValueError(f"interpolation: expected 'nearest' or 'linear', got {interpolation!r}")
        theta_h, _, theta_d, phi_d = wiwo_to_half_diff(wi, wo)
        wi = np.asarray(wi, dtype=np.float64)
        wo = np.asarray(wo, dtype=np.float64)
        above = (wi[..., 2] > 0.0) & (wo[..., 2] > 0.0)
        if interpolation == "nearest":
            i_h, i_d, i_p = _indices(theta_h, theta_d, phi_d)
            f = np.moveaxis(self.table[:, i_h, i_d, i_p], 0, -1)
        else:
            f = self._trilinear(*_cell_coordinates(theta_h, theta_d, phi_d))
        return np.where(above[..., None], f, 0.0)

    def _trilinear(self, x_h: Float64Array, x_d: Float64Array, x_p: Float64Array) -> Float64Array:
        result: Any = 0.0  # then the weighted sum of the corners' arrays
        corners = []
        for x, size, periodic in ((x_h, MERL_SHAPE[0], False), (x_d, MERL_SHAPE[1], False), (x_p, MERL_SHAPE[2], True)):
            position = x - 0.5  # centres sit at i + 0.5
            low = np.floor(position)
            # a lookup at a cell's centre (to the rounding of the angles' round trip) reads that cell alone
            weight = position - low
            weight = np.where(weight < _CENTRE_SNAP, 0.0, np.where(weight > 1.0 - _CENTRE_SNAP, 1.0, weight))
            low = low.astype(np.int64)
            high = low + 1
            if periodic:
                low, high = low % size, high % size
            else:
                low, high = np.clip(low, 0, size - 1), np.clip(high, 0, size - 1)
            corners.append(((low, 1.0 - weight), (high, weight)))
        for index_h, weight_h in corners[0]:
            for index_d, weight_d in corners[1]:
                for index_p, weight_p in corners[2]:
                    cell = np.moveaxis(self.table[:, index_h, index_d, index_p], 0, -1)
                    weight = (weight_h * weight_d * weight_p)[..., None]
                    # a corner of weight 0 adds nothing, even where it has no data (NaN)
                    result = result + np.where(weight > 0.0, weight * cell, 0.0)
        return result


def _require_brdf_values(name: str, values: Float64Array) -> None:
    """f >= 0 and finite, or NaN (no data): a negative value would be written as "no data"."""
    bad = ~((values >= 0.0) & (values < np.inf)) & ~np.isnan(values)
    if bad.any():
        i = _validate.first_true(bad)
        raise ValueError(f"{_validate.element_name(name, i, values.shape)}: {float(values.ravel()[i])!r} is not a "
                         "BRDF value (finite and >= 0, or NaN for no data)")


def load_merl(path: str | bytes | os.PathLike[str] | int) -> MerlBRDF:
    """Reads a MERL ``.binary`` file: ``path`` a path, or an open file descriptor (an int),
    read from its current position and left open. A file of the wrong size or header is a
    ValueError saying what was expected; a stored value that is NaN or infinite is a ValueError
    naming its channel and cell (a negative value marks a cell without data: NaN in the table)."""
    if isinstance(path, (bool, np.bool_)) or not isinstance(path, (str, bytes, os.PathLike, int)):
        raise TypeError(f"path: expected a path or an open file descriptor (int), got {type(path).__name__}")
    where = f"file descriptor {path}" if isinstance(path, int) else os.fsdecode(path)
    descriptor = isinstance(path, int)
    size = os.fstat(path).st_size if isinstance(path, int) else os.path.getsize(path)
    with open(path, "rb", closefd=not descriptor) as f:
        start = f.tell() if descriptor and f.seekable() else 0
        header = np.frombuffer(f.read(_HEADER_BYTES), dtype="<i4")
        if header.size != 3 or tuple(int(v) for v in header) != MERL_SHAPE:
            raise ValueError(f"{where}: expected a MERL header of three int32 dimensions {MERL_SHAPE}, "
                             f"got {tuple(int(v) for v in header)}")
        if f.seekable() and size - start != _FILE_BYTES:
            raise ValueError(f"{where}: expected {_FILE_BYTES} bytes (a 12-byte header and 3 x {_CELLS} float64), "
                             f"got {size - start}")
        data = f.read(3 * _CELLS * 8)
        if len(data) != 3 * _CELLS * 8:
            raise ValueError(f"{where}: expected {_FILE_BYTES} bytes (a 12-byte header and 3 x {_CELLS} float64), "
                             f"got {_HEADER_BYTES + len(data)}")
    stored = np.frombuffer(data, dtype="<f8").reshape((3,) + MERL_SHAPE)
    bad = ~np.isfinite(stored)
    if bad.any():
        channel, i_h, i_d, i_p = (int(i) for i in np.unravel_index(int(np.argmax(bad)), stored.shape))
        color = ("red", "green", "blue")[channel]
        raise ValueError(f"{where}: channel {channel} ({color}), cell (θh {i_h}, θd {i_d}, "
                         f"φd {i_p}): stored value {float(stored[channel, i_h, i_d, i_p])!r} is not finite "
                         "(a negative value marks a cell without data)")
    table = stored * MERL_SCALE[:, None, None, None]
    table[stored < 0.0] = np.nan
    return MerlBRDF(table)


def save_merl(path: str | os.PathLike[str],
              brdf: MerlBRDF | Callable[[Float64Array, Float64Array], RealArrayLike]) -> None:
    """Writes a MERL ``.binary`` file: ``brdf`` a :class:`MerlBRDF`, or any callable
    ``f(wi, wo) -> (..., 3)`` in 1/sr (e.g. ``lambda wi, wo: pb.reference.eval(m, wi, wo)``),
    evaluated at the cells' centres. NaN (missing) is written as -1."""
    if isinstance(path, (bool, np.bool_)) or not isinstance(path, (str, bytes, os.PathLike, int)):
        raise TypeError(f"path: expected a path or an open file descriptor (int), got {type(path).__name__}")
    if isinstance(brdf, MerlBRDF):
        table = brdf.table
    elif callable(brdf):
        wi, wo = merl_pairs()
        values = np.asarray(brdf(wi, wo), dtype=np.float64)
        if values.shape != (_CELLS, 3):
            raise ValueError(f"brdf: expected the callable to return ({_CELLS}, 3) values, got {values.shape}")
        _require_brdf_values("brdf", values)
        table = values.T.reshape((3,) + MERL_SHAPE)
    else:
        raise TypeError(f"brdf: expected a MerlBRDF or a callable f(wi, wo), got {type(brdf).__name__}")
    stored = table / MERL_SCALE[:, None, None, None]
    stored = np.where(np.isnan(stored), -1.0, stored)
    with open(path, "wb") as f:
        np.asarray(MERL_SHAPE, dtype="<i4").tofile(f)
        stored.astype("<f8").tofile(f)
