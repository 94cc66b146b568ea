"""``eval_grad``'s columns in the directions (docs/gradients.md, "Derivatives in the directions").

``wrt`` may name ``"wi"`` and ``"wo"`` (three columns each, ``wi_x, wi_y, wi_z``,
``wo_x, wo_y, wo_z``, or any of those six), after the parameter columns. The
parameter columns and f come from eval_grad's own pass (or eval's, when no
parameter is asked for), which checks the directions; the direction columns
from a second pass, the model's forward mode (``model/direction_gradient.hpp``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from . import _batch, _core, _gradient
from ._gradient import GRADIENT_NAMES, Gradient
from ._validate import broadcast_leading, flag, model_index

if TYPE_CHECKING:
    from ._typing import FloatArray, Layout, Model, RealArrayLike
    from .material import Material

__all__ = ["DIRECTION_NAMES", "asks_for_directions", "eval_grad", "reference_eval_grad"]

DIRECTION_NAMES = ("wi_x", "wi_y", "wi_z", "wo_x", "wo_y", "wo_z")
_DIRECTION_GROUPS = {"wi": DIRECTION_NAMES[:3], "wo": DIRECTION_NAMES[3:]}


def _requested(wrt: object) -> list[object] | None:
    return [wrt] if isinstance(wrt, str) else list(wrt) if isinstance(wrt, (list, tuple)) else None


def _direction_columns(name: object) -> tuple[str, ...]:
    if not isinstance(name, str):
        return ()
    return _DIRECTION_GROUPS.get(name, (name,) if name in DIRECTION_NAMES else ())


def asks_for_directions(wrt: object) -> bool:
    """True when ``wrt`` names a direction (``wi``, ``wo`` or one of their components)."""
    requested = _requested(wrt)
    return requested is not None and any(_direction_columns(name) for name in requested)


def split(wrt: object, argument: str = "wrt") -> tuple[list[int], list[int]]:
    """(parameter slot indices, direction component indices) of ``wrt``, each in
    table order; errors name ``argument``."""
    requested = _requested(wrt)
    if wrt is None or requested is None or not requested:
        return _gradient.columns(wrt, argument), []
    directions: set[int] = set()
    parameters: list[object] = []
    for name in requested:
        components = _direction_columns(name)
        if components:
            directions.update(DIRECTION_NAMES.index(c) for c in components)
            continue
        if isinstance(name, str) and name != "base_color" and name not in GRADIENT_NAMES:
            raise ValueError(f"{argument}: unknown parameter {name!r}; expected one of {', '.join(GRADIENT_NAMES)}, "
                             f"base_color, wi or wo (or one of {', '.join(DIRECTION_NAMES)})")
        parameters.append(name)
    return (_gradient.columns(parameters, argument) if parameters else []), sorted(directions)


def _names(parameters: list[int], directions: list[int]) -> tuple[str, ...]:
    return tuple(GRADIENT_NAMES[k] for k in parameters) + tuple(DIRECTION_NAMES[k] for k in directions)


def _joined(parts: list[FloatArray], soa: bool) -> FloatArray:
    """The parameter and direction columns side by side: the last axis, or axis 1 for layout="soa"."""
    return parts[0] if len(parts) == 1 else np.concatenate(parts, axis=1 if soa else -1)


def _refuse_energy_compensation(energy_compensation: object) -> None:
    if flag("energy_compensation", energy_compensation):
        raise NotImplementedError("eval_grad: energy_compensation=True is not supported (the derivative of the "
                                  "multiple-scattering lobe is not implemented); evaluate f with pb.eval")


def eval_grad(material: Material, wi: RealArrayLike, wo: RealArrayLike, *, wrt: object, model: Model, cosine: bool,
              layout: Layout, threads: Any, out: Any, check: bool, isa: str | None,
              energy_compensation: bool) -> Gradient:
    """pb.eval_grad with direction columns in ``wrt`` (its arguments, checked as it checks them)."""
    parameters, directions = split(wrt)
    _refuse_energy_compensation(energy_compensation)
    layout = _batch._layout(layout)
    soa = layout == "soa"
    _batch._require_pair(out, "jacobian")
    options = dict(model=model, cosine=cosine, layout=layout, threads=threads, check=check, isa=isa)
    # f and the parameter columns, the directions checked on the way (this pass raises on a bad one)
    if parameters:
        first = _batch.eval_grad(material, wi, wo, wrt=[GRADIENT_NAMES[k] for k in parameters], **options)
        value, parts = first.value, [first.jacobian]
    else:
        value, parts = _batch.eval(material, wi, wo, **options), []
    wi_dirs, wo_dirs = _batch._Directions("wi", wi, layout), _batch._Directions("wo", wo, layout)
    leading = broadcast_leading(wi=wi_dirs.leading, wo=wo_dirs.leading, material=material.shape)
    n = _batch._size(leading)
    if out is not None:  # checked before the direction pass, written after it
        _batch._output_pair(out, value.shape, _batch._jacobian_shape(leading, layout, len(parameters) + len(directions)),
                            "jacobian")
    wi_flat, wi_code = wi_dirs.flat(leading)
    wo_flat, wo_code = wo_dirs.flat(leading)
    by_direction = np.empty((3, 6, n) if soa else (n, 3, 6), np.float32)
    evaluation = _core.EvalOptions(model=model_index(model), cosine=flag("cosine", cosine), energy_compensation=False,
                                   check_tolerance=0.0, threads=_batch._threads(threads), isa=_batch._isa(isa))
    if n:
        _core.batch_eval_direction_grad(wi=wi_flat, wi_layout=wi_code, wo=wo_flat, wo_layout=wo_code,
                                        params=_batch._params(material, leading), jacobian=by_direction,
                                        out_layout=_batch._ROWS if soa else _batch._INTERLEAVED, n=n,
                                        options=evaluation)
    selected = by_direction[:, directions] if soa else by_direction[..., directions]
    parts.append(selected.reshape((3, len(directions)) + leading if soa else leading + (3, len(directions))))
    jacobian = _joined(parts, soa)
    if out is not None:
        out[0][...] = value
        out[1][...] = jacobian
        value, jacobian = out
    return Gradient(value, jacobian, _names(parameters, directions))


def reference_eval_grad(material: Material, wi: RealArrayLike, wo: RealArrayLike, *, wrt: object, model: Model,
                        cosine: bool, layout: Layout, energy_compensation: bool) -> Gradient:
    """pb.reference.eval_grad with direction columns in ``wrt``."""
    from . import reference

    parameters, directions = split(wrt)
    _refuse_energy_compensation(energy_compensation)
    soa = reference._layout(layout)
    options = dict(model=model, cosine=cosine, layout=layout)
    if parameters:
        first = reference.eval_grad(material, wi, wo, wrt=[GRADIENT_NAMES[k] for k in parameters], **options)
        value, parts = first.value, [first.jacobian]
    else:
        value, parts = reference.eval(material, wi, wo, **options), []
    shape, wi_rows, wo_rows, params, model_id = reference._prepare(
        material, reference._as_aos("wi", wi, soa), reference._as_aos("wo", wo, soa), model)
    by_direction = _core.reference_eval_direction_grad(wi_rows, wo_rows, params, model_id, flag("cosine", cosine))
    selected = by_direction[..., directions].reshape(shape + (3, len(directions)))
    parts.append(reference._as_layout(selected, soa, trailing=2))
    return Gradient(value, _joined(parts, soa), _names(parameters, directions))
