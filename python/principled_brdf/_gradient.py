"""The parameters ``eval_grad`` differentiates by: its columns, by name.

The Jacobian's columns are the 13 parameter slots of the C++ table
(``params.hpp``), in its order, with ``base_color`` expanded to
``base_color_r``, ``base_color_g`` and ``base_color_b`` (docs/gradients.md).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from . import _core, _models
from ._models import gradient_names
from ._results import Gradient
from .material import PARAMETERS

if TYPE_CHECKING:
    from ._typing import FloatArray

__all__ = ["GRADIENT_NAMES", "GRADIENT_NAMES_2015", "DIFFERENTIABLE", "gradient_names", "columns", "result"]

# The columns of the default model (the 2012 and 2014 models' 13 slots).
GRADIENT_NAMES = gradient_names(_models.DEFAULT_MODEL)
# Every slot of the table: the 2015 models' columns, and what fitting packs.
GRADIENT_NAMES_2015 = _models.slot_names(_core.PARAM_SLOTS)
# The parameters with derivative columns in the default model, in the table's order,
# which the plots sweep.
DIFFERENTIABLE = {name: info for name, info in PARAMETERS.items()
                  if info.first_slot < _models.RULES[_models.DEFAULT_MODEL].gradient_slots}


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
