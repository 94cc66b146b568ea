"""Directions and shading frames (docs/materials-and-directions.md), float64, vectorised.

The library's directions live in a local shading frame: normal z, tangent x
(the alpha_x axis), bitangent y. These helpers build such frames from
normals (and tangents) and move directions between world and local
coordinates; angles are in radians.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from . import _validate
from .measured import half_diff_to_wiwo, wiwo_to_half_diff

if TYPE_CHECKING:
    from ._typing import Float64Array, RealArrayLike

__all__ = ["spherical_to_direction", "direction_to_spherical", "frame_from_normal", "to_local", "to_world",
           "wiwo_to_half_diff", "half_diff_to_wiwo"]


def spherical_to_direction(theta: RealArrayLike, phi: RealArrayLike = 0.0) -> Float64Array:
    """(sin θ cos φ, sin θ sin φ, cos θ) ``(..., 3)``: θ from the normal, φ from the tangent."""
    theta, phi = np.broadcast_arrays(np.asarray(_validate.as_real_array("theta", theta), dtype=np.float64),
                                     np.asarray(_validate.as_real_array("phi", phi), dtype=np.float64))
    _validate.require_finite("theta", theta)
    _validate.require_finite("phi", phi)
    sin_theta = np.sin(theta)
    return np.stack([sin_theta * np.cos(phi), sin_theta * np.sin(phi), np.cos(theta)], axis=-1)


def direction_to_spherical(w: RealArrayLike) -> tuple[Float64Array, Float64Array]:
    """(θ, φ) of unit directions ``(..., 3)``: θ in [0, π] (by atan2, accurate near the
    normal), φ in (-π, π]."""
    w = _validate.directions("w", w)
    return np.arctan2(np.hypot(w[..., 0], w[..., 1]), w[..., 2]), np.arctan2(w[..., 1], w[..., 0])


def frame_from_normal(normal: RealArrayLike, tangent: RealArrayLike | None = None) -> Float64Array:
    """Orthonormal frames ``(..., 3, 3)`` whose rows are (tangent, bitangent, normal).

    Without ``tangent``, the tangent is the branchless construction of Duff et
    al. 2017 ("Building an Orthonormal Basis, Revisited"), continuous except
    across n.z = 0's sign change; with one, the tangent is its part
    orthogonal to the normal (Gram-Schmidt), so anisotropic materials follow it.
    The normal passes the direction check (docs/bad-input.md) and is then
    normalized (one unit to 1e-14 is kept as given), so the frames are
    orthonormal to float64's rounding."""
    n = _validate.directions("normal", normal)
    length2 = np.sum(n * n, axis=-1, keepdims=True)
    # normals already unit to float64's rounding stay exactly as given (the frame's last row)
    n = np.where(np.abs(length2 - 1.0) > 1e-14, n / np.sqrt(length2), n)
    if tangent is None:
        sign = np.where(n[..., 2] >= 0.0, 1.0, -1.0)
        a = -1.0 / (sign + n[..., 2])
        b = n[..., 0] * n[..., 1] * a
        t = np.stack([1.0 + sign * n[..., 0] ** 2 * a, sign * b, -sign * n[..., 0]], axis=-1)
    else:
        t = np.asarray(_validate.as_real_array("tangent", tangent), dtype=np.float64)
        if t.ndim == 0 or t.shape[-1] != 3:
            raise ValueError(f"tangent: expected shape (..., 3), got {t.shape}")
        _validate.require_finite("tangent", t)
        t, n = np.broadcast_arrays(t, n)
        # scaled to its largest component first, so that squares neither overflow nor underflow
        largest = np.max(np.abs(t), axis=-1, keepdims=True)
        t = t / np.where(largest > 0.0, largest, 1.0)
        t = t - np.sum(t * n, axis=-1, keepdims=True) * n
        length = np.linalg.norm(t, axis=-1, keepdims=True)
        parallel = ~(length > 1e-12)
        if parallel.any():
            i = _validate.first_true(parallel[..., 0])
            raise ValueError(f"{_validate.element_name('tangent', i, t.shape[:-1])}: zero or parallel to the normal")
        t = t / length
    bitangent = np.cross(n, t)
    return np.stack(np.broadcast_arrays(t, bitangent, n), axis=-2)


def _vectors_and_frames(w: RealArrayLike, frame: RealArrayLike) -> tuple[Float64Array, Float64Array]:
    """``w`` finite ``(..., 3)``; ``frame`` ``(..., 3, 3)`` orthonormal rows within the
    direction check's tolerance (1e-3 on every entry of frame frameᵀ - I)."""
    w = _validate.as_real_array("w", w)
    if w.ndim == 0 or w.shape[-1] != 3:
        raise ValueError(f"w: expected shape (..., 3), got {w.shape}")
    _validate.require_finite("w", w)
    frame = _validate.as_real_array("frame", frame)
    if frame.ndim < 2 or frame.shape[-2:] != (3, 3):
        raise ValueError(f"frame: expected shape (..., 3, 3) with rows (tangent, bitangent, normal), got {frame.shape}")
    _validate.require_finite("frame", frame)
    error = np.abs(np.einsum("...ij,...kj->...ik", frame, frame) - np.eye(3)).max(axis=(-2, -1))
    bad = error > _validate.DIRECTION_LENGTH_TOLERANCE
    if bad.any():
        i = _validate.first_true(bad)
        raise ValueError(f"{_validate.element_name('frame', i, frame.shape[:-2])}: rows not orthonormal "
                         f"(frame frameᵀ is {float(error.ravel()[i]):.3g} off the identity; "
                         f"within {_validate.DIRECTION_LENGTH_TOLERANCE:g})")
    return w, frame


def to_local(w: RealArrayLike, frame: RealArrayLike) -> Float64Array:
    """World directions ``(..., 3)`` in the frames ``(..., 3, 3)`` of :func:`frame_from_normal`
    (orthonormal rows, checked; finite ``w``)."""
    w, frame = _vectors_and_frames(w, frame)
    return np.einsum("...ij,...j->...i", frame, w)


def to_world(w: RealArrayLike, frame: RealArrayLike) -> Float64Array:
    """Local directions ``(..., 3)`` back to world coordinates (the frames' transpose)."""
    w, frame = _vectors_and_frames(w, frame)
    return np.einsum("...ji,...j->...i", frame, w)
