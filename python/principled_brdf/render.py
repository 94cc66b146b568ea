"""Lit-sphere pictures computed with the batched kernel.

A unit sphere seen from +z (orthographic), each pixel shaded in its own
tangent frame (normal n, tangent along the sphere's latitude), lit by an
environment and an optional directional key light. The environment is a
latitude-longitude map (:class:`~principled_brdf.environment.Environment`: the
built-in ``"studio"`` and ``"outdoor"``, a ``.exr``/``.hdr`` file or an array),
the simple ``"sky"`` gradient, or any callable ``L(direction)``. Its integral is
estimated per pixel at a rank-1 lattice's points (a Kronecker sequence, randomly
shifted per pixel), so pictures are deterministic and read noise-free: for a map,
each point gives one direction drawn from the BSDF (``pb.sample``) and one drawn
from the map by luminance, combined by multiple importance sampling (Veach 1997,
the power heuristic); for a callable, BSDF samples alone. Returns linear RGB;
:func:`to_srgb8` (a tone curve on luminance, then sRGB) gives a displayable image
and :func:`save_image` writes PNG, OpenEXR (linear) or ``.npy`` (linear) by the
file's extension.
"""

from __future__ import annotations

import os
import struct
import typing
import zlib

import numpy as np

from . import _color, _low_discrepancy, _sphere_paths, _validate
from ._sphere_paths import power_heuristic as _power_heuristic
from ._batch import eval as _eval
from ._batch import eval_pdf as _eval_pdf
from ._batch import random_uniforms as _random_uniforms
from ._batch import sample as _sample
from .environment import MAP_FORMATS as _MAP_FORMATS
from .environment import Environment
from ._model_checks import model_and_mode as _model_and_mode
from ._data_brdf import DataBrdf as _DataBrdf
from ._data_brdf import data_brdf as _data_brdf
from ._data_brdf import is_data as _is_data
from .material import Material
from .material import require_material as _require_material
from .procedural_environments import BUILT_IN as _BUILT_IN
from .procedural_environments import built_in as _built_in

if typing.TYPE_CHECKING:  # (typing.TYPE_CHECKING: this module shows its public names only)
    from collections.abc import Callable
    from typing import Any, Literal, Union

    from numpy.typing import ArrayLike, NDArray

    from ._typing import Float32Array, Float64Array, FloatArray, Model, RealArrayLike
    from .measured import MerlBRDF

    #: L(direction): camera-space directions (..., 3) to RGB radiance (..., 3)
    _Environment = Callable[[Float32Array], ArrayLike]
    #: what the ``environment=`` arguments take: "sky", "studio", "outdoor", a .exr/.hdr path, an (H, W, 3)
    #: map or an Environment, None or False (none), True (the sky), or an L(direction)
    _EnvironmentArg = Union[str, "os.PathLike[str]", bool, None, Environment, NDArray[Any], _Environment]
    _ToneCurve = Literal["filmic", "reinhard", "clip"]

__all__ = ["render_sphere", "render_environment", "sky_environment", "environment_of", "Environment", "ENVIRONMENT_NAMES",
           "DEFAULT_LIGHT_INTENSITY", "sphere_frames", "lattice_uniforms", "tone_map",
           "to_srgb8", "png_bytes", "write_png", "save_image", "IMAGE_FORMATS", "DEFAULT_LIGHT", "DEFAULT_SAMPLES", "DEFAULT_MAP_SAMPLES", "MAX_RESOLUTION",
           "MAX_SAMPLES", "MAX_SAMPLE_WORK",
           "TONE_CURVES", "REINHARD_WHITE", "FILMIC_WHITE"]

DEFAULT_LIGHT = (-0.5, 0.6, 0.75)  # towards the light, camera space (x right, y up, z to the viewer)
# the key light's irradiance by default with the sky or no environment; 0 with any other environment (a map
# or a callable L(direction)), which brings its own lights
DEFAULT_LIGHT_INTENSITY = 3.0
#: The environments named by a string: the simple gradient and the built-in maps.
ENVIRONMENT_NAMES = ("sky",) + tuple(_BUILT_IN)


