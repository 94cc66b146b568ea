"""The float64 reference (SPEC §3): slow, plain, and the yardstick for everything else."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from . import _core
from ._validate import broadcast_leading, directions, model_index
from .material import Material

__all__ = ["eval", "eval_lobes", "Lobes"]


class Lobes(NamedTuple):
    """The four lobes of SPEC §3, each ``(..., 3)``, already weighted as they enter the sum."""

    diffuse: np.ndarray  # diffuse + subsurface, times (1 - metallic)
    sheen: np.ndarray  # times (1 - metallic)
    specular: np.ndarray  # primary GTR2 lobe
    clearcoat: np.ndarray  # grey

    def total(self) -> np.ndarray:
        return self.diffuse + self.sheen + self.specular + self.clearcoat


def _prepare(material, wi, wo, model):
    if not isinstance(material, Material):
        raise TypeError(f"material: expected a principled_brdf.Material, got {type(material).__name__}")
    model_id = model_index(model)
    wi = directions("wi", wi)
    wo = directions("wo", wo)
    shape = broadcast_leading(wi=wi.shape[:-1], wo=wo.shape[:-1], material=material.shape)
    rows = lambda w: np.ascontiguousarray(np.broadcast_to(w, shape + (3,)).reshape(-1, 3))  # noqa: E731
    return shape, rows(wi), rows(wo), material.packed(shape), model_id


def eval(material: Material, wi, wo, *, model: str = "disney2014", cosine: bool = False) -> np.ndarray:
    """f(wi, wo) in 1/sr as float64 ``(..., 3)``; times cos θl if ``cosine``."""
    shape, wi_rows, wo_rows, params, model_id = _prepare(material, wi, wo, model)
    f = _core.reference_eval(wi_rows, wo_rows, params, model_id, False)
    if cosine:
        f *= np.maximum(wi_rows[:, 2:3], 0.0)
    return f.reshape(shape + (3,))


def eval_lobes(material: Material, wi, wo, *, model: str = "disney2014", cosine: bool = False) -> Lobes:
    """The four lobes as a :class:`Lobes` of float64 ``(..., 3)`` arrays."""
    shape, wi_rows, wo_rows, params, model_id = _prepare(material, wi, wo, model)
    lobes = _core.reference_eval(wi_rows, wo_rows, params, model_id, True)
    if cosine:
        lobes *= np.maximum(wi_rows[:, None, 2:3], 0.0)
    return Lobes(*(lobes[:, k, :].reshape(shape + (3,)) for k in range(4)))
