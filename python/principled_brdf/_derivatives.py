"""The derivatives of f: pb.eval_grad and pb.eval_vjp (the SIMD kernels, or the
float64 reference for ``precision="float64"``) and pb.reference.eval_grad, in
the material's parameters and in the directions (docs/gradients.md).

``wrt`` may name ``"wi"`` and ``"wo"`` (three columns each, ``wi_x, wi_y, wi_z``,
``wo_x, wo_y, wo_z``, or any of those six), after the parameter columns. The
parameter columns and f come from the backend's own pass (or its eval, when no
parameter is asked for), which checks the directions; the direction columns
from a second pass, the model's forward mode (``model/direction_gradient.hpp``).
Both backends are joined here, above them.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from . import _batch, _float64, _gradient
from ._gradient import GRADIENT_NAMES
from ._model_checks import model_and_mode
from ._results import Gradient
from ._validate import as_real_array, layout as checked_layout, refuse_energy_compensation_derivative, require_finite
from .material import PARAMETERS, require_material

if TYPE_CHECKING:
    from typing import Literal, SupportsIndex

    from numpy.typing import NDArray

    from ._typing import Float32Array, FloatArray, Layout, Mode, Model, RealArrayLike
    from .material import Material

__all__ = ["DIRECTION_NAMES", "asks_for_directions", "split", "eval_grad", "eval_vjp", "reference_eval_grad",
           "direction_vjp"]

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


def eval_grad(material: Material, wi: RealArrayLike, wo: RealArrayLike, *,
              wrt: str | list[str] | tuple[str, ...] | None = None, model: Model = "disney2014", cosine: bool = False,
              layout: Layout = "aos", threads: SupportsIndex | None = None,
              out: tuple[Float32Array, Float32Array] | None = None, check: bool = True,
              isa: str | None = None, energy_compensation: bool = False, mode: Mode = "radiance") -> Gradient:
    """f and its Jacobian in the material's parameters, by the SIMD kernel in
    float32 (docs/gradients.md).

    Returns a :class:`Gradient`: ``value`` as :func:`eval` returns it,
    ``jacobian`` ``(..., 3, P)`` (``(3, P, ...)`` for ``layout="soa"``) with
    ``jacobian[..., c, k] = ∂f_c/∂names[k]``, and ``names``: the P parameters
    ``wrt`` selects (default all 13 slots of the parameter table the 2012
    and 2014 models read, all 16 for ``model="disney2015"``,
    ``base_color`` as ``base_color_r/g/b``), in the table's order. A uniform
    parameter still gets a per-element derivative. ``out=(value, jacobian)``
    writes into preallocated float32 arrays of exactly those shapes. The other
    arguments are :func:`eval`'s; ``energy_compensation=True`` raises
    NotImplementedError with the BRDFs (the 2015 solid's is differentiated). ``wrt`` may also name ``"wi"`` and ``"wo"``: three
    columns each (``wi_x, wi_y, wi_z``, ``wo_x, wo_y, wo_z``) after the
    parameters', the derivatives of f in the 3-vectors as given
    (docs/gradients.md, "Derivatives in the directions").
    """
    if not asks_for_directions(wrt):
        return _batch.parameter_grad(material, wi, wo, wrt=wrt, model=model, cosine=cosine, layout=layout,
                                     threads=threads, out=out, check=check, isa=isa,
                                     energy_compensation=energy_compensation, mode=mode)
    refuse_energy_compensation_derivative(energy_compensation, model)
    model_id, mode_id = model_and_mode(material, model, mode, energy_compensation)
    names = _gradient.gradient_names(model)
    parameters, directions = split(wrt, names=names)
    layout = checked_layout(layout)
    soa = layout == "soa"
    _batch.require_out_pair(out, "jacobian")
    parts = []
    if parameters:  # f and the parameter columns first, the directions checked on the way
        first = _batch.parameter_grad(material, wi, wo, wrt=[names[k] for k in parameters], model=model,
                                      cosine=cosine, layout=layout, threads=threads, check=check, isa=isa, mode=mode,
                                      energy_compensation=energy_compensation)
        parts.append(first.jacobian)
        check = False
    value, by_direction = _batch.direction_grad(material, wi, wo, model_id=model_id, mode_id=mode_id, cosine=cosine,
                                                layout=layout, threads=threads, check=check, isa=isa,
                                                energy_compensation=energy_compensation)
    if parameters:
        value = first.value
    parts.append(by_direction if len(directions) == len(DIRECTION_NAMES) else
                 by_direction[:, directions] if soa else by_direction[..., directions])
    axis = 1 if soa else -1
    if out is None and len(parts) == 1 and parts[0] is by_direction:
        return Gradient(value, by_direction, _names(names, parameters, directions))
    shape = list(parts[0].shape)
    shape[axis] = sum(part.shape[axis] for part in parts)
    result, jacobian = _batch.out_pair(out, value.shape, tuple(shape), "jacobian")
    if result is not value:
        result[...] = value
    np.concatenate(parts, axis=axis, out=jacobian)  # the columns side by side, written once
    return Gradient(result, jacobian, _names(names, parameters, directions))


def reference_eval_grad(material: Material, wi: RealArrayLike, wo: RealArrayLike, *,
                        wrt: str | list[str] | tuple[str, ...] | None = None, model: Model = "disney2014",
                        cosine: bool = False, layout: Layout = "aos", energy_compensation: bool = False,
                        mode: Mode = "radiance") -> Gradient:
    """pb.reference.eval_grad: :func:`eval_grad`'s columns from the float64 reference."""
    if not asks_for_directions(wrt):
        return _float64.parameter_grad(material, wi, wo, wrt=wrt, model=model, cosine=cosine, layout=layout,
                                       energy_compensation=energy_compensation, mode=mode)
    refuse_energy_compensation_derivative(energy_compensation, model)
    mode_id = model_and_mode(material, model, mode, energy_compensation)[1]
    names = _gradient.gradient_names(model)
    parameters, directions = split(wrt, names=names)
    soa = checked_layout(layout) == "soa"
    if parameters:
        first = _float64.parameter_grad(material, wi, wo, wrt=[names[k] for k in parameters], model=model,
                                        cosine=cosine, layout=layout, mode=mode, energy_compensation=energy_compensation)
        value, parts = first.value, [first.jacobian]
    else:
        value, parts = _float64.eval(material, wi, wo, model=model, cosine=cosine, layout=layout, mode=mode,
                                     energy_compensation=energy_compensation), []
    by_direction = _float64.direction_grad(material, wi, wo, model=model, cosine=cosine, layout=layout, mode_id=mode_id,
                                           energy_compensation=energy_compensation)
    parts.append(by_direction[:, directions] if soa else by_direction[..., directions])
    return Gradient(value, np.concatenate(parts, axis=1 if soa else -1), _names(names, parameters, directions))


def eval_vjp(material: Material, wi: RealArrayLike, wo: RealArrayLike, cotangent: RealArrayLike, *,
             wrt: str | list[str] | tuple[str, ...] | None = None, model: Model = "disney2014", cosine: bool = False,
             layout: Layout = "aos", threads: SupportsIndex | None = None, check: bool = True,
             isa: str | None = None, precision: Literal["float32", "float64"] = "float32",
             mode: Mode = "radiance") -> dict[str, FloatArray]:
    """The vector-Jacobian product of f: for a cotangent g shaped like f,
    ``Σ_c g_c ∂f_c/∂p`` for each parameter slot p that ``wrt`` selects (as
    :func:`eval_grad`'s; default all), without forming the Jacobian
    (docs/gradients.md).

    Returns ``{slot name: array}`` in the table's order, each array shaped like
    that parameter's own value in ``material`` (without ``base_color``'s
    trailing 3): a per-element parameter gets one product per element (summed
    over the axes it is broadcast along), a uniform one the sum over every
    element, a 0-d array. ``cotangent``: real, ``(..., 3)`` (``(3, ...)`` for
    ``layout="soa"``) broadcasting with the call's shape. ``precision``:
    ``"float32"`` (the SIMD kernel; sums over elements taken in float64, then
    rounded) or ``"float64"`` (the reference). The other arguments are
    :func:`eval_grad`'s.
    """
    require_material("material", material)
    model_id, mode_id = model_and_mode(material, model, mode)
    names = _gradient.gradient_names(model)
    wanted = _gradient.columns(wrt, names=names)
    if not isinstance(precision, str) or precision not in ("float32", "float64"):
        raise ValueError(f"precision: expected 'float32' or 'float64', got {precision!r}")
    layout = checked_layout(layout)
    soa = layout == "soa"
    # a float32 cotangent is read as it is, anything else as float64
    given_float32 = isinstance(cotangent, np.ndarray) and cotangent.dtype == np.float32
    g = np.asarray(cotangent) if given_float32 else as_real_array("cotangent", cotangent)
    if g.ndim == 0 or g.shape[0 if soa else -1] != 3:
        raise ValueError(f"cotangent: expected shape {'(3, ...)' if soa else '(..., 3)'} like f, got {g.shape}")
    require_finite("cotangent", g)  # the rule of every backward pass (docs/bad-input.md)
    if precision == "float64":
        gradient = _float64.parameter_grad(material, wi, wo, wrt=wrt, model=model, cosine=cosine, layout=layout,
                                           mode=mode)
        jacobian = gradient.jacobian if not soa else np.moveaxis(gradient.jacobian, (0, 1), (-2, -1))
        g_aos = g if not soa else np.moveaxis(g, 0, -1)
        products = np.einsum("...c,...ck->...k", np.broadcast_to(g_aos, jacobian.shape[:-1]), jacobian)
        return _sum_to_parameters(material, products, wanted, names, np.float64)
    g32 = g.astype(np.float32, copy=False)
    if g32 is not g and np.isinf(g32).any():
        raise ValueError("cotangent: values beyond float32's range")
    product = _batch.parameter_vjp(material, wi, wo, g32, columns=wanted, model_id=model_id, mode_id=mode_id,
                                   cosine=cosine, layout=layout, threads=threads, check=check, isa=isa)
    return _sum_to_parameters(material, product if not soa else np.moveaxis(product, 0, -1), wanted, names, np.float32)


def _sum_to_parameters(material: Material, products: NDArray[Any], wanted: list[int], names: tuple[str, ...],
                       dtype: type[np.floating[Any]]) -> dict[str, FloatArray]:
    """``products`` ``(..., P)`` summed down to each selected parameter's own shape (float64 sums)."""
    result: dict[str, FloatArray] = {}
    for k, slot in enumerate(wanted):
        info = next(i for i in PARAMETERS.values() if i.first_slot <= slot < i.first_slot + i.slots)
        value = np.asarray(getattr(material, info.name))
        own = value.shape[:-1] if info.slots == 3 else value.shape
        column = products[..., k]
        extra = column.ndim - len(own)
        axes = tuple(range(extra)) + tuple(extra + a for a, d in enumerate(own) if d == 1 and column.shape[extra + a] != 1)
        if not axes:  # one product an element: as it is
            result[names[slot]] = np.ascontiguousarray(column, dtype=dtype).reshape(own)
            continue
        total = column.sum(axis=axes, dtype=np.float64, keepdims=False)
        result[names[slot]] = np.asarray(total, dtype=np.float64).reshape(own).astype(dtype)
    return result


def direction_vjp(material: Material, wi: RealArrayLike, wo: RealArrayLike, cotangent: FloatArray, *,
                  model: Model = "disney2014", cosine: bool = False, threads: Any = None, isa: str | None = None,
                  mode: Mode = "radiance") -> tuple[FloatArray, FloatArray]:
    """``Σ_c g_c ∂f_c/∂wi`` and ``∂f_c/∂wo`` per element (float32 kernels), each ``(..., 3)`` at the
    call's broadcast shape, for a finite float32 cotangent ``(..., 3)`` broadcasting with it."""
    model_id, mode_id = model_and_mode(material, model, mode)
    product = _batch.direction_vjp(material, wi, wo, np.asarray(cotangent, np.float32), model_id=model_id,
                                   mode_id=mode_id, cosine=cosine, threads=threads, isa=isa)
    return product[..., :3], product[..., 3:]