MAX_RESOLUTION = _validate.MAX_RESOLUTION  # pixels along a side (16384)
DEFAULT_SAMPLES = 64  # sky samples per pixel: with the lattice below, no visible noise on any preset
# map samples per pixel (each one direction from the BSDF and one from the map): a glossy metal under the
# studio's sharp-edged softboxes keeps about 3% RMS noise (64 leave about 9%, a visible grain)
DEFAULT_MAP_SAMPLES = 256
MAX_SAMPLES = 1 << 16  # environment samples per pixel
# Sky samples in all (pixels x samples, every sphere of a batch counted): 16384² pixels at the default
# 64 samples; about half an hour at the 9 M samples/s of two cores.
MAX_SAMPLE_WORK = 1 << 34


def _samples(value: object, pixels: int) -> int:
    """Sky samples per pixel: an integer from 1 to MAX_SAMPLES, and pixels x samples at most MAX_SAMPLE_WORK."""
    samples = _validate.integer_in("samples", value, 1, MAX_SAMPLES, " per pixel")
    if pixels * samples > MAX_SAMPLE_WORK:
        raise ValueError(f"samples: {samples} per pixel over {pixels} pixels is {pixels * samples} samples, beyond "
                         f"the {MAX_SAMPLE_WORK} (2^34) a picture takes; at most {max(MAX_SAMPLE_WORK // pixels, 0)} "
                         "per pixel at this size")
    return samples


def _pixels(material: object, resolution: int) -> int:
    """The pixels a picture of ``material`` shades (every sphere of a batch), where the shapes broadcast."""
    try:
        shape = np.broadcast_shapes(tuple(getattr(material, "shape", ())), (resolution, resolution))
    except (TypeError, ValueError):  # refused where the material is used, naming it
        shape = (resolution, resolution)
    return int(np.prod(shape, dtype=np.int64))


def _light_direction(value: object) -> Float64Array:
    light = _validate.as_real_array("light", value)
    if light.shape != (3,):
        raise ValueError(f"light: expected a 3-vector towards the light, got shape {light.shape}")
    _validate.require_finite("light", light)
    largest = float(np.max(np.abs(light)))
    light = light / largest if largest > 0.0 else light  # no overflow nor underflow in the length
    length = float(np.linalg.norm(light))
    if not 0.0 < length < np.inf:
        raise ValueError(f"light: expected a non-zero direction, got {light.tolist()}")
    return light / length


def sphere_frames(resolution: int) -> tuple[NDArray[np.bool_], Callable[[RealArrayLike], Float32Array]]:
    """Per-pixel local directions for a sphere image.

    Returns ``(inside, to_local)``: ``inside`` is the ``(resolution, resolution)``
    mask of pixels on the sphere, and ``to_local(d)`` maps a camera-space unit
    vector ``d`` (3,) to each pixel's local shading frame, ``(H, W, 3)`` float32
    (pixels off the sphere get the normal, so every vector is valid).
    """
    resolution = _validate.resolution("resolution", resolution)
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

    def to_local(direction: RealArrayLike) -> Float32Array:
        d = np.asarray(direction, dtype=np.float64)
        d = d / np.linalg.norm(d)
        local = np.stack([tangent @ d, bitangent @ d, normal @ d], axis=-1)
        local /= np.linalg.norm(local, axis=-1, keepdims=True)
        return local.astype(np.float32)

    return inside, to_local


def environment_of(value: _EnvironmentArg) -> Environment | _Environment | None:
    """What an ``environment=`` argument names: ``"sky"`` (:func:`sky_environment`) or True;
    ``"studio"`` or ``"outdoor"`` (:mod:`~principled_brdf.procedural_environments`); a path
    to a ``.exr`` or ``.hdr`` latitude-longitude map; an ``(H, W, 3)`` array of linear RGB
    radiance (a map); an :class:`~principled_brdf.environment.Environment`; any callable
    ``L(direction)``; None or False (no environment)."""
    expected = ("expected 'sky', 'studio', 'outdoor', a .exr or .hdr file, an (H, W, 3) map, None or a callable "
                "L(direction)")
    if isinstance(value, Environment):
        return value
    if isinstance(value, str) and value in ENVIRONMENT_NAMES:
        return sky_environment if value == "sky" else _built_in(value)
    if isinstance(value, (str, os.PathLike)):
        path = os.fspath(value)
        if isinstance(path, str) and os.path.splitext(path)[1].lower() in _MAP_FORMATS:
            return Environment.read(path)
        raise ValueError(f"environment: {expected}, got {value!r}")
    if value is None or value is False:
        return None
    if value is True:
        return sky_environment
    if isinstance(value, (np.ndarray, list, tuple)):
        return Environment(value)
    if not callable(value):
        raise TypeError(f"environment: {expected}, got {type(value).__name__}")
    return value


