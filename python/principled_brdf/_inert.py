"""Fitted parameters that end without effect go back to their start (docs/fitting.md#what-the-fit-holds).

At ``metallic = 1`` the diffuse, subsurface and sheen lobes are weighted by
``1 - metallic = 0`` and ``specular``, ``specular_tint`` drop out of Cspec0;
at ``sheen = 0`` ``sheen_tint`` does nothing, at ``clearcoat = 0``
``clearcoat_gloss``. Whatever values such parameters took on the way are
noise (a metal that ends with ``sheen = 1`` has no sheen), so they are set back
to their start when that leaves f unchanged at every sample to float32's
resolution (within 1e-6 of its largest value; a bound is reached only to
the solver's tolerance, so ``1 - metallic`` may be 3e-8 rather than 0): the
fitted f is the same, only its reading changes. The candidates are the
parameters whose move back changes f by less than that to first order
(``|∂f/∂p| |p - start| <= 1e-8 max |f|``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ._gradient import GRADIENT_NAMES_2015
from .material import PARAMETERS

_FIRST_ORDER_CHANGE = 1e-8  # of max |f|: below float32's resolution (6e-8)
_SAME_F = 1e-6  # of max |f|: f unchanged to float32's resolution
_SHOWN_CHANGE = 1e-6  # a parameter set back from closer than this to its start is not named in the note

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence
    from typing import Any

    from numpy.typing import NDArray

    from ._typing import Float64Array

    # f and ∂f/∂slot at the slot values (P,) over one problem's samples: (n, 3), (n, 3, P), P = 13 or 16
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
          value: Value) -> list[str] | None:
    """Sets back to ``start``, in ``values`` (P,) in place, the fitted parameters (``slots``)
    whose derivative is (next to) zero at every sample, when f (``value``) is then unchanged
    to 1e-6 of its largest value; returns the names of those that moved visibly (by more than
    1e-6), or None when nothing was set back."""
    f, jacobian = evaluate(values)
    resolution = _FIRST_ORDER_CHANGE * float(np.max(np.abs(f), initial=0.0))
    inert = [group for group in _whole_parameters(slots)
             if np.any(values[group] != start[group])
             and float(np.max(np.abs(jacobian[..., group] @ (values[group] - start[group])))) <= resolution]
    if not inert:
        return None
    moved = values.copy()
    for group in inert:
        moved[group] = start[group]
    if not np.max(np.abs(value(moved) - f), initial=0.0) <= _SAME_F * float(np.max(np.abs(f), initial=0.0)):
        return None
    shown = [GRADIENT_NAMES_2015[group[0]].removesuffix("_r") for group in inert
             if np.max(np.abs(values[group] - start[group])) > _SHOWN_CHANGE]
    values[:] = moved
    return shown


def candidates(value: NDArray[np.floating[Any]], jacobian: NDArray[np.floating[Any]], present: NDArray[np.bool_],
               values: Float64Array, start: Float64Array, slots: Sequence[int]) -> NDArray[np.bool_]:
    """Which of B problems ``reset`` may change: f ``(B, n, 3)``, its Jacobian ``(B, n, 3, P)``,
    ``present`` ``(B, n)`` the samples to look at, ``values`` and ``start`` ``(B, P)``. A superset
    (twice reset's first-order bound), so that a problem left out is one reset would leave."""
    here = present[..., None]
    scale = np.max(np.where(here, np.abs(value), 0.0), axis=(1, 2), initial=0.0)
    bound = 2.0 * _FIRST_ORDER_CHANGE * scale.astype(np.float64)
    maybe = np.zeros(len(values), bool)
    for group in _whole_parameters(slots):
        delta = (values[:, group] - start[:, group]).astype(np.float64)
        change = np.einsum("bnck,bk->bnc", jacobian[..., group].astype(np.float64), delta)
        first_order = np.max(np.where(here, np.abs(change), 0.0), axis=(1, 2), initial=0.0)
        maybe |= np.any(delta != 0.0, axis=1) & (first_order <= bound)
    return maybe


def note(reset_names: Sequence[Sequence[str]], problems: int) -> str | None:
    """The result's note: which parameters went back to their start, in how many of the problems."""
    counted: dict[str, int] = {}
    for names in reset_names:
        for name in names:
            counted[name] = counted.get(name, 0) + 1
    if not counted:
        return None
    names = [name for name in PARAMETERS if name in counted]
    where = "" if problems == 1 else f" (in {max(counted.values())} of {problems} problems)"
    return (f"{', '.join(names)} set back to the start{where}: no effect on f at the fitted material "
            "(e.g. the diffuse and sheen lobes of a metal, metallic = 1); f unchanged to float32's resolution")
