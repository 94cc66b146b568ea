"""The kernels as JAX operations on CPU arrays (docs/interop.md).

``eval`` is a ``jax.custom_vjp`` function over host callbacks
(``jax.pure_callback``): it runs under ``jit`` and ``vmap``, and its backward
pass is the library's vector-Jacobian product, in the parameters and in
``wi`` and ``wo`` (only in the inputs that are differentiated). float32 inputs go through the
SIMD kernels; float64 inputs (with ``jax_enable_x64``) through the float64
reference. What is known when the call is traced (shapes, dtypes, options,
concrete values) is checked then; traced values inside the callbacks.

    import jax, jax.numpy as jnp
    from principled_brdf import jax as pbj
    loss = lambda r: jnp.sum(pbj.eval({"roughness": r}, wi, wo))
    jax.grad(loss)(jnp.float32(0.5))
"""

from __future__ import annotations

import dataclasses
import functools
from typing import TYPE_CHECKING, Any

import numpy as np

try:
    import jax
    import jax.numpy as jnp
    from jax.custom_derivatives import CustomVJPPrimal, SymbolicZero
except ImportError as error:  # pragma: no cover - the test extra installs jax
    raise ImportError("principled_brdf.jax needs JAX: pip install 'principled-brdf[jax]'") from error

from . import _interop
from ._validate import as_real_array, directions, require_finite, require_float32

if TYPE_CHECKING:
    from collections.abc import Mapping

__all__ = ["eval"]


def _traced(value: object) -> bool:
    """True for a value JAX traces (under jit, grad, vmap): known only when the callback runs."""
    return isinstance(value, jax.core.Tracer)


def _static_options(options: Mapping[str, Any]) -> dict[str, Any]:
    """The options, checked: they select the computation, so they cannot be traced."""
    for name, value in options.items():
        if _traced(value):
            raise TypeError(f"{name}: must be a static Python value, not a traced array; under jit, mark it "
                            f"static (static_argnames) or close over it")
    return _interop.check_options(options)


def _parameter(name: str, value: object) -> Any:
    """A JAX array of float32 or float64 (TypeError naming ``name`` otherwise), a numpy
    array as given (pb.Material checks its dtype), or a number or sequence read as a real array."""
    if isinstance(value, jax.Array):
        if value.dtype.name not in _interop.FLOAT_DTYPES:
            raise _interop.dtype_error(name, value.dtype, "array", "x.astype(jnp.float32)")
        return value
    return value if isinstance(value, np.ndarray) else as_real_array(name, value)


def _direction(name: str, value: object) -> Any:
    """A JAX array of float32 or float64, or a number or array read as pb.eval reads a direction."""
    if isinstance(value, jax.Array):
        return _parameter(name, value)
    return _interop.real_array(name, value)


def _precision(wi: Any) -> np.dtype[Any]:
    """float64 when ``wi`` is float64 and JAX keeps float64 (``jax_enable_x64``), else float32."""
    if wi.dtype == np.float64:
        return np.dtype(jax.dtypes.canonicalize_dtype(np.float64))
    return np.dtype(np.float32)


def _check_concrete(names: list[str], values: list[Any], wi: Any, wo: Any, options: dict[str, Any],
                    float32: bool) -> None:
    """The checks pb.eval applies, to the arguments whose values are known now (not traced)."""
    for name, w in (("wi", wi), ("wo", wo)):
        if not _traced(w):
            directions(name, np.asarray(w))
    known = [(name, np.asarray(v) if isinstance(v, jax.Array) else v) for name, v in zip(names, values)
             if not _traced(v)]
    if not known:
        return
    # bright_base_color: the callback's Material gives the warning, once
    material = _interop.material_of([n for n, _ in known], [v for _, v in known], options, bright_base_color=True)
    if float32:
        for name, _ in known:
            require_float32(name, getattr(material, name))


@jax.tree_util.register_static
@dataclasses.dataclass(frozen=True)
class _Asked:
    """Which of (wi, wo, *values) the backward pass differentiates: static, kept in the residuals' structure."""

    inputs: tuple[bool, ...]


def _aligned(array: jax.Array, rank: int, trailing: int) -> jax.Array:
    """``array`` with leading 1s up to ``rank`` leading axes (plus ``trailing``), so that
    every argument of the callback has one rank and ``vmap`` adds its axes alike."""
    return jnp.reshape(array, (1,) * (rank + trailing - array.ndim) + array.shape)