def render_sphere(material: Material | MerlBRDF | Callable[..., Any], resolution: int = 256,
                  light: RealArrayLike = DEFAULT_LIGHT,
                  light_intensity: float | None = None, ambient: float = 0.0, model: Model = "disney2014", *,
                  environment: _EnvironmentArg = "sky", samples: int | None = None,
                  seed: int = 0, energy_compensation: bool = False) -> Float32Array:
    """Linear RGB ``(resolution, resolution, 3)`` image of ``material`` on a sphere.

    ``resolution``: pixels along a side, an integer from 2 to :data:`MAX_RESOLUTION`
    (16384), the rule of every picture of ``render``, ``plot`` and the explorer.
    Lit by ``environment`` (:func:`environment`: ``"sky"``, the default, a simple
    gradient; ``"studio"`` or ``"outdoor"``; a ``.exr``/``.hdr`` file or an ``(H, W, 3)``
    latitude-longitude map; a callable ``L(direction)`` from camera-space directions
    ``(..., 3)`` to RGB radiance, finite and >= 0; None or False: no environment) and
    by a directional key light (``light``: direction towards it in camera space, x right,
    y up, z to the viewer; ``light_intensity``: its irradiance, by default
    :data:`DEFAULT_LIGHT_INTENSITY` with the sky or no environment and 0 with any other
    environment, a map or a callable, which brings its own lights; given, it lights any
    environment). The environment's integral is :func:`render_environment`'s (``samples``
    per pixel, by default :data:`DEFAULT_SAMPLES` for the sky or a callable and
    :data:`DEFAULT_MAP_SAMPLES` for a map, fewer where that would pass the limit; ``seed``; 1 to :data:`MAX_SAMPLES`, and
    pixels x samples at most :data:`MAX_SAMPLE_WORK`). ``ambient``: an optional constant ``ambient * base_color``
    term (an approximation that ignores metallic; 0 by default).

    ``material`` may be uniform or per pixel (leading shape ``(resolution, resolution)``,
    e.g. made by :meth:`Material.mix` with a mask); a leading shape ``S + (1, 1)``
    renders one sphere per material, ``S + (resolution, resolution, 3)``, in one
    kernel call. Background is 0. ``energy_compensation`` as in ``pb.eval``.

    ``model="disney2015"`` renders a solid sphere of the 2015 BSDF and
    ``"disney2015_thin"`` a thin shell: light the material sends into the sphere
    goes on inside, every event drawn by ``pb.sample``, until it leaves
    (docs/rendering-and-plots.md, "Light through the sphere"); the environment
    and the key light light each point only from its side of its tangent plane.

    ``material`` may also be data: measured (a :class:`~principled_brdf.measured.MerlBRDF`,
    its nearest cell) or any callable ``f(wi, wo)`` of shading-frame directions ``(..., 3)``
    to f ``(..., 3)`` in 1/sr (finite and >= 0, NaN where there is no data), a BRDF seen
    from above. Data has no sampler of its own: the environment's integral draws from a
    cosine lobe and, for a map, from the map, weighted by the power heuristic; cells
    without data add nothing. ``model`` and ``energy_compensation`` are a Material's,
    and ``ambient`` needs its base color: 0 and False with data.
    """
    light = _light_direction(light)
    lighting = environment_of(environment)
    is_map = isinstance(lighting, Environment)
    if light_intensity is None:
        light_intensity = DEFAULT_LIGHT_INTENSITY if lighting is None or lighting is sky_environment else 0.0
    if samples is None:  # (for a map, no more than MAX_SAMPLE_WORK allows at this size)
        pixels = _pixels(material, _validate.resolution("resolution", resolution))
        samples = max(1, min(DEFAULT_MAP_SAMPLES, MAX_SAMPLE_WORK // pixels)) if is_map else DEFAULT_SAMPLES
    light_intensity = _validate.real_number("light_intensity", light_intensity, 0.0)
    ambient = _validate.real_number("ambient", ambient, 0.0)
    resolution = _validate.resolution("resolution", resolution)
    _samples(samples, _pixels(material, resolution) if lighting is not None else 0)  # (unused without one)
    if _is_data(material):
        return _data_sphere(_data_brdf("material", material), resolution, light, light_intensity, ambient,
                            lighting, samples, seed, energy_compensation)
    material = typing.cast(Material, material)  # (anything else is refused by the kernels' checks, naming it)
    inside, to_local = sphere_frames(resolution)
    wi, wo = to_local(light), to_local((0.0, 0.0, 1.0))
    radiance = np.float32(light_intensity) * _eval(material, wi, wo, cosine=True, model=model,
                                                   energy_compensation=energy_compensation)
    radiance[..., wi[..., 2] <= 0.0, :] = 0.0  # (the 2015 models: the sphere hides a light behind its tangent plane)
    if ambient > 0.0:
        radiance += np.float32(ambient) * np.asarray(material.base_color, dtype=np.float32)
    if lighting is not None:
        radiance += render_environment(material, resolution, lighting, samples, seed, model,
                                       energy_compensation=energy_compensation).astype(np.float32)
    radiance[..., ~inside, :] = 0.0
    return radiance


def _data_sphere(f: _DataBrdf, resolution: int, light: Float64Array, light_intensity: float, ambient: float,
                 lighting: Environment | _Environment | None, samples: int, seed: int,
                 energy_compensation: bool) -> Float32Array:
    """render_sphere of data f (its docstring), its arguments checked there: the key light's
    f cos θl, and the environment's integral by a cosine lobe's draws and, for a map, the
    map's, with the power heuristic."""
    if energy_compensation:
        raise ValueError("energy_compensation: the compensation is a Material's; data keeps its own energy")
    if ambient > 0.0:
        raise ValueError("ambient: the ambient term is ambient x a Material's base_color; data has none (use 0)")
    is_map = isinstance(lighting, Environment)
    pixels = resolution * resolution
    inside, to_local = sphere_frames(resolution)
    wo = to_local((0.0, 0.0, 1.0)).astype(np.float64)
    frame = [to_local(e).astype(np.float64) for e in np.eye(3)]  # frame[k][..., j]: axis j's camera component k

    def value(wi: Float64Array) -> Float64Array:  # f |cos θl| above the surface, 0 below and where no data
        fc = np.nan_to_num(f(wi, np.broadcast_to(wo, wi.shape)), nan=0.0) * np.maximum(wi[..., 2:3], 0.0)
        return np.where(wi[..., 2:3] > 0.0, fc, 0.0)

    wi = to_local(light).astype(np.float64)
    radiance = light_intensity * value(wi)
    chunk = max(1, (1 << 20) // pixels)
    for start in range(0, samples if lighting is not None else 0, chunk):
        count = min(chunk, samples - start)
        points = lattice_uniforms(count, inside.shape, seed, first=start).astype(np.float64)
        # the cosine lobe's strategy: wi = (√u1 cos 2πu2, √u1 sin 2πu2, √(1 - u1)), pdf cos θl / π
        radius, angle = np.sqrt(points[..., 0]), 2.0 * np.pi * points[..., 1]
        local = np.stack([radius * np.cos(angle), radius * np.sin(angle), np.sqrt(1.0 - points[..., 0])], axis=-1)
        cosine_pdf = local[..., 2] / np.pi
        camera = np.stack([sum(local[..., j] * frame[k][..., j] for j in range(3)) for k in range(3)], axis=-1)
        if is_map:
            environment_map = typing.cast(Environment, lighting)
            light_radiance, light_pdf = environment_map._lookup_unchecked(camera.astype(np.float32))
            weight = _power_heuristic(cosine_pdf, light_pdf)
        else:
            light_radiance = _sphere_paths.callable_radiance(typing.cast("Callable[..., Any]", lighting),
                                                             camera.astype(np.float32))
            weight = np.ones_like(cosine_pdf)
        estimate = np.divide(weight, cosine_pdf, out=np.zeros_like(weight), where=cosine_pdf > 0.0)
        radiance += (value(local) * light_radiance * estimate[..., None]).sum(axis=0) / samples
        if is_map:
            towards, light_pdf, light_radiance = environment_map._sample_unchecked(points[..., 1:])
            towards = towards.astype(np.float64)
            local = towards[..., 0, None] * frame[0] + towards[..., 1, None] * frame[1] + towards[..., 2, None] * frame[2]
            local /= np.linalg.norm(local, axis=-1, keepdims=True)
            weight = _power_heuristic(light_pdf, np.maximum(local[..., 2], 0.0) / np.pi)
            estimate = np.divide(weight, light_pdf, out=np.zeros_like(weight), where=light_pdf > 0.0)
            radiance += (value(local) * light_radiance * estimate[..., None]).sum(axis=0) / samples
    radiance[~inside] = 0.0
    return radiance.astype(np.float32)


def sky_environment(direction: RealArrayLike, zenith: RealArrayLike = (0.65, 0.75, 0.9),
                    horizon: RealArrayLike = (1.0, 1.0, 1.0),
                    ground: RealArrayLike = (0.12, 0.11, 0.1)) -> Float32Array:
    """A simple sky/ground gradient ``L(w)`` (RGB radiance, float32) for camera-space directions ``(..., 3)``.

    y is up (as in :mod:`principled_brdf.render`): above the horizon the sky
    goes from ``horizon`` to ``zenith`` as ``sqrt(y)``; below it is ``ground``,
    blended over a narrow band around the horizon. The default colors are
    nearly neutral, so that a metal shows its own color, and the ground is
    dark, so that its curvature shows.
    """
    up = np.asarray(direction, dtype=np.float32)[..., 1]
    zenith, horizon, ground = (np.asarray(c, dtype=np.float32) for c in (zenith, horizon, ground))
    blend = np.clip(up * np.float32(25.0) + np.float32(0.5), 0.0, 1.0)  # 0 to 1 over |y| < 0.02
    height = np.sqrt(np.clip(up, 0.0, 1.0))
    # ground + blend (horizon - ground) + blend height (zenith - horizon), as one small matrix product
    basis = np.stack([np.ones_like(up), blend, blend * height], axis=-1)
    return basis @ np.stack([ground, horizon - ground, zenith - horizon])


def lattice_uniforms(count: int, shape: tuple[int, ...], seed: int = 0, first: int = 0) -> Float32Array:
    """``(count,) + shape + (3,)`` float32 uniforms: sample ``k`` of each element is the
    Kronecker point ``frac(k α + s)`` of Roberts' generalised golden ratio in 3-d
    (``α_j = φ3^-(j+1)``, ``φ3`` the real root of ``x⁴ = x + 1``), ``s`` the element's random
    shift (Cranley-Patterson rotation, from ``seed``), for ``k = first .. first + count - 1``.
    Every element gets a well-spread set of points, and neighbouring elements uncorrelated ones."""
    elements = int(np.prod(shape, dtype=np.int64))
    shift = _random_uniforms(seed, elements).reshape(tuple(shape) + (3,))
    index = np.arange(first, first + count, dtype=np.float64).reshape((count,) + (1,) * len(shape))
    return _low_discrepancy.shifted_points(index, shift)


def render_environment(material: Material | MerlBRDF | Callable[..., Any], resolution: int = 256,
                       environment: _EnvironmentArg = "sky",
                       samples: int = DEFAULT_SAMPLES, seed: int = 0, model: Model = "disney2014", *,
                       energy_compensation: bool = False) -> Float64Array:
    """Linear RGB ``(resolution, resolution, 3)`` (or ``S + (resolution, resolution, 3)`` as
    :func:`render_sphere`): the sphere lit by ``environment`` alone (as :func:`environment_of`
    reads it: ``"sky"``, the default, :func:`sky_environment`; None or False, no
    environment, gives a black picture), per pixel ``∫ f L(wi) |cos θl| dωi``.

    The estimate uses ``samples`` points of :func:`lattice_uniforms` per pixel, shifted per
    pixel from ``seed``: deterministic, and far less noisy than independent samples. For a
    latitude-longitude map each point draws one direction from the BSDF (``pb.sample``) and
    one from the map in proportion to its luminance (``Environment.sample``), weighted by
    the power heuristic of multiple importance sampling (Veach 1997, eq. 9.13), so that
    small bright lights and sharp lobes both converge; for a callable ``L(direction)``,
    the BSDF samples alone. ``samples``: 1 to :data:`MAX_SAMPLES`, and pixels (every sphere
    of a batch) x samples at most :data:`MAX_SAMPLE_WORK`. ``energy_compensation`` as in
    ``pb.sample``. ``material`` may also be data, as :func:`render_sphere` takes it (the
    cosine lobe's and the map's draws)."""
    lighting = environment_of(environment)
    resolution = _validate.resolution("resolution", resolution)
    samples = _samples(samples, _pixels(material, resolution))
    if _is_data(material):
        return _data_sphere(_data_brdf("material", material), resolution, np.array([0.0, 0.0, 1.0]), 0.0, 0.0,
                            lighting, samples, seed, energy_compensation).astype(np.float64)
    material = typing.cast(Material, material)  # (anything else is refused by the kernels' checks, naming it)
    if lighting is None:  # no environment, no light: a black picture, of the checked arguments' shape
        _model_and_mode(_require_material("material", material), model, "radiance", energy_compensation)
        shape = _validate.broadcast_leading(material=material.shape, resolution=(resolution, resolution))
        return np.zeros(shape + (3,))
    inside, to_local = sphere_frames(resolution)
    wo = to_local((0.0, 0.0, 1.0))
    # to_local(e_k)[..., j] = frame_j[k]: the tangent, bitangent and normal (j = 0, 1, 2) in camera space
    frame = [to_local(e) for e in np.eye(3)]  # frame[k][..., j]

    def to_camera(local: FloatArray) -> Float32Array:
        return np.stack([local[..., 0] * frame[k][..., 0] + local[..., 1] * frame[k][..., 1]
                         + local[..., 2] * frame[k][..., 2] for k in range(3)], axis=-1)

    def to_shading(direction: FloatArray) -> Float32Array:
        local = sum(direction[..., k, None] * frame[k] for k in range(3))
        return (local / np.linalg.norm(local, axis=-1, keepdims=True)).astype(np.float32)

    shape = np.broadcast_shapes(material.shape, inside.shape)
    elements = int(np.prod(shape, dtype=np.int64))
    is_map = isinstance(lighting, Environment)
    # the 2015 models send light into the sphere: such paths go on inside (_sphere_paths), and the
    # environment lights a point only from above its tangent plane (the sphere hides the rest)
    normals = np.broadcast_to(to_camera(np.array([0.0, 0.0, 1.0])), shape + (3,)).reshape(-1, 3)

    def material_at(element: NDArray[np.intp]) -> Material:
        if material.shape == ():
            return material
        index = np.unravel_index(element, shape)[len(shape) - len(material.shape):]
        return material[tuple(np.where(np.asarray(material.shape)[k] == 1, 0, i) for k, i in enumerate(index))]
    chunk = max(1, (1 << 20) // (elements * (2 if is_map else 1)))
    total = np.zeros(shape + (3,))
    # the points depend on the pixel alone: a sphere looks the same rendered alone or in a batch
    spheres = (1,) * (len(shape) - inside.ndim)
    options: dict[str, Any] = dict(model=model, energy_compensation=energy_compensation)
    for start in range(0, samples, chunk):
        count = min(chunk, samples - start)
        points = lattice_uniforms(count, inside.shape, seed, first=start)
        u = points.reshape((count,) + spheres + inside.shape + (3,))
        drawn = _sample(material, wo, u=u, **options)
        direction = to_camera(drawn.wi)
        above = (drawn.wi[..., 2] > 0.0)[..., None]
        entering = np.nonzero(~above[..., 0] & (drawn.pdf > 0.0))
        if len(entering[0]):
            element = np.ravel_multi_index(entering[1:], shape)
            # a path is named by its sample and its pixel (not its sphere: a batch looks like its spheres alone)
            pixel = np.ravel_multi_index(entering[-2:], inside.shape).astype(np.uint64)
            paths = _sphere_paths.through_the_sphere(material_at, element, normals[element], direction[entering],
                                                     drawn.weight[entering], lighting, model,
                                                     start + entering[0], pixel, seed, energy_compensation)
            np.add.at(total.reshape(-1, 3), element, paths)
        if not is_map:
            radiance = _sphere_paths.callable_radiance(lighting, direction)
            total += np.where(above, drawn.weight * radiance, 0.0).sum(axis=0, dtype=np.float64)
            continue
        environment_map = typing.cast(Environment, lighting)
        radiance, light_pdf = environment_map._lookup_unchecked(direction)
        weight = np.where(above, drawn.weight * _power_heuristic(drawn.pdf, light_pdf)[..., None], 0.0)
        total += (weight * radiance).sum(axis=0, dtype=np.float64)
        # the map's strategy: directions per pixel (shared by the spheres of a batch), from two of the point's axes
        towards, light_pdf, radiance = environment_map._sample_unchecked(points[..., 1:])
        local = to_shading(towards).reshape((count,) + spheres + inside.shape + (3,))
        value, bsdf_pdf = _eval_pdf(material, local, wo, cosine=True, **options)
        value = np.where(local[..., 2:3] > 0.0, value, 0.0)
        light_pdf = light_pdf.reshape((count,) + spheres + inside.shape)
        # f |cos| L / pdf_light x pdf_light² / (pdf_light² + pdf_bsdf²)
        heuristic = _power_heuristic(light_pdf, bsdf_pdf)
        weight = np.divide(heuristic, light_pdf, out=np.zeros_like(heuristic), where=light_pdf > 0.0)
        total += (value * weight[..., None] * radiance.reshape(local.shape)).sum(axis=0, dtype=np.float64)
    total /= samples
    total[..., ~inside, :] = 0.0
    return total


TONE_CURVES = ("filmic", "reinhard", "clip")
REINHARD_WHITE = 4.0  # the luminance the "reinhard" curve maps to display white
FILMIC_WHITE = (0.56 + (0.56**2 + 4 * 0.08 * 0.14) ** 0.5) / 0.16  # 7.24: the "filmic" curve reaches 1 (0.08 x² - 0.56 x - 0.14 = 0)


def _filmic(luminance: Float64Array) -> Float64Array:
    # Narkowicz's 2015 fit of the ACES reference rendering transform, y = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14):
    # a toe, midtones near the identity (0.18 -> 0.27, 1 -> 0.80) and a shoulder reaching 1 at FILMIC_WHITE
    mapped = luminance * (2.51 * luminance + 0.03) / (luminance * (2.43 * luminance + 0.59) + 0.14)
    return np.where(luminance < FILMIC_WHITE, mapped, 1.0)


def _reinhard(luminance: Float64Array) -> Float64Array:
    return luminance * (1.0 + luminance / REINHARD_WHITE**2) / (1.0 + luminance)


def tone_map(linear: RealArrayLike, exposure: float = 1.0, curve: _ToneCurve = "filmic") -> Float64Array:
    """Scene-referred linear RGB ``(..., 3)`` to display-referred linear RGB in [0, 1].

    The curve maps each pixel's luminance ``Y`` (Rec. 709 weights) to ``Y'``;
    the pixel's color is scaled by ``Y'/Y`` and, where a channel would still
    exceed 1, divided by that channel, so a gold highlight stays gold and a
    white material keeps its shading instead of clipping flat. ``"filmic"``
    (default): the ACES fit of Narkowicz 2015, white at ``Y`` =
    :data:`FILMIC_WHITE`; ``"reinhard"``: the extended Reinhard curve ``Y (1 +
    Y / W²) / (1 + Y)``, white ``W`` = :data:`REINHARD_WHITE` (darker
    midtones); ``"clip"``: each channel clipped to [0, 1]. All after
    multiplying by ``exposure``. Negative values count as 0 and +inf as white;
    NaN is a ValueError naming the pixel."""
    if curve not in TONE_CURVES:
        raise ValueError(f"curve: expected one of {', '.join(TONE_CURVES)}, got {curve!r}")
    exposure = _validate.real_number("exposure", exposure, 0.0)
    c = _validate.as_real_array("linear", linear)
    if c.ndim == 0 or c.shape[-1] != 3:
        raise ValueError(f"linear: expected RGB values of shape (..., 3), got {c.shape}")
    if np.isnan(c).any():
        i = _validate.first_true(np.isnan(c))
        raise ValueError(f"{_validate.element_name('linear', i, c.shape)}: nan is not a color")
    # far above any white point, and small enough that the curves' squares stay finite
    c = np.clip(c * exposure, 0.0, 1e30)
    if curve == "clip":
        return np.minimum(c, 1.0)
    luminance = c @ np.array(_color.LUMINANCE_WEIGHTS)
    mapped = _filmic(luminance) if curve == "filmic" else _reinhard(luminance)
    scale = np.divide(mapped, luminance, out=np.zeros_like(luminance), where=luminance > 0.0)
    c = c * scale[..., None]
    return c / np.maximum(1.0, c.max(axis=-1, keepdims=True))


def to_srgb8(linear: RealArrayLike, exposure: float = 1.0, curve: _ToneCurve = "filmic") -> NDArray[np.uint8]:
    """Linear RGB to 8-bit sRGB for saving or showing: :func:`tone_map`, then the sRGB encoding."""
    return np.round(_color.srgb_encode(tone_map(linear, exposure, curve)) * 255.0).astype(np.uint8)


def png_bytes(image: RealArrayLike) -> bytes:
    """An 8-bit ``(H, W, 3)`` RGB or ``(H, W, 4)`` RGBA image as PNG bytes (no dependency beyond zlib)."""
    pixels = np.ascontiguousarray(image, dtype=np.uint8)
    if pixels.ndim != 3 or pixels.shape[2] not in (3, 4):
        raise ValueError(f"image: expected an (H, W, 3) or (H, W, 4) uint8 array, got shape {pixels.shape}")
    height, width, channels = pixels.shape
    rows = np.concatenate([np.zeros((height, 1), np.uint8), pixels.reshape(height, width * channels)], axis=1)

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 6 if channels == 4 else 2, 0, 0, 0)  # 8-bit RGBA or RGB
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows.tobytes(), 6))
            + chunk(b"IEND", b""))


