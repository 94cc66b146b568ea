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
from ._validate import flag, model_and_mode

if TYPE_CHECKING:
    from ._typing import FloatArray, Layout, Mode, Model, RealArrayLike
    from .material import Material

__all__ = ["DIRECTION_NAMES", "asks_for_directions", "eval_grad", "reference_eval_grad", "vjp"]

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


def split(wrt: object, argument: str = "wrt", names: tuple[str, ...] = GRADIENT_NAMES) -> tuple[list[int], list[int]]:
    """(parameter slot indices, direction component indices) of ``wrt``, each in
    table order, the parameters among ``names`` (the model's columns); errors name ``argument``."""
    requested = _requested(wrt)
    if wrt is None or requested is None or not requested:
        return _gradient.columns(wrt, argument, names=names), []
    directions: set[int] = set()
    parameters: list[object] = []
    for name in requested:
        components = _direction_columns(name)
        if components:
            directions.update(DIRECTION_NAMES.index(c) for c in components)
            continue
        if isinstance(name, str) and name != "base_color" and name not in names:
            raise ValueError(f"{argument}: unknown parameter {name!r}; expected one of {', '.join(names)}, "
                             f"base_color, wi or wo (or one of {', '.join(DIRECTION_NAMES)})")
        parameters.append(name)
    return (_gradient.columns(parameters, argument, names=names) if parameters else []), sorted(directions)


def _names(names: tuple[str, ...], parameters: list[int], directions: list[int]) -> tuple[str, ...]:
    return tuple(names[k] for k in parameters) + tuple(DIRECTION_NAMES[k] for k in directions)


def _refuse_energy_compensation(energy_compensation: object) -> None:
    if flag("energy_compensation", energy_compensation):
        raise NotImplementedError("eval_grad: energy_compensation=True is not supported (the derivative of the "
                                  "multiple-scattering lobe is not implemented); evaluate f with pb.eval")


def eval_grad(material: Material, wi: RealArrayLike, wo: RealArrayLike, *, wrt: object, model: Model, cosine: bool,
              layout: Layout, threads: Any, out: Any, check: bool, isa: str | None,
              energy_compensation: bool, mode: Mode = "radiance") -> Gradient:
    """pb.eval_grad with direction columns in ``wrt`` (its arguments, checked as it checks them)."""
    _refuse_energy_compensation(energy_compensation)
    model_id, mode_id = model_and_mode(material, model, mode)
    names = _gradient.gradient_names(model)
    parameters, directions = split(wrt, names=names)
    layout = _batch._layout(layout)
    soa = layout == "soa"
    _batch._require_pair(out, "jacobian")
    options = dict(model=model, cosine=cosine, layout=layout, threads=threads, check=check, isa=isa, mode=mode)
    parts = []
    if parameters:  # f and the parameter columns first, the directions checked on the way
        first = _batch.eval_grad(material, wi, wo, wrt=[names[k] for k in parameters], **options)
        parts.append(first.jacobian)
        options["check"] = False

    def outputs(leading: tuple[int, ...], layout: str) -> list[FloatArray]:
        return [np.empty(_batch._vec3_shape(leading, layout), np.float32),
                np.empty(_batch._jacobian_shape(leading, layout, len(DIRECTION_NAMES)), np.float32)]

    value, by_direction = _batch._evaluate(material, wi, wo, model_id, cosine, layout, options["threads"],
                                           options["check"], isa, outputs, directions=True, mode_id=mode_id)
    if parameters:
        value = first.value
    parts.append(by_direction if len(directions) == len(DIRECTION_NAMES) else
                 by_direction[:, directions] if soa else by_direction[..., directions])
    axis = 1 if soa else -1
    if out is None and len(parts) == 1 and parts[0] is by_direction:
        return Gradient(value, by_direction, _names(names, parameters, directions))
    shape = list(parts[0].shape)
    shape[axis] = sum(part.shape[axis] for part in parts)
    result, jacobian = _batch._output_pair(out, value.shape, tuple(shape), "jacobian")
    if result is not value:
        result[...] = value
    np.concatenate(parts, axis=axis, out=jacobian)  # the columns side by side, written once
    return Gradient(result, jacobian, _names(names, parameters, directions))


def vjp(material: Material, wi: RealArrayLike, wo: RealArrayLike, cotangent: FloatArray, *,
        model: Model = "disney2014", cosine: bool = False, threads: Any = None, isa: str | None = None,
        mode: Mode = "radiance") -> tuple[FloatArray, FloatArray]:
    """``Σ_c g_c ∂f_c/∂wi`` and ``∂f_c/∂wo`` per element (float32 kernels), each ``(..., 3)`` at the
    call's broadcast shape, for a finite float32 cotangent ``(..., 3)`` broadcasting with it."""
    model_id, mode_id = model_and_mode(material, model, mode)
    g32 = np.asarray(cotangent, np.float32)

    def outputs(leading: tuple[int, ...], layout: str) -> list[FloatArray]:
        return [np.empty(leading + (len(DIRECTION_NAMES),), np.float32)]

    (product,) = _batch._evaluate(material, wi, wo, model_id, cosine, "aos", threads, True, isa, outputs,
                                  cotangent=g32, directions=True, mode_id=mode_id)
    return product[..., :3], product[..., 3:]


def reference_eval_grad(material: Material, wi: RealArrayLike, wo: RealArrayLike, *, wrt: object, model: Model,
                        cosine: bool, layout: Layout, energy_compensation: bool, mode: Mode = "radiance") -> Gradient:
    """pb.reference.eval_grad with direction columns in ``wrt``."""
    from . import reference

    _refuse_energy_compensation(energy_compensation)
    mode_id = model_and_mode(material, model, mode)[1]
    names = _gradient.gradient_names(model)
    parameters, directions = split(wrt, names=names)
    soa = reference._layout(layout)
    if parameters:
        first = reference.eval_grad(material, wi, wo, wrt=[names[k] for k in parameters], model=model,
                                    cosine=cosine, layout=layout, mode=mode)
        value, parts = first.value, [first.jacobian]
    else:
        value, parts = reference.eval(material, wi, wo, model=model, cosine=cosine, layout=layout, mode=mode), []
    shape, wi_rows, wo_rows, params, model_id = reference._prepare(
        material, reference._as_aos("wi", wi, soa), reference._as_aos("wo", wo, soa), model)
    by_direction = _core.reference_eval_direction_grad(wi_rows, wo_rows, params, model_id, flag("cosine", cosine), mode_id)
    selected = by_direction[..., directions].reshape(shape + (3, len(directions)))
    parts.append(reference._as_layout(selected, soa, trailing=2))
    return Gradient(value, np.concatenate(parts, axis=1 if soa else -1), _names(names, parameters, directions))
