"""Directional albedo by importance sampling: the fraction of light arriving
from everywhere that leaves towards wo, ∫ f(wi, wo) |cos θl| dωi, per lobe and
in total, with its Monte Carlo standard error; for the 2015 models also split
into the light from wo's side (reflectance) and through the surface
(transmittance)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from . import _models
from ._batch import random_uniforms, sample
from ._results import Albedo, Lobes
from ._validate import (as_real_array, broadcast_leading, element_name, first_true, integer_in, require_in_domain,
                        seed_value)
from .material import PARAMETERS, Material, require_material

if TYPE_CHECKING:
    from typing import Any, SupportsIndex

    from ._typing import Float64Array, Mode, Model, RealArrayLike, SpecularSampler

__all__ = ["Albedo", "albedo"]

# The most samples per albedo: beyond, one cos θo alone needs gigabytes.
MAX_SAMPLES = 1 << 26
# Elements per kernel call: bounds the memory of one chunk (about 150 bytes each).
_CHUNK_ELEMENTS = 1 << 22


def _with_sample_axis(material: Material, leading: tuple[int, ...]) -> Material:
    """The material broadcast to ``leading`` with a trailing axis of length 1 for the samples."""
    params: dict[str, Any] = {}  # Material's keywords
    for name, info in PARAMETERS.items():
        value = getattr(material, name)
        if info.slots == 3:
            params[name] = value if value.shape == (3,) else np.broadcast_to(value, leading + (3,))[..., None, :]
        else:
            params[name] = value if value.ndim == 0 else np.broadcast_to(value, leading)[..., None]
    return Material(**params)


def albedo(material: Material, cos_theta_o: RealArrayLike, *, samples: SupportsIndex = 1 << 16,
           seed: SupportsIndex = 0, model: Model = "disney2014", specular_sampler: SpecularSampler = "visible",
           threads: SupportsIndex | None = None, energy_compensation: bool = False,
           mode: Mode = "radiance") -> Albedo:
    """Directional albedo ``E(wo) = ∫ f(wi, wo) |cos θl| dωi`` for ``wo = (sin θo, 0, cos θo)``.

    ``cos_theta_o`` in (0, 1], any shape, broadcast with the material's
    leading shape; for the 2015 models in [-1, 1] without 0, a negative one
    a view from inside the solid. Each albedo is the mean of ``samples``
    importance-sampled weights (``pb.sample``, seeded, so the call is
    reproducible); errors are the standard errors of those means.
    ``reflectance`` and ``transmittance`` split the total by the side ``wi``
    lies on (wo's, or the other one). ``energy_compensation`` and ``mode`` as
    in ``pb.sample``; in importance mode the albedo of a clear dielectric
    (``spec_trans=1``, white) is at most 1 from either side.
    """
    require_material("material", material)
    cos_o = as_real_array("cos_theta_o", cos_theta_o)
    whole_sphere = _models.is_whole_sphere(model)
    require_in_domain("cos_theta_o", cos_o, -1.0 if whole_sphere else 0.0, 1.0)
    if np.any(cos_o == 0.0):  # wo in the surface
        i = first_true(cos_o == 0.0)
        domain = "[-1, 1] without 0" if whole_sphere else "(0, 1]"
        raise ValueError(f"{element_name('cos_theta_o', i, cos_o.shape)}: {float(cos_o.ravel()[i])!r} is outside its "
                         f"domain {domain}")
    count = integer_in("samples", samples, 2, MAX_SAMPLES)
    seed = seed_value(seed)
    leading = broadcast_leading(cos_theta_o=cos_o.shape, material=material.shape)
    expanded = _with_sample_axis(material, leading)
    cos_flat = np.broadcast_to(cos_o, leading).reshape(-1)
    m = cos_flat.size

    sums = np.zeros((3 + len(_models.LOBE_NAMES), m, 3))  # total, the lobes, reflectance, transmittance
    squares = np.zeros_like(sums)
    per_chunk = max(1, _CHUNK_ELEMENTS // count)
    flat_material = _flatten(expanded, leading)
    for start in range(0, m, per_chunk):
        stop = min(m, start + per_chunk)
        cos = cos_flat[start:stop]
        wo = np.stack([np.sqrt(1.0 - cos * cos), np.zeros_like(cos), cos], axis=-1).astype(np.float32)
        wo = np.broadcast_to(wo[:, None, :], (stop - start, count, 3))
        chunk_material = _slice(flat_material, start, stop)
        u = random_uniforms(seed, (stop - start) * count, first=start * count).reshape(stop - start, count, 3)
        # one kernel pass: the weight and each lobe's share of it
        drawn, shares = sample(chunk_material, wo, u=u, model=model, specular_sampler=specular_sampler,
                               threads=threads, check=False, with_lobes=True,
                               energy_compensation=energy_compensation, mode=mode)
        through = (drawn.wi[..., 2] * wo[..., 2] < 0)[..., None]
        split = (np.where(through, 0.0, drawn.weight), np.where(through, drawn.weight, 0.0))
        for k, weight in enumerate((drawn.weight, *shares, *split)):
            weight = weight.astype(np.float64)
            sums[k, start:stop] = weight.sum(axis=1)
            squares[k, start:stop] = np.square(weight).sum(axis=1)

    mean = sums / count
    variance = np.maximum(squares / count - mean * mean, 0.0) * count / (count - 1)
    error = np.sqrt(variance / count)
    shape = leading + (3,)
    lobes = range(1, 1 + len(_models.LOBE_NAMES))
    return Albedo(
        total=mean[0].reshape(shape),
        lobes=Lobes(*(mean[k].reshape(shape) for k in lobes)),
        total_error=error[0].reshape(shape),
        lobe_errors=Lobes(*(error[k].reshape(shape) for k in lobes)),
        reflectance=mean[-2].reshape(shape),
        transmittance=mean[-1].reshape(shape),
    )


def _flatten(material: Material, leading: tuple[int, ...]) -> dict[str, Float64Array]:
    """Per-element parameters of a sample-axis material as flat (M, 1[, 3]) arrays; uniform ones as they are."""
    flat: dict[str, Float64Array] = {}
    for name, info in PARAMETERS.items():
        value = getattr(material, name)
        uniform = value.shape == ((3,) if info.slots == 3 else ())
        flat[name] = value if uniform else value.reshape((-1, 1, 3) if info.slots == 3 else (-1, 1))
    return flat


def _slice(flat: dict[str, Float64Array], start: int, stop: int) -> Material:
    values: dict[str, Any] = {name: (v if v.ndim <= 1 and (v.shape in ((), (3,))) else v[start:stop])
                              for name, v in flat.items()}
    return Material(**values)
