"""Lit-sphere pictures computed with the batched kernel.

A unit sphere seen from +z (orthographic), each pixel shaded in its own
tangent frame (normal n, tangent along the sphere's latitude), lit by one
directional light plus a constant ambient term. Returns linear RGB; use
:func:`to_srgb8` (a Reinhard-type tone curve on luminance, then sRGB) for a
displayable image.
"""

from __future__ import annotations

import struct
import zlib

import numpy as np

from . import _validate
from ._batch import eval as _eval
from ._batch import random_uniforms as _random_uniforms
from ._batch import sample as _sample
from .material import Material

__all__ = ["render_sphere", "render_environment", "sky_environment", "sphere_frames", "tone_map", "to_srgb8",
           "write_png", "DEFAULT_LIGHT", "MAX_RESOLUTION", "TONE_CURVES", "REINHARD_WHITE"]

DEFAULT_LIGHT = (-0.5, 0.6, 0.75)  # towards the light, camera space (x right, y up, z to the viewer)


MAX_RESOLUTION = 16384


def _resolution(value) -> int:
    value = _validate.integer("resolution", value)
    if not 2 <= value <= MAX_RESOLUTION:
        raise ValueError(f"resolution: expected 2 to {MAX_RESOLUTION} pixels, got {value}")
    return value


def _light_direction(value) -> np.ndarray:
    light = _validate.as_real_array("light", value)
    if light.shape != (3,):
        raise ValueError(f"light: expected a 3-vector towards the light, got shape {light.shape}")
    _validate.require_finite("light", light)
    length = float(np.linalg.norm(light))
    if not 0.0 < length < np.inf:
        raise ValueError(f"light: expected a non-zero direction, got {light.tolist()}")
    return light / length


def _non_negative(name: str, value) -> float:
    array = _validate.as_real_array(name, value)
    if array.shape != ():
        raise ValueError(f"{name}: expected one number, got shape {array.shape}")
    _validate.require_in_domain(name, array, 0.0, np.inf)
    return float(array)


def sphere_frames(resolution: int):
    """Per-pixel local directions for a sphere image.

    Returns ``(inside, to_local)``: ``inside`` is the ``(resolution, resolution)``
    mask of pixels on the sphere, and ``to_local(d)`` maps a camera-space unit
    vector ``d`` (3,) to each pixel's local shading frame, ``(H, W, 3)`` float32
    (pixels off the sphere get the normal, so every vector is valid).
    """
    resolution = _resolution(resolution)
    coords = (np.arange(resolution) + 0.5) / resolution * 2.0 - 1.0
    x, y = np.meshgrid(coords, -coords)  # row 0 at the top
    r2 = x * x + y * y
    inside = r2 < 1.0
    z = np.sqrt(np.clip(1.0 - r2, 1e-12, None))
    normal = np.stack([x, y, z], axis=-1)
    normal[~inside] = (0.0, 0.0, 1.0)
    tangent = np.stack([normal[..., 2], np.zeros_like(x), -normal[..., 0]], axis=-1)
    tangent /= np.linalg.norm(tangent, axis=-1, keepdims=True)
    bitangent = np.cross(normal, tangent)

    def to_local(direction) -> np.ndarray:
        d = np.asarray(direction, dtype=np.float64)
        d = d / np.linalg.norm(d)
        local = np.stack([tangent @ d, bitangent @ d, normal @ d], axis=-1)
        local /= np.linalg.norm(local, axis=-1, keepdims=True)
        return local.astype(np.float32)

    return inside, to_local


def render_sphere(material: Material, resolution: int = 256, light=DEFAULT_LIGHT, light_intensity: float = 3.0,
                  ambient: float = 0.03, model: str = "disney2014") -> np.ndarray:
    """Linear RGB ``(resolution, resolution, 3)`` image of ``material`` on a sphere.

    ``material`` may be uniform or per pixel (leading shape ``(resolution, resolution)``,
    e.g. made by :meth:`Material.mix` with a mask); a leading shape ``S + (1, 1)``
    renders one sphere per material, ``S + (resolution, resolution, 3)``, in one
    kernel call. Background is 0.
    """
    light = _light_direction(light)
    light_intensity = _non_negative("light_intensity", light_intensity)
    ambient = _non_negative("ambient", ambient)
    inside, to_local = sphere_frames(resolution)
    wi, wo = to_local(light), to_local((0.0, 0.0, 1.0))
    radiance = np.float32(light_intensity) * _eval(material, wi, wo, cosine=True, model=model)
    radiance += np.float32(ambient) * np.asarray(material.base_color, dtype=np.float32)
    radiance[..., ~inside, :] = 0.0
    return radiance


