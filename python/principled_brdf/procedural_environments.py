"""The built-in environments, drawn by this code (no downloaded data): a photographic
*studio* and an *outdoor* scene, as latitude-longitude maps
(:class:`~principled_brdf.environment.Environment`).

Each is a radiance function of camera-space directions (x right, y up, z towards the
viewer) averaged over ``SUPERSAMPLING²`` directions per pixel, so edges are smooth at the
map's resolution. Units: a white Lambertian surface facing the key softbox or the sun
gets a radiance of about 1, the tone curves' mid-upper range.

- ``studio``: a dark surround (a cyclorama of radiance 0.01 to 0.02) and a grey floor,
  lit by four planar softboxes, each a rectangle of even radiance with soft edges: a large
  key up and to the left of the camera, a dimmer fill on the right, a strip overhead and
  a rim light behind the subject on the right. A mirror shows them as crisp rectangles,
  a metal's colour reads against the dark surround.
- ``outdoor``: a clear sky (a pale horizon to a deep blue zenith, a glow around the
  sun), a sun disk of 1.5° radius up and to the left of the camera, and a ground plane
  of checkered tiles (1 unit below the viewer, tiles of 0.5) that recede to the
  horizon: what glass bends is easy to see.
"""

from __future__ import annotations

import functools
import math
import typing

import numpy as np

from . import _validate, environment

if typing.TYPE_CHECKING:
    from collections.abc import Callable

    from ._typing import Float64Array, FloatArray, RealArrayLike

__all__ = ["BUILT_IN", "DEFAULT_HEIGHT", "MAX_HEIGHT", "SUPERSAMPLING", "SUN_DIRECTION", "SUN_RADIUS", "built_in",
           "studio", "outdoor", "studio_radiance", "outdoor_radiance"]

