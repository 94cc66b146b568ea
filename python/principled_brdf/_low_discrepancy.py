"""Deterministic uniforms for the pictures of :mod:`principled_brdf.render`: Kronecker
sequences (low discrepancy) shifted per pixel by a counter-based hash.

Roberts' generalised golden ratio in ``d`` dimensions: ``x_k = frac(k α)`` with
``α_j = φ_d^-(j+1)``, ``φ_d`` the real root above 1 of ``x^(d+1) = x + 1`` (φ_1 the golden
ratio, φ_2 the plastic number); its points fill ``[0, 1)^d`` evenly for any count. A
random shift per pixel (Cranley-Patterson rotation) keeps neighbouring pixels
uncorrelated. The hash is SplitMix64's output function (Steele et al. 2014) of a key
mixed with a stream of (seed, event).
"""

from __future__ import annotations

import functools
import typing

import numpy as np

if typing.TYPE_CHECKING:
    from ._typing import Float32Array, Float64Array

_BELOW_ONE = np.nextafter(np.float32(1.0), np.float32(0.0))


@functools.lru_cache(maxsize=16)
def kronecker_steps(dimensions: int) -> Float64Array:
    """``α`` of the ``dimensions``-d sequence (module docstring), by Newton's method from 2."""
    x = 2.0
    for _ in range(64):
        x -= (x ** (dimensions + 1) - x - 1.0) / ((dimensions + 1) * x**dimensions - 1.0)
    steps = x ** -np.arange(1.0, dimensions + 1.0)
    steps.flags.writeable = False
    return steps


def shifted_points(index: np.ndarray, shift: np.ndarray) -> Float32Array:
    """float32 points ``frac(k α + s)`` in [0, 1) for sample indices ``k`` (shape ``(...)``)
    and shifts ``s`` (``(..., d)``, in [0, 1)), ``α = kronecker_steps(d)``."""
    steps = kronecker_steps(shift.shape[-1])
    points = shift + np.mod(np.asarray(index, dtype=np.float64)[..., None] * steps, 1.0).astype(np.float32)
    points -= points >= 1.0  # frac of a sum of two numbers in [0, 1)
    return np.minimum(points, _BELOW_ONE)


def splitmix64(x: np.ndarray) -> np.ndarray:
    """The SplitMix64 output function of the state after ``x`` (uint64, wrapping)."""
    z = x + np.uint64(0x9E3779B97F4A7C15)
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return z ^ (z >> np.uint64(31))


def hashed_uniforms(keys: np.ndarray, seed: int, event: int, columns: int) -> Float32Array:
    """``(P, columns)`` float32 uniforms in [0, 1) of uint64 ``keys`` for one ``event`` of a ``seed``."""
    stream = splitmix64(np.array([seed * 64 + event], dtype=np.uint64))
    state = splitmix64(keys.astype(np.uint64) ^ stream)
    out = np.empty((len(keys), columns), np.float32)
    for j in range(columns):
        state = splitmix64(state)
        out[:, j] = (state >> np.uint64(40)).astype(np.float32) * np.float32(2.0**-24)
    return out
