"""Light that passes through a sphere of a 2015 material, for the pictures of
:mod:`principled_brdf.render`.

A path that the BSDF sends below the sphere's surface at the camera's hit
(refraction into a solid, transmission through a thin shell) travels along
the chord to the far side, where the material scatters it again as seen from
inside (``wo`` below the local tangent plane): out into the environment, or
back inside for another chord. Every event is drawn by ``pb.sample`` itself
and weighted by its weight ``f |cos θl| / pdf``, so a converged picture is a
visual proof of the sampler. Paths stop after :data:`MAX_BOUNCES` events
inside; from the :data:`ROULETTE_AFTER`-th on, each continues with probability
``q = min(max channel of its throughput, 1)`` and is divided by ``q``
(Russian roulette, unbiased). Under a latitude-longitude map each event
inside also draws a direction from the map (next-event estimation: the
outside is unoccluded from the sphere's surface), and the two strategies are
combined by the power heuristic (Veach 1997, eq. 9.13), as at the camera's
hit. The sphere is the unit sphere of render.py,
each point shaded in the same frame (normal, tangent along the latitude).
The uniforms of an event inside are the path's sample's point of a 6-d
low-discrepancy (Kronecker) sequence, shifted by a hash of its pixel, the seed
and the event: the samples of a pixel spread evenly over each event's
dimensions, a sphere looks the same rendered alone or in a batch, and a
picture the same on every run.
"""

from __future__ import annotations

import typing

import numpy as np

from . import _low_discrepancy, _validate
from ._batch import eval_pdf as _eval_pdf
from ._batch import sample as _sample
from .environment import Environment

if typing.TYPE_CHECKING:
    from collections.abc import Callable

    from numpy.typing import ArrayLike

    from ._typing import Float32Array, Float64Array, FloatArray, Model
    from .material import Material

MAX_BOUNCES = 16  # scattering events inside the sphere after the camera's
ROULETTE_AFTER = 4  # events inside before Russian roulette starts


def frames(normal: FloatArray) -> tuple[Float64Array, Float64Array]:
    """``(tangent, bitangent)`` of unit normals ``(..., 3)``: the tangent along the latitude,
    ``(n_z, 0, -n_x)`` normalised (``+x`` at the poles), the bitangent ``n x t``."""
    n = np.asarray(normal, dtype=np.float64)
    tangent = np.stack([n[..., 2], np.zeros(n.shape[:-1]), -n[..., 0]], axis=-1)
    length = np.linalg.norm(tangent, axis=-1, keepdims=True)
    tangent = np.where(length > 1e-9, tangent / np.maximum(length, 1e-300), np.array([1.0, 0.0, 0.0]))
    return tangent, np.cross(n, tangent)


def inner_uniforms(sample: np.ndarray, pixel: np.ndarray, seed: int, event: int) -> Float32Array:
    """``(P, 6)`` uniforms of one ``event`` inside for the paths of ``sample`` indices and
    ``pixel`` indices: the 6-d Kronecker point of the sample, shifted by a hash of the pixel
    and the event (:mod:`principled_brdf._low_discrepancy`)."""
    shift = _low_discrepancy.hashed_uniforms(pixel, seed, event, 6)
    return _low_discrepancy.shifted_points(sample, shift)


def power_heuristic(pdf: FloatArray, other: FloatArray) -> Float64Array:
    """Veach's power heuristic (β = 2) for one sample of each of two strategies:
    ``pdf² / (pdf² + other²)``, 0 where both densities are 0."""
    p, q = np.broadcast_arrays(np.asarray(pdf, dtype=np.float64) ** 2, np.asarray(other, dtype=np.float64) ** 2)
    return np.divide(p, p + q, out=np.zeros(p.shape), where=p > 0.0)


