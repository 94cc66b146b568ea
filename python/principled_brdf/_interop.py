"""What the PyTorch and JAX operations share (docs/interop.md): the checks of
their arguments (pb.Material's, with its messages), f by the float32 kernels
or the float64 reference, and the vector-Jacobian products their backward
passes return.

Everything here takes and returns numpy arrays; the framework modules convert.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from . import _batch, _derivatives, reference
from ._model_checks import model_and_mode
from ._validate import as_real_array, broadcast_leading, flag, mode_index, model_index, require_finite
from .material import PARAMETERS, Material

if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence

# Options the differentiable operations pass on to eval and eval_grad, with pb.eval's defaults.
EVAL_OPTIONS = {"model": "disney2014", "cosine": False, "mode": "radiance"}
# The dtypes a framework's own tensor or array may have: the float32 kernels' and the float64 reference's.
FLOAT_DTYPES = ("float32", "float64")


def parameter_names(material: Mapping[str, Any]) -> list[str]:
    """The mapping's keys, checked against the parameter table, in the table's order."""
    unknown = [name for name in material if name not in PARAMETERS]
    if unknown:
        raise ValueError(f"material: unknown parameter {unknown[0]!r}; expected names from {', '.join(PARAMETERS)}")
    return [name for name in PARAMETERS if name in material]


def check_options(options: Mapping[str, Any]) -> dict[str, Any]:
    """``model``, ``cosine`` and ``mode``, checked as pb.eval checks them, the others at their defaults."""
    unknown = [name for name in options if name not in EVAL_OPTIONS]
    if unknown:
        raise TypeError(f"unexpected option {unknown[0]!r}; the differentiable eval takes {', '.join(EVAL_OPTIONS)}")
    checked = {**EVAL_OPTIONS, **options}
    model_index(checked["model"])
    mode_index(checked["mode"])
    checked["cosine"] = flag("cosine", checked["cosine"])
    return checked


def dtype_error(name: str, dtype: object, kind: str, conversion: str) -> TypeError:
    """The error for a framework tensor or array of a dtype the kernels do not take (``kind``:
    "tensor" or "array"; ``conversion``: how to convert one, e.g. ``.float()``)."""
    return TypeError(f"{name}: expected a real floating-point {kind} (float32 or float64), got {dtype}; "
                     f"convert it, e.g. {conversion}")


def real_array(name: str, value: object) -> np.ndarray:
    """A direction (or ``u``) given as a number or an array, not a framework's: a float32 or
    float64 array as it is, anything else read as pb.eval reads it (TypeError naming ``name``)."""
    if isinstance(value, np.ndarray) and value.dtype.name in FLOAT_DTYPES:
        return value
    return as_real_array(name, value)


def leading_shape(names: Sequence[str], shapes: Sequence[tuple[int, ...]], wi: tuple[int, ...],
                  wo: tuple[int, ...]) -> tuple[int, ...]:
    """The broadcast leading shape of the directions ``(..., 3)`` and the parameters of
    ``shapes`` (base_color ``(..., 3)``), or the library's errors naming the argument."""
    leading = {}
    for name, shape in (("wi", wi), ("wo", wo)):
        if len(shape) == 0 or shape[-1] != 3:
            raise ValueError(f"{name}: expected shape (..., 3) with unit 3-vectors on the last axis, got {shape}")
        leading[name] = shape[:-1]
    for name, shape in zip(names, shapes):
        if PARAMETERS[name].slots == 3:
            if len(shape) == 0 or shape[-1] != 3:
                raise ValueError(f"{name}: expected an RGB triple, shape (3,) or (..., 3), got shape {shape}")
            shape = shape[:-1]
        leading[name] = shape
    return broadcast_leading(**leading)


def material_of(names: Sequence[str], values: Sequence[Any], options: Mapping[str, Any] | None = None,
                bright_base_color: bool = False) -> Material:
    """pb.Material of the named values (its checks and messages); with ``options``, also
    the rules of their model (its unread parameters at their defaults)."""
    material = Material(**dict(zip(names, values)), bright_base_color=bright_base_color)
    if options is not None:
        model_and_mode(material, options["model"], options["mode"])
    return material


def evaluate(material: Material, wi: np.ndarray, wo: np.ndarray, double: bool,
             options: Mapping[str, Any]) -> np.ndarray:
    """f by the float64 reference (``double``) or the float32 kernels."""
    if double:
        return reference.eval(material, wi, wo, **options)
    return _batch.eval(material, wi, wo, **options)  # (which converts them to float32, checked)


