"""What ``eval_grad`` returns, and the parameters it differentiates by.

The Jacobian's columns are the 13 parameter slots of the C++ table
(``params.hpp``), in its order, with ``base_color`` expanded to
``base_color_r``, ``base_color_g`` and ``base_color_b`` (docs/gradients.md).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from . import _core
from ._validate import BSDF_MODELS
from .material import PARAMETERS

if TYPE_CHECKING:
    from ._typing import FloatArray

__all__ = ["Gradient", "GRADIENT_NAMES", "DIFFERENTIABLE"]


# The parameters with derivative columns, in the table's order: the 2012 and
# 2014 models' (the 2015 models' own parameters have none yet), which fitting
# adjusts.
DIFFERENTIABLE = {name: info for name, info in PARAMETERS.items() if info.first_slot < _core.GRADIENT_SLOTS}


def _slot_names() -> tuple[str, ...]:
    names: list[str] = []
    for info in DIFFERENTIABLE.values():
        names += [f"{info.name}_{c}" for c in "rgb"] if info.slots == 3 else [info.name]
    return tuple(names)


GRADIENT_NAMES = _slot_names()
# the 2015 models' columns: every slot of the table
GRADIENT_NAMES_2015 = GRADIENT_NAMES + tuple(name for name in PARAMETERS if name not in DIFFERENTIABLE)


def gradient_names(model: object) -> tuple[str, ...]:
    """The columns of ``model``'s Jacobian in the parameters (``model`` checked by the caller)."""
    return GRADIENT_NAMES_2015 if model in BSDF_MODELS else GRADIENT_NAMES


class Gradient(NamedTuple):
    """f and its partial derivatives: ``jacobian[..., c, k] = ∂f_c / ∂names[k]``."""

    value: FloatArray  # (..., 3) as eval returns it
    jacobian: FloatArray  # (..., 3, P)
    names: tuple[str, ...]  # the P parameters in the table's order, then any direction components


def columns(wrt: object, argument: str = "wrt", names: tuple[str, ...] = GRADIENT_NAMES) -> list[int]:
    """The slot indices for ``wrt``: None (all of ``names``, the model's), a name or a
    sequence of names; ``base_color`` stands for its three channels. Kept in the
    table's order; errors name ``argument``."""
    if wrt is None:
        return list(range(len(names)))
    requested = [wrt] if isinstance(wrt, str) else list(wrt) if isinstance(wrt, (list, tuple)) else None
    if requested is None or not requested:
        raise TypeError(f"{argument}: expected None, a parameter name or a non-empty list of names, got {wrt!r}")
    wanted = set()
    for name in requested:
        if not isinstance(name, str):
            raise TypeError(f"{argument}: expected parameter names, got {name!r}")
        expanded = [f"{name}_{c}" for c in "rgb"] if name == "base_color" else [name]
        for slot_name in expanded:
            if slot_name not in names:
                raise ValueError(f"{argument}: unknown parameter {name!r}; expected one of {', '.join(names)} "
                                 "or base_color")
            wanted.add(names.index(slot_name))
    return sorted(wanted)


def result(value: FloatArray, jacobian: FloatArray, wrt_columns: list[int],
           names: tuple[str, ...] = GRADIENT_NAMES) -> Gradient:
    """The Gradient of full Jacobians (a column each of ``names``), keeping ``wrt_columns``."""
    if len(wrt_columns) != len(names):
        jacobian = np.ascontiguousarray(jacobian[..., wrt_columns])
    return Gradient(value, jacobian, tuple(names[k] for k in wrt_columns))
