"""The float64 reference (docs/model.md, "The model"): slow, plain, and the yardstick for everything else.

The same calls as the SIMD ones, with their options where they apply (model,
cosine, layout, specular_sampler, mode); threads, out, check and isa do not:
the reference is one float64 loop, and always checks its directions.
"""

from __future__ import annotations

import typing

from . import _derivatives
from ._float64 import eval, eval_lobes, lobe_probabilities, pdf, sample
from ._results import Gradient, Lobes, Sample

if typing.TYPE_CHECKING:  # (typing.TYPE_CHECKING: this module shows its public names only)
    from ._typing import Layout, Mode, Model, RealArrayLike
    from .material import Material

__all__ = ["eval", "eval_lobes", "eval_grad", "Lobes", "Gradient", "sample", "pdf", "lobe_probabilities", "Sample"]


def eval_grad(material: Material, wi: RealArrayLike, wo: RealArrayLike, *,
              wrt: str | list[str] | tuple[str, ...] | None = None, model: Model = "disney2014",
              cosine: bool = False, layout: Layout = "aos", energy_compensation: bool = False,
              mode: Mode = "radiance") -> Gradient:
    """f in float64 and its Jacobian in the material's parameters (docs/gradients.md):
    ``value`` ``(..., 3)`` as :func:`eval`, ``jacobian`` ``(..., 3, P)`` with
    ``jacobian[..., c, k] = ∂f_c/∂names[k]``, ``names`` the P parameters ``wrt``
    selects (default all 13, 16 for ``model="disney2015"``, ``base_color`` as three channels). A uniform
    parameter still gets a per-element derivative. ``layout="soa"``: ``(3, ...)``
    and ``(3, P, ...)``. ``energy_compensation=True`` raises NotImplementedError.
    ``wrt`` may also name ``"wi"`` and ``"wo"`` (three columns each, after the
    parameters'; docs/gradients.md, "Derivatives in the directions")."""
    return _derivatives.reference_eval_grad(material, wi, wo, wrt=wrt, model=model, cosine=cosine, layout=layout,
                                            energy_compensation=energy_compensation, mode=mode)