def sum_to_shape(gradient: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """``gradient`` summed over the axes that broadcasting added to an argument of ``shape``."""
    extra = gradient.ndim - len(shape)
    if extra:
        gradient = gradient.sum(axis=tuple(range(extra)))
    ones = tuple(axis for axis, size in enumerate(shape) if size == 1 and gradient.shape[axis] != 1)
    if ones:
        gradient = gradient.sum(axis=ones, keepdims=True)
    return gradient.reshape(shape)


def backward(material: Material, names: Sequence[str], wi: np.ndarray, wo: np.ndarray, cotangent: np.ndarray,
             asked: Sequence[bool], double: bool, options: Mapping[str, Any],
             direction_shapes: tuple[tuple[int, ...], tuple[int, ...]] | None = None) -> list[np.ndarray | None]:
    """The cotangents of ``(wi, wo, *names)`` that ``asked`` selects (None for the others)
    for a finite ``cotangent`` shaped like f (a ValueError naming ``cotangent`` otherwise),
    in the call's precision. A parameter's is summed to its shape in ``material``, a
    direction's to its own shape (or ``direction_shapes``): the derivative of f in the
    3-vector as given (docs/gradients.md, "Derivatives in the directions")."""
    require_finite("cotangent", cotangent)
    dtype = np.float64 if double else np.float32
    result: list[np.ndarray | None] = [None, None]
    if asked[0] or asked[1]:
        shapes = direction_shapes or (wi.shape, wo.shape)
        products = direction_vjp(material, wi, wo, cotangent, double, options)
        result = [sum_to_shape(np.broadcast_to(d, np.broadcast_shapes(d.shape, shape)), shape).astype(dtype)
                  if want else None for d, shape, want in zip(products, shapes, asked[:2])]
    gradients = vjp(material, names, wi, wo, cotangent, asked[2:], double, options)
    return result + [None if g is None else np.asarray(g, dtype) for g in gradients]


def vjp(material: Material, names: Sequence[str], wi: np.ndarray, wo: np.ndarray, cotangent: np.ndarray,
        wanted: Sequence[bool], double: bool, options: Mapping[str, Any]) -> list[np.ndarray | None]:
    """``Σ_c cotangent_c ∂f_c/∂p`` for each named parameter whose ``wanted`` is set, summed to
    that parameter's shape in ``material`` (None for the others)."""
    asked = [name for name, want in zip(names, wanted) if want]
    if not asked:
        return [None] * len(names)
    if double:
        gradient = reference.eval_grad(material, wi, wo, wrt=asked, **options)
        # (..., 3, P) contracted with the cotangent over the colour axis
        per_element = np.einsum("...c,...ck->...k", cotangent.astype(np.float64, copy=False), gradient.jacobian)
        columns = dict(zip(gradient.names, np.moveaxis(per_element, -1, 0)))
    else:
        columns = _derivatives.eval_vjp(material, np.asarray(wi, np.float32), np.asarray(wo, np.float32), cotangent,
                                        wrt=asked, **options)
    result: list[np.ndarray | None] = []
    for name, want in zip(names, wanted):
        if not want:
            result.append(None)
            continue
        part = columns[name] if PARAMETERS[name].slots == 1 else np.stack([columns[f"{name}_{c}"] for c in "rgb"],
                                                                           axis=-1)
        result.append(sum_to_shape(np.asarray(part), getattr(material, name).shape))
    return result


def direction_vjp(material: Material, wi: np.ndarray, wo: np.ndarray, cotangent: np.ndarray, double: bool,
                  options: Mapping[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    """``Σ_c cotangent_c ∂f_c/∂wi`` and ``∂f_c/∂wo`` per element, at the broadcast shape of the
    call and the cotangent: the derivatives of f in the 3-vectors as given (docs/gradients.md,
    "Derivatives in the directions")."""
    # a cotangent with axes the inputs lack (vmap over it): the directions broadcast to them
    full = np.broadcast_shapes(wi.shape, wo.shape, cotangent.shape)
    wi_call, wo_call = np.broadcast_to(wi, full), np.broadcast_to(wo, full)
    if double:
        gradient = reference.eval_grad(material, wi_call, wo_call, wrt=["wi", "wo"], **options)
        products = np.einsum("...c,...ck->...k", cotangent.astype(np.float64, copy=False), gradient.jacobian)
        return products[..., :3], products[..., 3:]
    return _derivatives.direction_vjp(material, np.asarray(wi_call, np.float32), np.asarray(wo_call, np.float32),
                                      np.asarray(cotangent, np.float32), **options)