def write_png(path: str | os.PathLike[str], image: RealArrayLike) -> None:
    """Write an 8-bit RGB ``(H, W, 3)`` (or RGBA) image as PNG (:func:`png_bytes`)."""
    data = png_bytes(image)
    with open(path, "wb") as f:
        f.write(data)


#: The formats :func:`save_image` writes, by extension.
IMAGE_FORMATS = {".png": "8-bit sRGB after tone_map", ".exr": "linear float32 RGB (OpenEXR, `pip install OpenEXR`)",
                 ".npy": "linear float32 RGB (numpy)"}


def save_image(path: str | os.PathLike[str], linear: RealArrayLike, exposure: float = 1.0,
               curve: _ToneCurve = "filmic") -> str:
    """Write a linear RGB ``(H, W, 3)`` image in the format of ``path``'s extension
    (:data:`IMAGE_FORMATS`): ``.png`` tone-mapped and sRGB-encoded (:func:`to_srgb8`),
    ``.exr`` and ``.npy`` the linear values times ``exposure`` (high dynamic range kept).
    Returns the path. Another extension is a ValueError naming it."""
    import os

    path = os.fspath(path)
    extension = os.path.splitext(path)[1].lower()
    if extension not in IMAGE_FORMATS:
        raise ValueError(f"path: cannot write {extension or 'a file without an extension'!r} images; "
                         f"supported: {', '.join(IMAGE_FORMATS)}")
    image = np.asarray(linear, dtype=np.float64)
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"linear: expected an (H, W, 3) RGB image, got shape {image.shape}")
    exposure = _validate.real_number("exposure", exposure, 0.0)
    if extension == ".png":
        write_png(path, to_srgb8(image, exposure, curve))
    elif extension == ".npy":
        np.save(path, (image * exposure).astype(np.float32))
    else:
        try:
            import OpenEXR
        except ImportError:
            raise ImportError("writing .exr needs the OpenEXR package: pip install OpenEXR") from None
        pixels = np.ascontiguousarray(image * exposure, dtype=np.float32)
        header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
        with OpenEXR.File(header, {"RGB": pixels}) as exr:
            exr.write(path)
    return path