def callable_radiance(environment: Callable[[Float32Array], ArrayLike], directions: Float32Array) -> np.ndarray:
    """``environment(directions)`` of a callable ``L(direction)``, checked as a map's pixels are:
    real RGB radiance of the directions' shape ``(..., 3)``, finite and >= 0 (its dtype kept);
    otherwise an error naming ``environment`` and the first direction at fault."""
    radiance = np.asarray(environment(directions))
    if radiance.dtype.kind not in "biuf":
        raise TypeError(f"environment: the callable returned {radiance.dtype} values, expected real RGB radiance")
    if radiance.shape != directions.shape:
        raise ValueError(f"environment: expected radiance of shape {directions.shape} (RGB for each direction) "
                         f"from the callable, got {radiance.shape}")
    if not _validate.all_within(radiance, 0.0, np.inf):
        with np.errstate(invalid="ignore"):
            bad = ~((radiance >= 0.0) & (radiance < np.inf))
        i = _validate.first_true(bad)
        direction = ", ".join(f"{float(x):.4g}" for x in directions.reshape(-1, 3)[i // 3])
        raise ValueError(f"environment: the callable returned {float(radiance.ravel()[i])!r} at direction "
                         f"[{direction}] (radiance is finite and >= 0)")
    return radiance


def _local(direction: Float64Array, tangent: Float64Array, bitangent: Float64Array, normal: Float64Array) -> Float64Array:
    return np.stack([np.sum(f * direction, axis=-1) for f in (tangent, bitangent, normal)], axis=-1)


def _unit(v: Float64Array) -> Float64Array:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def through_the_sphere(material_at: Callable[[np.ndarray], Material], element: np.ndarray, normal: FloatArray,
                       direction: FloatArray, throughput: FloatArray, radiance: Callable[[Float32Array], ArrayLike],
                       model: Model, sample: np.ndarray, pixel: np.ndarray, seed: int,
                       energy_compensation: bool = False) -> Float64Array:
    """The radiance ``(P, 3)`` each path brings back: paths entering the sphere at the camera's
    hit points ``normal`` (``(P, 3)``, camera space) along ``direction`` (``(P, 3)``, into the
    sphere) with ``throughput`` (``(P, 3)``, the first event's weight). ``material_at(element)``
    gives the material of the paths' elements; ``radiance(direction)`` the environment;
    ``sample`` and ``pixel`` (``(P,)`` integers) name the paths for their random numbers;
    ``energy_compensation`` as in ``pb.eval``."""
    out = np.zeros((len(element), 3))
    path = np.arange(len(element))
    point = np.asarray(normal, dtype=np.float64)
    travel = _unit(np.asarray(direction, dtype=np.float64))
    weight = np.asarray(throughput, dtype=np.float64)
    for bounce in range(1, MAX_BOUNCES + 1):
        if len(path) == 0:
            break
        # along the chord to the far side: |p + s d| = 1 with |p| = 1 gives s = -2 p·d
        point = _unit(point - 2.0 * np.sum(point * travel, axis=-1, keepdims=True) * travel)
        tangent, bitangent = frames(point)
        wo = _local(-travel, tangent, bitangent, point).astype(np.float32)
        material = material_at(element[path])
        u = inner_uniforms(sample[path], pixel[path], seed, bounce)
        if isinstance(radiance, Environment):  # the map's strategy: f |cos θl| L / pdf_light, weighted
            towards, light_pdf, light = radiance._sample_unchecked(u[:, 4:6])
            local = _local(towards.astype(np.float64), tangent, bitangent, point)
            value, bsdf_pdf = _eval_pdf(material, local.astype(np.float32), wo, cosine=True, model=model, check=False,
                                        energy_compensation=energy_compensation)
            share = np.divide(power_heuristic(light_pdf, bsdf_pdf), light_pdf, out=np.zeros(len(path)),
                              where=(light_pdf > 0.0) & (local[:, 2] > 0.0))
            out[path] += weight * value * light * share[:, None]
        drawn = _sample(material, wo, u=u[:, :3], model=model, check=False, energy_compensation=energy_compensation)
        wi = drawn.wi.astype(np.float64)
        leaving = wi[:, 0:1] * tangent + wi[:, 1:2] * bitangent + wi[:, 2:3] * point
        weight = weight * drawn.weight
        exits = wi[:, 2] > 0.0
        if exits.any():
            outward = leaving[exits].astype(np.float32)
            if isinstance(radiance, Environment):
                seen, light_pdf = radiance._lookup_unchecked(outward)
                arriving = seen * power_heuristic(drawn.pdf[exits], light_pdf)[:, None]
            else:
                arriving = callable_radiance(radiance, outward).astype(np.float64)
            out[path[exits]] += weight[exits] * arriving
        keep = ~exits & (drawn.pdf > 0.0)
        if bounce >= ROULETTE_AFTER:
            survival = np.minimum(weight.max(axis=-1), 1.0)
            keep &= u[:, 3] < survival
            weight = weight / np.where(keep, survival, 1.0)[:, None]
        path, point, travel, weight = path[keep], point[keep], _unit(leaving[keep]), weight[keep]
    return out
