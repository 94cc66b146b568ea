"""Latitude-longitude environment maps: radiance from every direction, importance-sampled.

Directions are camera space as in :mod:`principled_brdf.render` (x right, y up, z towards
the viewer). Row 0 of a map is straight up, its last row straight down (``θ`` from +y,
``v = θ / π``); along a row ``φ = 2π u`` turns from +z (behind the viewer: the map's left
and right edges) through -x at ``u = 1/4``, -z (in front of the viewer, behind the sphere)
at the centre and +x at ``u = 3/4``, so that the map reads as the panorama of a viewer
looking along -z::

    direction = (-sin θ sin φ, cos θ, sin θ cos φ)

A map is piecewise constant (each pixel one radiance, looked up without filtering), so
the sampling density below is exactly proportional to the pixel's luminance: the
:class:`~principled_brdf.piecewise.PiecewiseConstant2D` distribution of ``luminance ·
sin θ`` (the ``sin θ`` of the row's centre: the solid angle of a pixel shrinks towards the
poles), whose density over ``(u, v)`` becomes ``pdf_uv / (2π² sin θ)`` per steradian
(``dω = sin θ dθ dφ = 2π² sin θ du dv``).
"""

from __future__ import annotations

import os
import typing

import numpy as np

from . import _color, _validate, piecewise

if typing.TYPE_CHECKING:
    from ._typing import Float32Array, Float64Array, FloatArray, RealArrayLike

__all__ = ["Environment", "MAP_FORMATS", "MAX_MAP_PIXELS", "directions_to_uv", "uv_to_directions", "read_map"]

#: The map files :meth:`Environment.read` takes, by extension.
MAP_FORMATS = {".exr": "OpenEXR (the `exr` extra)", ".hdr": "Radiance RGBE (the `hdr` extra: opencv-python-headless)"}
MAX_MAP_PIXELS = 1 << 26  # 8192 x 8192: a map and its distribution stay within a few GB


def uv_to_directions(uv: RealArrayLike) -> Float32Array:
    """Unit directions ``(..., 3)`` of map coordinates ``(u, v)`` in [0, 1]² (``(..., 2)``).

    Float32, as the kernels take them (and numpy's float32 trigonometry is many times faster)."""
    uv = np.asarray(uv, dtype=np.float32)
    phi, theta = np.float32(2.0 * np.pi) * uv[..., 0], np.float32(np.pi) * uv[..., 1]
    sin_theta = np.sin(theta)
    return np.stack([-sin_theta * np.sin(phi), np.cos(theta), sin_theta * np.cos(phi)], axis=-1)


def directions_to_uv(directions: RealArrayLike) -> tuple[Float32Array, Float32Array]:
    """``(uv (..., 2), sin θ (...))`` of unit directions ``(..., 3)``; u in [0, 1), v in [0, 1] (float32)."""
    d = np.asarray(directions, dtype=np.float32)
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    sin_theta = np.hypot(x, z)
    u = np.arctan2(-x, z) * np.float32(0.5 / np.pi)
    u += u < 0.0
    v = np.arctan2(sin_theta, y) * np.float32(1.0 / np.pi)
    return np.stack([np.minimum(u, np.nextafter(np.float32(1.0), np.float32(0.0))), v], axis=-1), sin_theta


def _path(value: object) -> str:
    """A file's path (a str, bytes or ``os.PathLike``) as a str; TypeError naming ``path`` otherwise."""
    if not isinstance(value, (str, bytes, os.PathLike)):
        raise TypeError(f"path: expected a path to a .exr or .hdr file, got {type(value).__name__}")
    return os.fsdecode(os.fspath(value))


def read_map(path: str | os.PathLike[str]) -> Float32Array:
    """The linear RGB ``(H, W, 3)`` float32 pixels of a ``.exr`` (OpenEXR; channels ``RGB``
    or ``R``, ``G``, ``B``) or ``.hdr`` (Radiance RGBE, read by OpenCV) file."""
    path = _path(path)
    extension = os.path.splitext(path)[1].lower()
    if extension not in MAP_FORMATS:
        raise ValueError(f"environment: cannot read {extension or 'a file without an extension'!r} maps; "
                         f"supported: {', '.join(MAP_FORMATS)}")
    if not os.path.isfile(path):
        raise FileNotFoundError(f"environment: no such file: {path!r}")
    if extension == ".exr":
        try:
            import OpenEXR
        except ImportError:
            raise ImportError("reading .exr needs the OpenEXR package: pip install OpenEXR") from None
        try:
            with OpenEXR.File(path) as exr:
                channels = exr.channels()
                if "RGB" in channels:
                    pixels = np.asarray(channels["RGB"].pixels)
                elif all(name in channels for name in "RGB"):
                    pixels = np.stack([np.asarray(channels[name].pixels) for name in "RGB"], axis=-1)
                else:
                    raise ValueError(f"environment: {path!r} has no R, G, B channels (it has {', '.join(channels)})")
        except RuntimeError as error:  # OpenEXR's way of saying the file is not one it can read
            raise ValueError(f"environment: {path!r} is not a readable OpenEXR file ({error})") from None
        return np.asarray(pixels, dtype=np.float32)
    try:
        import cv2
    except ImportError:
        raise ImportError("reading .hdr needs OpenCV: pip install opencv-python-headless") from None
    bgr = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    if bgr is None or bgr.ndim != 3 or bgr.shape[2] != 3:
        raise ValueError(f"environment: {path!r} is not a readable Radiance RGBE (.hdr) image")
    return np.ascontiguousarray(bgr[..., ::-1], dtype=np.float32)