DEFAULT_HEIGHT = 512  # map rows (columns: twice as many); 0.35° a pixel
#: The most rows a built-in map may have: height x 2 height pixels within ``environment.MAX_MAP_PIXELS``
#: (2^26; the map is then 1.6 GB of float64 while it is made).
MAX_HEIGHT = math.isqrt(environment.MAX_MAP_PIXELS // 2)  # 5792
SUPERSAMPLING = 2  # directions averaged per pixel along each axis


def _unit(vector: tuple[float, float, float]) -> Float64Array:
    v = np.asarray(vector, dtype=np.float64)
    return v / np.linalg.norm(v)


def _smoothstep(edge0: float, edge1: float, x: FloatArray) -> Float64Array:
    t = np.clip((x - edge0) / (edge1 - edge0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def _softbox(d: FloatArray, centre: tuple[float, float, float], half_width: float, half_height: float,
             softness: float = 0.04, right: tuple[float, float, float] | None = None) -> Float64Array:
    """The relative radiance of a planar softbox seen from the origin: 1 at its centre, falling
    to 0.45 at its sides (the diffuser is brightest in front of the lamp), 0 outside over a
    soft edge.

    The rectangle is perpendicular to ``centre`` at unit distance; ``half_width`` and
    ``half_height`` are its half-extents there, along ``right`` (default: horizontal) and
    the axis perpendicular to both; ``softness`` the edge's width, the same units."""
    c = _unit(centre)
    r = _unit(right) if right is not None else _unit(tuple(np.cross((0.0, 1.0, 0.0), c)))
    up = np.cross(c, r)
    facing = d @ c
    ahead = facing > 1e-3
    scale = np.divide(1.0, facing, out=np.zeros_like(facing), where=ahead)  # to the plane at distance 1
    x, y = (d @ r) * scale, (d @ up) * scale
    inside = (_smoothstep(half_width + softness, half_width - softness, np.abs(x))
              * _smoothstep(half_height + softness, half_height - softness, np.abs(y)))
    falloff = 1.0 - 0.55 * np.minimum((x / half_width) ** 2 + (y / half_height) ** 2, 1.0)
    return np.where(ahead, inside * falloff, 0.0)


def studio_radiance(d: RealArrayLike) -> Float64Array:
    """The studio's RGB radiance ``(..., 3)`` of unit directions ``(..., 3)`` (module docstring),
    checked as everywhere in the library (finite, of unit length within 1e-3)."""
    return _studio(_validate.directions("d", d))


def _studio(d: FloatArray) -> Float64Array:
    y = d[..., 1]
    # the surround: a dark cyclorama, a little lighter towards the top
    surround = 0.012 + 0.01 * np.clip(y, 0.0, 1.0)
    # the floor: a plane one unit below, lit in a pool under the subject that fades into the dark
    below = y < -1e-3
    distance = np.hypot(d[..., 0], d[..., 2]) / np.where(below, -y, 1.0)
    floor = 0.01 + 0.07 * np.exp(-((distance / 1.5) ** 2))
    ground = _smoothstep(0.0, -0.04, y)  # the floor's far edge meets the cyclorama softly
    background = (surround + ground * (floor - surround))[..., None] * np.array([1.0, 0.98, 0.95])
    # a warm key (a tungsten-balanced lamp of about 4000 K) against cool-white fill and strips
    warm, neutral = np.array([1.0, 0.84, 0.66]), np.array([0.92, 0.96, 1.0])
    key = 9.0 * _softbox(d, (-1.0, 0.75, 0.85), 0.38, 0.55)  # a tall softbox up and to the left of the camera
    others = (2.5 * _softbox(d, (1.0, 0.1, 0.35), 0.25, 0.5)  # fill on the right
              + 5.0 * _softbox(d, (0.0, 1.0, -0.15), 0.75, 0.08, right=(1.0, 0.0, 0.0))  # strip overhead
              + 7.0 * _softbox(d, (0.75, 0.3, -1.0), 0.1, 0.55, softness=0.02))  # rim: a narrow strip behind
    return background + key[..., None] * warm + others[..., None] * neutral


SUN_DIRECTION = (-0.55, 0.6, 0.45)  # towards the sun: up and to the left of the camera
SUN_RADIUS = np.radians(1.5)


def outdoor_radiance(d: RealArrayLike) -> Float64Array:
    """The outdoor scene's RGB radiance ``(..., 3)`` of unit directions ``(..., 3)`` (module docstring),
    checked as everywhere in the library (finite, of unit length within 1e-3)."""
    return _outdoor(_validate.directions("d", d))


def _outdoor(d: FloatArray) -> Float64Array:
    y = d[..., 1]
    elevation = np.clip(y, 0.0, 1.0)
    zenith, horizon = np.array([0.05, 0.11, 0.32]), np.array([0.42, 0.48, 0.58])
    blend = (1.0 - elevation) ** 4
    sky = zenith + blend[..., None] * (horizon - zenith)
    sun = _unit(SUN_DIRECTION)
    angle = np.arccos(np.clip(d @ sun, -1.0, 1.0))
    glow = 0.5 * np.exp(-angle / 0.12) + 0.1 * np.exp(-angle / 0.6)
    sky = sky + glow[..., None] * np.array([1.0, 0.9, 0.75])
    disk = _smoothstep(SUN_RADIUS * 1.05, SUN_RADIUS * 0.95, angle)
    # a sun of irradiance ~4 on a surface facing it: radiance x solid angle (π radius²)
    sun_radiance = 4.0 / (np.pi * SUN_RADIUS**2)
    sky = sky + (sun_radiance * disk)[..., None] * np.array([1.0, 0.95, 0.85])
    # the ground: tiles of 0.5 one unit below, their contrast fading where they shrink below a pixel
    below = y < -1e-4
    scale = np.divide(1.0, -y, out=np.zeros_like(y), where=below)
    x, z = d[..., 0] * scale, d[..., 2] * scale
    checker = ((np.floor(2.0 * x) + np.floor(2.0 * z)) % 2.0)[..., None]
    light, dark = np.array([0.45, 0.41, 0.35]), np.array([0.08, 0.09, 0.11])
    distance = np.hypot(x, z)
    contrast = _smoothstep(7.0, 2.5, distance)[..., None]
    mean = 0.5 * (light + dark)
    tiles = mean + contrast * (np.where(checker > 0.5, light, dark) - mean)
    haze = _smoothstep(0.0, 0.25, -y)[..., None]  # towards the horizon the ground fades into the haze
    ground = horizon * 0.6 + haze * (tiles - horizon * 0.6)
    return np.where(below[..., None], ground, sky)


def _map(radiance: Callable[[FloatArray], Float64Array], height: int) -> Float64Array:
    """The ``(height, 2 height, 3)`` map of ``radiance``, each pixel the mean over its
    ``SUPERSAMPLING²`` sub-pixel centres (built a band of rows at a time)."""
    width, n = 2 * height, SUPERSAMPLING
    offsets = (np.arange(n) + 0.5) / n
    image = np.empty((height, width, 3))
    band = max(1, (1 << 20) // (width * n * n))
    for top in range(0, height, band):
        rows = np.arange(top, min(top + band, height))
        v = (rows[:, None] + offsets[None, :]).ravel() / height
        u = (np.arange(width)[:, None] + offsets[None, :]).ravel() / width
        uv = np.stack(np.broadcast_arrays(u[None, :], v[:, None]), axis=-1)
        values = radiance(environment.uv_to_directions(uv))  # (rows n, width n, 3)
        image[rows] = values.reshape(len(rows), n, width, n, 3).mean(axis=(1, 3))
    return image


@functools.lru_cache(maxsize=8)
def _cached(name: str, height: int) -> environment.Environment:
    return environment.Environment(_map(_RADIANCE[name], height), name=name)


def _height(value: object) -> int:
    """Map rows: an integer from 2 to :data:`MAX_HEIGHT`, checked before the map is made."""
    return _validate.integer_in("height", value, 2, MAX_HEIGHT, f" rows (a map of height x 2 height pixels, at most "
                                                               f"{environment.MAX_MAP_PIXELS})")


def studio(height: int = DEFAULT_HEIGHT) -> environment.Environment:
    """The studio (module docstring) as a ``(height, 2 height)`` map (made once per height;
    ``height`` from 2 to :data:`MAX_HEIGHT`)."""
    return _cached("studio", _height(height))


def outdoor(height: int = DEFAULT_HEIGHT) -> environment.Environment:
    """The outdoor scene (module docstring) as a ``(height, 2 height)`` map (made once per height;
    ``height`` from 2 to :data:`MAX_HEIGHT`)."""
    return _cached("outdoor", _height(height))


_RADIANCE = {"studio": _studio, "outdoor": _outdoor}
#: The built-in environments by name.
BUILT_IN: dict[str, Callable[..., environment.Environment]] = {"studio": studio, "outdoor": outdoor}


def built_in(name: str) -> environment.Environment:
    """The built-in environment ``name`` (:data:`BUILT_IN`) at its default size."""
    if name not in BUILT_IN:
        raise ValueError(f"environment: expected one of {', '.join(BUILT_IN)}, got {name!r}")
    return BUILT_IN[name]()