@functools.lru_cache(maxsize=None)
def _operation(names: tuple[str, ...], options: tuple[tuple[str, Any], ...]) -> Any:
    """The custom_vjp function of (wi, wo, *values) for one set of parameter names and options."""
    keywords = dict(options)
    names_list = list(names)

    def host_eval(*arguments: Any) -> np.ndarray:
        wi, wo, *values = (np.asarray(a) for a in arguments)  # (the callback may be given JAX arrays)
        material = _interop.material_of(names_list, values)
        return _interop.evaluate(material, wi, wo, wi.dtype == np.float64, keywords).astype(wi.dtype, copy=False)

    def host_vjp(rank: int, asked: tuple[bool, ...], *arguments: Any) -> tuple[np.ndarray, ...]:
        wi, wo, cotangent, *values = (np.asarray(a) for a in arguments)  # (wi, wo, cotangent, *values)
        # vmap's axes lead every argument (1 where one is not mapped); each cotangent has all of them
        k = wi.ndim - 1 - rank
        mapped = np.broadcast_shapes(*(a.shape[:k] for a in (wi, wo, cotangent, *values)))
        material = _interop.material_of(names_list, [np.broadcast_to(v, mapped + v.shape[k:]) for v in values])
        cotangents = _interop.backward(material, names_list, wi, wo, cotangent, asked, wi.dtype == np.float64,
                                       keywords, (mapped + wi.shape[k:], mapped + wo.shape[k:]))
        return tuple(c for c in cotangents if c is not None)

    def value_shape(wi: jax.Array, wo: jax.Array, values: tuple[jax.Array, ...]) -> jax.ShapeDtypeStruct:
        leading = np.broadcast_shapes(wi.shape[:-1], wo.shape[:-1],
                                      *(v.shape[:-1] if n == "base_color" else v.shape for n, v in zip(names, values)))
        return jax.ShapeDtypeStruct(leading + (3,), wi.dtype)  # type: ignore[no-untyped-call]

    @jax.custom_vjp
    def operation(wi: jax.Array, wo: jax.Array, *values: jax.Array) -> jax.Array:
        return jax.pure_callback(host_eval, value_shape(wi, wo, values), wi, wo, *values, vmap_method="expand_dims")

    def forward(*primals: CustomVJPPrimal) -> tuple[jax.Array, tuple[Any, ...]]:
        arrays = tuple(p.value for p in primals)
        return operation(*arrays), (arrays, _Asked(tuple(bool(p.perturbed) for p in primals)))

    def backward(residuals: tuple[Any, ...], cotangent: Any) -> tuple[Any, ...]:
        arrays, asked = residuals
        if isinstance(cotangent, SymbolicZero) or not any(asked.inputs):
            return (None,) * len(arrays)
        if not _traced(cotangent):
            require_finite("cotangent", np.asarray(cotangent))
        shapes = tuple(jax.ShapeDtypeStruct(a.shape, a.dtype)  # type: ignore[no-untyped-call]
                       for a, want in zip(arrays, asked.inputs) if want)
        computed = iter(jax.pure_callback(functools.partial(host_vjp, cotangent.ndim - 1, asked.inputs), shapes,
                                          arrays[0], arrays[1], cotangent, *arrays[2:], vmap_method="expand_dims"))
        # only the cotangents of the inputs that are differentiated are computed; None is a zero
        return tuple(next(computed) if want else None for want in asked.inputs)

    operation.defvjp(forward, backward, symbolic_zeros=True)
    return operation


def eval(material: Mapping[str, Any], wi: Any, wo: Any, **options: Any) -> jax.Array:
    """f(wi, wo) as a JAX array ``(..., 3)``, differentiable in the parameters and the directions.

    ``material``: a mapping of parameter names to arrays or numbers (the others
    take their defaults). Parameters and directions broadcast as in
    :func:`principled_brdf.eval`. ``options``: ``model``, ``cosine``, ``mode``
    (static: not traced). The computation runs in float64 (the reference) when
    ``wi`` is float64, else in float32 (the SIMD kernels); parameters are cast to
    that dtype. JAX arrays must be float32 or float64. Shapes, dtypes, options and
    the values known when the call is traced are checked then, as pb.eval checks
    them; traced values when the callback runs (docs/interop.md).
    """
    if not hasattr(material, "items"):
        raise TypeError(f"material: expected a mapping of parameter names to arrays, got {type(material).__name__}")
    names = _interop.parameter_names(material)
    options = _static_options(options)
    wi, wo = _direction("wi", wi), _direction("wo", wo)
    values = [_parameter(name, material[name]) for name in names]
    leading = _interop.leading_shape(names, [np.shape(v) for v in values], np.shape(wi), np.shape(wo))
    dtype = _precision(wi)
    _check_concrete(names, values, wi, wo, options, dtype == np.float32)
    rank = len(leading)
    arrays = [_aligned(jnp.asarray(v, dtype), rank, 1 if n == "base_color" else 0) for n, v in zip(names, values)]
    operation = _operation(tuple(names), tuple(sorted(options.items())))
    return operation(_aligned(jnp.asarray(wi, dtype), rank, 1), _aligned(jnp.asarray(wo, dtype), rank, 1), *arrays)
