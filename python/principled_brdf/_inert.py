"""Fitted parameters that end without effect go back to their start (docs/fitting.md#what-the-fit-holds).

At ``metallic = 1`` the diffuse, subsurface and sheen lobes are weighted by
``1 - metallic = 0`` and ``specular``, ``specular_tint`` drop out of Cspec0;
at ``sheen = 0`` ``sheen_tint`` does nothing, at ``clearcoat = 0``
``clearcoat_gloss``. Whatever values such parameters took on the way are
noise (a metal that ends with ``sheen = 1`` has no sheen), so they are set back
to their start when that leaves f unchanged to the last bit at every sample:
the fitted material, its cost and residuals are the same, only its reading is.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ._gradient import GRADIENT_NAMES
from .material import PARAMETERS

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence

    from ._typing import Float64Array

    # f and ∂f/∂slot at the slot values (13,) over one problem's samples: (n, 3), (n, 3, 13)
    Evaluate = Callable[[Float64Array], tuple[Float64Array, Float64Array]]
    Value = Callable[[Float64Array], Float64Array]


def _whole_parameters(slots: Sequence[int]) -> list[list[int]]:
    """The fitted slots grouped by parameter (base_color's three together)."""
    groups = []
    for info in PARAMETERS.values():
        group = [k for k in range(info.first_slot, info.first_slot + info.slots) if k in slots]
        if group:
            groups.append(group)
    return groups


def reset(values: Float64Array, start: Float64Array, slots: Sequence[int], evaluate: Evaluate,
          value: Value) -> list[str]:
    """Sets back to ``start``, in ``values`` (13,) in place, the fitted parameters (``slots``)
    whose derivative is zero at every sample, when f (``value``) is then unchanged bit for bit;
    returns their names."""
    f, jacobian = evaluate(values)
    inert = [group for group in _whole_parameters(slots)
             if not np.any(jacobian[..., group]) and np.any(values[group] != start[group])]
    if not inert:
        return []
    moved = values.copy()
    for group in inert:
        moved[group] = start[group]
    if not np.array_equal(value(moved), f):
        return []
    values[:] = moved
    return [GRADIENT_NAMES[group[0]].removesuffix("_r") for group in inert]


def note(reset_names: Sequence[Sequence[str]]) -> str | None:
    """The result's note: which parameters went back to their start, in how many problems."""
    counted: dict[str, int] = {}
    for names in reset_names:
        for name in names:
            counted[name] = counted.get(name, 0) + 1
    if not counted:
        return None
    names = [name for name in PARAMETERS if name in counted]
    where = "" if len(reset_names) == 1 else f" (in {max(counted.values())} of {len(reset_names)} problems)"
    return (f"{', '.join(names)} set back to the start{where}: no effect on f at the fitted material "
            "(e.g. the diffuse and sheen lobes of a metal, metallic = 1); f, cost and residuals unchanged")