def sky_environment(direction, zenith=(0.25, 0.45, 1.0), horizon=(1.0, 1.0, 1.0), ground=(0.25, 0.22, 0.2)):
    """A simple sky/ground gradient ``L(w)`` (RGB radiance) for camera-space directions ``(..., 3)``.

    y is up (as in :mod:`principled_brdf.render`): above the horizon the sky
    goes from ``horizon`` to ``zenith`` as ``sqrt(y)``; below it is ``ground``,
    blended over a narrow band around the horizon.
    """
    w = np.asarray(direction, dtype=np.float64)
    up = w[..., 1:2]
    zenith, horizon, ground = (np.asarray(c, dtype=np.float64) for c in (zenith, horizon, ground))
    sky = horizon + (zenith - horizon) * np.sqrt(np.clip(up, 0.0, 1.0))
    blend = np.clip(0.5 + up / 0.04, 0.0, 1.0)
    return ground + (sky - ground) * blend


def render_environment(material: Material, resolution: int = 256, environment=None, samples: int = 64, seed: int = 0,
                       model: str = "disney2014") -> np.ndarray:
    """Linear RGB ``(resolution, resolution, 3)``: the sphere of :func:`render_sphere` lit by
    ``environment`` (camera-space directions ``(..., 3)`` to RGB radiance; default
    :func:`sky_environment`), per pixel ``∫ f L(wi) cos θl dωi`` estimated from
    ``samples`` importance samples (``pb.sample``, reproducible from ``seed``)."""
    environment = sky_environment if environment is None else environment
    inside, to_local = sphere_frames(resolution)
    wo = to_local((0.0, 0.0, 1.0))
    # to_local(e_k)[..., j] = frame_j[k]: the rows of the local-to-camera matrix.
    to_camera = np.stack([to_local(e) for e in np.eye(3)], axis=-2)  # [..., k, j]
    pixels = resolution * resolution
    chunk = max(1, (1 << 20) // pixels)
    total = np.zeros((resolution, resolution, 3))
    for start in range(0, samples, chunk):
        count = min(chunk, samples - start)
        u = _random_uniforms(seed, count * pixels, first=start * pixels).reshape(count, resolution, resolution, 3)
        drawn = _sample(material, wo, u=u, model=model)
        direction = np.einsum("...kj,s...j->s...k", to_camera, drawn.wi)
        radiance = np.asarray(environment(direction), dtype=np.float64)
        if radiance.shape != direction.shape:
            raise ValueError(f"environment: expected RGB radiance of shape {direction.shape}, got {radiance.shape}")
        total += np.einsum("s...c,s...c->...c", drawn.weight.astype(np.float64), radiance)
    total /= samples
    total[~inside] = 0.0
    return total


TONE_CURVES = ("reinhard", "clip")
REINHARD_WHITE = 4.0  # the luminance the default curve maps to display white


def tone_map(linear: np.ndarray, exposure: float = 1.0, curve: str = "reinhard") -> np.ndarray:
    """Scene-referred linear RGB ``(..., 3)`` to display-referred linear RGB in [0, 1].

    ``"reinhard"``: the extended Reinhard curve on luminance, ``Y' = Y (1 + Y /
    W²) / (1 + Y)`` with white ``W`` = :data:`REINHARD_WHITE`, each pixel's
    colour scaled by ``Y'/Y`` and, where a channel would still exceed 1,
    divided by that channel (so a gold highlight stays gold and a white
    material keeps its shading instead of clipping flat). ``"clip"``: each
    channel clipped to [0, 1]. Both after multiplying by ``exposure``."""
    if curve not in TONE_CURVES:
        raise ValueError(f"curve: expected one of {', '.join(TONE_CURVES)}, got {curve!r}")
    exposure = _non_negative("exposure", exposure)
    c = np.maximum(np.asarray(linear, dtype=np.float64) * exposure, 0.0)
    if curve == "clip":
        return np.minimum(c, 1.0)
    luminance = c @ np.array([0.2126, 0.7152, 0.0722])
    mapped = luminance * (1.0 + luminance / REINHARD_WHITE**2) / (1.0 + luminance)
    scale = np.divide(mapped, luminance, out=np.zeros_like(luminance), where=luminance > 0.0)
    c = c * scale[..., None]
    return c / np.maximum(1.0, c.max(axis=-1, keepdims=True))


def to_srgb8(linear: np.ndarray, exposure: float = 1.0, curve: str = "reinhard") -> np.ndarray:
    """Linear RGB to 8-bit sRGB for saving or showing: :func:`tone_map`, then the sRGB encoding."""
    c = tone_map(linear, exposure, curve)
    srgb = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)
    return np.round(srgb * 255.0).astype(np.uint8)


def write_png(path: str, image: np.ndarray) -> None:
    """Write an 8-bit RGB ``(H, W, 3)`` image as PNG (no dependency beyond zlib)."""
    pixels = np.ascontiguousarray(image, dtype=np.uint8)
    if pixels.ndim != 3 or pixels.shape[2] != 3:
        raise ValueError(f"image: expected an (H, W, 3) uint8 array, got shape {pixels.shape}")
    height, width, _ = pixels.shape
    rows = np.concatenate([np.zeros((height, 1), np.uint8), pixels.reshape(height, width * 3)], axis=1)

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)  # 8-bit RGB
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows.tobytes(), 6))
                + chunk(b"IEND", b""))
