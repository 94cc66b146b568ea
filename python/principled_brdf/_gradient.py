"""What ``eval_grad`` returns, and the parameters it differentiates by.

The Jacobian's columns are the 13 parameter slots of the C++ table
(``params.hpp``), in its order, with ``base_color`` expanded to
``base_color_r``, ``base_color_g`` and ``base_color_b`` (docs/gradients.md).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from .material import PARAMETERS

if TYPE_CHECKING:
    from ._typing import FloatArray

__all__ = ["Gradient", "GRADIENT_NAMES"]


def _slot_names() -> tuple[str, ...]:
    names: list[str] = []
    for info in PARAMETERS.values():
        names += [f"{info.name}_{c}" for c in "rgb"] if info.slots == 3 else [info.name]
    return tuple(names)


GRADIENT_NAMES = _slot_names()


class Gradient(NamedTuple):
    """f and its partial derivatives: ``jacobian[..., c, k] = ∂f_c / ∂names[k]``."""

    value: FloatArray  # (..., 3) as eval returns it
    jacobian: FloatArray  # (..., 3, P)
    names: tuple[str, ...]  # the P parameters in the table's order, then any direction components


def columns(wrt: object, argument: str = "wrt") -> list[int]:
    """The slot indices for ``wrt``: None (all 13), a name or a sequence of names;
    ``base_color`` stands for its three channels. Kept in the table's order;
    errors name ``argument``."""
    if wrt is None:
        return list(range(len(GRADIENT_NAMES)))
    requested = [wrt] if isinstance(wrt, str) else list(wrt) if isinstance(wrt, (list, tuple)) else None
    if requested is None or not requested:
        raise TypeError(f"{argument}: expected None, a parameter name or a non-empty list of names, got {wrt!r}")
    wanted = set()
    for name in requested:
        if not isinstance(name, str):
            raise TypeError(f"{argument}: expected parameter names, got {name!r}")
        expanded = [f"{name}_{c}" for c in "rgb"] if name == "base_color" else [name]
        for slot_name in expanded:
            if slot_name not in GRADIENT_NAMES:
                raise ValueError(f"{argument}: unknown parameter {name!r}; expected one of {', '.join(GRADIENT_NAMES)} "
                                 "or base_color")
            wanted.add(GRADIENT_NAMES.index(slot_name))
    return sorted(wanted)


def result(value: FloatArray, jacobian: FloatArray, wrt_columns: list[int]) -> Gradient:
    """The Gradient of full 13-column Jacobians, keeping ``wrt_columns``."""
    if len(wrt_columns) != len(GRADIENT_NAMES):
        jacobian = np.ascontiguousarray(jacobian[..., wrt_columns])
    return Gradient(value, jacobian, tuple(GRADIENT_NAMES[k] for k in wrt_columns))