class Environment:
    """A latitude-longitude map of linear RGB radiance, ``(H, W, 3)`` with H >= 2 rows and
    W >= 2 columns, finite and non-negative (module docstring: the mapping and the density).

    Calling it, ``environment(directions)``, gives the radiance ``(..., 3)`` float32 of
    camera-space unit directions ``(..., 3)`` (so it is also an ``L(direction)`` of
    :func:`principled_brdf.render.render_sphere`); :meth:`sample` draws directions in
    proportion to luminance and :meth:`pdf` gives that density per steradian. Their
    arguments are checked as everywhere in the library (docs/bad-input.md): directions
    finite and of unit length within 1e-3, uniforms in [0, 1], the shapes.
    """

    def __init__(self, image: RealArrayLike, name: str = "map") -> None:
        pixels = _validate.as_real_array("environment", image)
        if pixels.ndim != 3 or pixels.shape[2] != 3 or pixels.shape[0] < 2 or pixels.shape[1] < 2:
            raise ValueError(f"environment: expected a latitude-longitude map of shape (H, W, 3), H and W at "
                             f"least 2, got {pixels.shape}")
        if pixels.shape[0] * pixels.shape[1] > MAX_MAP_PIXELS:
            raise ValueError(f"environment: {pixels.shape[0]}x{pixels.shape[1]} pixels, beyond the "
                             f"{MAX_MAP_PIXELS} (8192²) a map may have")
        _validate.require_in_domain("environment", pixels, 0.0, float(np.finfo(np.float32).max))
        self.name = name
        self.image: Float32Array = pixels.astype(np.float32)
        rows = pixels.shape[0]
        sin_theta = np.sin(np.pi * (np.arange(rows) + 0.5) / rows)
        luminance = pixels @ np.array(_color.LUMINANCE_WEIGHTS)
        self.distribution = piecewise.PiecewiseConstant2D(luminance * sin_theta[:, None])
        self._radiance = self.image.reshape(-1, 3)
        self._density = self.distribution.density.ravel()

    @classmethod
    def read(cls, path: str | os.PathLike[str]) -> Environment:
        """The map in a ``.exr`` or ``.hdr`` file (:func:`read_map`)."""
        return cls(read_map(path), name=os.path.basename(_path(path)))

    def turned(self, degrees: float) -> Environment:
        """The scene turned about the vertical axis by ``degrees`` (a whole number of the map's
        columns, the nearest): what was at ``φ`` is now at ``φ + degrees`` (module docstring),
        so ``turned(180)`` brings what was behind the viewer behind the subject, lighting it
        from behind. The same radiance values, moved: no resampling."""
        turn = _validate.real_number("degrees", degrees)
        columns = self.image.shape[1]
        shift = round(turn / 360.0 * columns) % columns
        return Environment(np.roll(self.image, shift, axis=1), name=f"{self.name}, turned {turn:g}°")

    def __repr__(self) -> str:
        return f"Environment({self.name!r}, {self.image.shape[0]}x{self.image.shape[1]})"

    def __call__(self, directions: RealArrayLike) -> Float32Array:
        uv, _ = directions_to_uv(_validate.directions("directions", directions))
        return self._radiance[self.distribution.cell(uv)]

    def pdf(self, directions: RealArrayLike) -> Float64Array:
        """The density per steradian with which :meth:`sample` draws ``directions`` (0 at the poles)."""
        return self.lookup(directions)[1]

    def lookup(self, directions: RealArrayLike) -> tuple[Float32Array, Float64Array]:
        """``(radiance (..., 3), pdf (...))`` of ``directions``: the call and :meth:`pdf` at once."""
        return self._lookup_unchecked(_validate.directions("directions", directions))

    def _lookup_unchecked(self, directions: FloatArray) -> tuple[Float32Array, Float64Array]:
        """:meth:`lookup` of directions the caller made unit vectors (the renderers' own)."""
        uv, sin_theta = directions_to_uv(directions)
        pixel = self.distribution.cell(uv)  # the map's pixels are the distribution's cells
        return self._radiance[pixel], self._per_steradian(self._density[pixel], sin_theta)

    def sample(self, u: RealArrayLike) -> tuple[Float32Array, Float64Array, Float32Array]:
        """``(directions (..., 3), pdf per steradian (...), radiance (..., 3))`` for uniforms
        ``u`` of shape ``(..., 2)`` in [0, 1]."""
        uniforms = _validate.as_real_array("u", u)
        if uniforms.ndim == 0 or uniforms.shape[-1] != 2:
            raise ValueError(f"u: expected uniforms of shape (..., 2), got {uniforms.shape}")
        _validate.require_in_domain("u", uniforms, 0.0, 1.0)
        return self._sample_unchecked(uniforms)

    def _sample_unchecked(self, u: FloatArray) -> tuple[Float32Array, Float64Array, Float32Array]:
        """:meth:`sample` of uniforms ``(..., 2)`` the caller made (the renderers' own)."""
        uv, pixel = self.distribution.sample_cells(u)
        directions = uv_to_directions(uv)
        sin_theta = np.hypot(directions[..., 0], directions[..., 2])
        return directions, self._per_steradian(self._density[pixel], sin_theta), self._radiance[pixel]

    @staticmethod
    def _per_steradian(density: Float64Array, sin_theta: FloatArray) -> Float64Array:
        """A density over (u, v) per steradian: ``dω = 2π² sin θ du dv``; 0 at the poles."""
        return np.divide(density, np.float32(2.0 * np.pi**2) * sin_theta, out=np.zeros_like(density),
                         where=sin_theta > 0.0)
