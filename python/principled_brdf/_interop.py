"""What the PyTorch and JAX operations share (docs/interop.md): a material given as
named arrays, f by the float32 kernels or the float64 reference, and the
vector-Jacobian product that their backward passes return.

Everything here takes and returns numpy arrays; the framework modules convert.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from . import _batch, _direction_grad, reference
from .material import PARAMETERS, Material

if TYPE_CHECKING:
    from collections.abc import Mapping

# Options the differentiable operations pass on to eval and eval_grad.
EVAL_OPTIONS = ("model", "cosine", "mode")


def parameter_names(material: Mapping[str, Any]) -> list[str]:
    """The mapping's keys, checked against the parameter table, in the table's order."""
    unknown = [name for name in material if name not in PARAMETERS]
    if unknown:
        raise ValueError(f"material: unknown parameter {unknown[0]!r}; expected names from {', '.join(PARAMETERS)}")
    return [name for name in PARAMETERS if name in material]


def check_options(options: Mapping[str, Any]) -> dict[str, Any]:
    unknown = [name for name in options if name not in EVAL_OPTIONS]
    if unknown:
        raise TypeError(f"unexpected option {unknown[0]!r}; the differentiable eval takes {', '.join(EVAL_OPTIONS)}")
    return dict(options)


def leading_rank(names: list[str], values: list[np.ndarray], wi: np.ndarray, wo: np.ndarray) -> int:
    """The rank of the broadcast leading shape: directions and base_color carry a trailing 3."""
    ranks = [wi.ndim - 1, wo.ndim - 1] + [v.ndim - (1 if n == "base_color" else 0) for n, v in zip(names, values)]
    return max(ranks)


def material_of(names: list[str], values: list[np.ndarray]) -> Material:
    parameters: dict[str, Any] = dict(zip(names, values))
    return Material(**parameters)


def evaluate(names: list[str], values: list[np.ndarray], wi: np.ndarray, wo: np.ndarray, double: bool,
             options: Mapping[str, Any]) -> np.ndarray:
    """f by the float64 reference (``double``) or the float32 kernels."""
    material = material_of(names, values)
    if double:
        return reference.eval(material, wi, wo, **options)
    return _batch.eval(material, np.asarray(wi, np.float32), np.asarray(wo, np.float32), **options)


def sum_to_shape(gradient: np.ndarray, shape: tuple[int, ...]) -> np.ndarray:
    """``gradient`` summed over the axes that broadcasting added to an argument of ``shape``."""
    extra = gradient.ndim - len(shape)
    if extra:
        gradient = gradient.sum(axis=tuple(range(extra)))
    ones = tuple(axis for axis, size in enumerate(shape) if size == 1 and gradient.shape[axis] != 1)
    if ones:
        gradient = gradient.sum(axis=ones, keepdims=True)
    return gradient.reshape(shape)


def vjp(names: list[str], values: list[np.ndarray], wi: np.ndarray, wo: np.ndarray, cotangent: np.ndarray,
        wanted: list[bool], double: bool, options: Mapping[str, Any],
        shapes: list[tuple[int, ...]] | None = None) -> list[np.ndarray | None]:
    """``Σ_c cotangent_c ∂f_c/∂p`` for each parameter whose ``wanted`` is set, summed to
    that parameter's shape or to ``shapes`` (None for the others)."""
    asked = [name for name, want in zip(names, wanted) if want]
    result: list[np.ndarray | None] = [None] * len(names)
    if not asked:
        return result
    if shapes is not None:  # a gradient per entry of an axis the value is broadcast along: the value at that shape
        values = [np.broadcast_to(v, shape) for v, shape in zip(values, shapes)]
    material = material_of(names, values)
    if double:
        gradient = reference.eval_grad(material, wi, wo, wrt=asked, **options)
        # (..., 3, P) contracted with the cotangent over the colour axis
        per_element = np.einsum("...c,...ck->...k", cotangent.astype(np.float64, copy=False), gradient.jacobian)
        columns = dict(zip(gradient.names, np.moveaxis(per_element, -1, 0)))
    else:
        columns = _batch.eval_vjp(material, np.asarray(wi, np.float32), np.asarray(wo, np.float32), cotangent,
                                  wrt=asked, **options)
    for index, (name, want) in enumerate(zip(names, wanted)):
        if not want:
            continue
        part = columns[name] if PARAMETERS[name].slots == 1 else np.stack([columns[f"{name}_{c}"] for c in "rgb"],
                                                                           axis=-1)
        shape = values[index].shape if shapes is None else shapes[index]
        result[index] = sum_to_shape(np.asarray(part), shape).astype(values[index].dtype, copy=False)
    return result


def direction_vjp(names: list[str], values: list[np.ndarray], wi: np.ndarray, wo: np.ndarray, cotangent: np.ndarray,
                  double: bool, options: Mapping[str, Any],
                  shapes: tuple[tuple[int, ...], tuple[int, ...]] | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``Σ_c cotangent_c ∂f_c/∂wi`` and ``∂f_c/∂wo``, the derivatives of f in the 3-vectors as given
    (docs/gradients.md, "Derivatives in the directions"), each summed to that direction's shape
    (or to ``shapes``)."""
    material = material_of(names, values)
    # a cotangent with axes the inputs lack (vmap over it): the directions broadcast to them
    full = np.broadcast_shapes(wi.shape, wo.shape, cotangent.shape)
    wi_call, wo_call = np.broadcast_to(wi, full), np.broadcast_to(wo, full)
    if double:
        gradient = reference.eval_grad(material, wi_call, wo_call, wrt=["wi", "wo"], **options)
        products = np.einsum("...c,...ck->...k", cotangent.astype(np.float64, copy=False), gradient.jacobian)
        by_wi, by_wo = products[..., :3], products[..., 3:]
    else:
        by_wi, by_wo = _direction_grad.vjp(material, np.asarray(wi_call, np.float32), np.asarray(wo_call, np.float32),
                                           np.asarray(cotangent, np.float32), **options)
    wi_shape, wo_shape = (wi.shape, wo.shape) if shapes is None else shapes
    return (sum_to_shape(np.broadcast_to(by_wi, np.broadcast_shapes(by_wi.shape, wi_shape)), wi_shape).astype(wi.dtype, copy=False),
            sum_to_shape(np.broadcast_to(by_wo, np.broadcast_shapes(by_wo.shape, wo_shape)), wo_shape).astype(wo.dtype, copy=False))
