"""The kernels as JAX operations on CPU arrays (docs/interop.md).

``eval`` is a ``jax.custom_vjp`` function over host callbacks
(``jax.pure_callback``): it runs under ``jit`` and ``vmap``, and its backward
pass is the library's vector-Jacobian product, in the parameters and in
``wi`` and ``wo``. float32 inputs go through the
SIMD kernels; float64 inputs (with ``jax_enable_x64``) through the float64
reference.

    import jax, jax.numpy as jnp
    from principled_brdf import jax as pbj
    loss = lambda r: jnp.sum(pbj.eval({"roughness": r}, wi, wo))
    jax.grad(loss)(jnp.float32(0.5))
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING, Any

import numpy as np

try:
    import jax
    import jax.numpy as jnp
except ImportError as error:  # pragma: no cover - the test extra installs jax
    raise ImportError("principled_brdf.jax needs JAX: pip install 'principled-brdf[jax]'") from error

from . import _interop

if TYPE_CHECKING:
    from collections.abc import Mapping

__all__ = ["eval"]


def _aligned(array: jax.Array, rank: int, trailing: int) -> jax.Array:
    """``array`` with leading 1s up to ``rank`` leading axes (plus ``trailing``), so that
    every argument of the callback has one rank and ``vmap`` adds its axes alike."""
    return jnp.reshape(array, (1,) * (rank + trailing - array.ndim) + array.shape)


@functools.lru_cache(maxsize=None)
def _operation(names: tuple[str, ...], options: tuple[tuple[str, Any], ...]) -> Any:
    """The custom_vjp function of (wi, wo, *values) for one set of parameter names and options."""
    keywords = dict(options)
    names_list = list(names)

    def host_eval(wi: np.ndarray, wo: np.ndarray, *values: np.ndarray) -> np.ndarray:
        double = wi.dtype == np.float64
        f = _interop.evaluate(names_list, [np.asarray(v) for v in values], np.asarray(wi), np.asarray(wo), double,
                              keywords)
        return f.astype(wi.dtype, copy=False)

    def host_vjp(rank: int, wi: np.ndarray, wo: np.ndarray, cotangent: np.ndarray,
                 *values: np.ndarray) -> tuple[np.ndarray, ...]:
        double = wi.dtype == np.float64
        arrays = [np.asarray(v) for v in values]
        # vmap's axes lead every argument (1 where one is not mapped); each gradient has all of them
        k = wi.ndim - 1 - rank
        mapped = np.broadcast_shapes(*(a.shape[:k] for a in (wi, wo, cotangent, *arrays)))
        shapes = [mapped + v.shape[len(mapped):] for v in arrays]
        gradients = _interop.vjp(names_list, arrays, np.asarray(wi), np.asarray(wo), np.asarray(cotangent),
                                 [True] * len(arrays), double, keywords, shapes)
        by_wi, by_wo = _interop.direction_vjp(names_list, arrays, np.asarray(wi), np.asarray(wo), np.asarray(cotangent),
                                              double, keywords, (mapped + wi.shape[k:], mapped + wo.shape[k:]))
        return (np.asarray(by_wi, wi.dtype), np.asarray(by_wo, wo.dtype),
                *(np.asarray(g, dtype=v.dtype) for g, v in zip(gradients, arrays)))

    def value_shape(wi: jax.Array, wo: jax.Array, values: tuple[jax.Array, ...]) -> jax.ShapeDtypeStruct:
        leading = jnp.broadcast_shapes(wi.shape[:-1], wo.shape[:-1],
                                       *(v.shape[:-1] if n == "base_color" else v.shape for n, v in zip(names, values)))
        return jax.ShapeDtypeStruct(leading + (3,), wi.dtype)  # type: ignore[no-untyped-call]

    @jax.custom_vjp
    def operation(wi: jax.Array, wo: jax.Array, *values: jax.Array) -> jax.Array:
        return jax.pure_callback(host_eval, value_shape(wi, wo, values), wi, wo, *values, vmap_method="expand_dims")

    def forward(wi: jax.Array, wo: jax.Array, *values: jax.Array) -> tuple[jax.Array, tuple[jax.Array, ...]]:
        return operation(wi, wo, *values), (wi, wo, *values)

    def backward(residuals: tuple[jax.Array, ...], cotangent: jax.Array) -> tuple[Any, ...]:
        wi, wo, *values = residuals
        shapes = tuple(jax.ShapeDtypeStruct(v.shape, v.dtype) for v in (wi, wo, *values))  # type: ignore[no-untyped-call]
        # the directions' derivatives in the 3-vectors as given (docs/gradients.md)
        return tuple(jax.pure_callback(functools.partial(host_vjp, cotangent.ndim - 1), shapes, wi, wo, cotangent,
                                       *values, vmap_method="expand_dims"))

    operation.defvjp(forward, backward)
    return operation


def eval(material: Mapping[str, Any], wi: Any, wo: Any, **options: Any) -> jax.Array:
    """f(wi, wo) as a JAX array ``(..., 3)``, differentiable in the parameters.

    ``material``: a mapping of parameter names to arrays or numbers (the others
    take their defaults). Parameters and directions broadcast as in
    :func:`principled_brdf.eval`. ``options``: ``model``, ``cosine``, ``mode``. The
    computation runs in float64 (the reference) when ``wi`` is float64, else in
    float32 (the SIMD kernels); parameters are cast to that dtype.
    """
    if not hasattr(material, "items"):
        raise TypeError(f"material: expected a mapping of parameter names to arrays, got {type(material).__name__}")
    names = _interop.parameter_names(material)
    options = _interop.check_options(options)
    wi, wo = jnp.asarray(wi), jnp.asarray(wo)
    dtype = jnp.float64 if wi.dtype == jnp.float64 else jnp.float32
    wi, wo = wi.astype(dtype), wo.astype(dtype)
    values = [jnp.asarray(material[name], dtype) for name in names]
    rank = _interop.leading_rank(names, values, wi, wo)  # type: ignore[arg-type]
    values = [_aligned(v, rank, 1 if n == "base_color" else 0) for n, v in zip(names, values)]
    operation = _operation(tuple(names), tuple(sorted(options.items())))
    return operation(_aligned(wi, rank, 1), _aligned(wo, rank, 1), *values)
