"""The Disney 2014 BRDF (bench/native_model.py) in jax.numpy, float32, jitted:
``eval`` for f, ``jacobian`` for its Jacobian in the 13 parameter slots by
``jax.jacfwd`` (one pair at a time under ``vmap``, as pb.eval_grad returns it),
and ``grad_sum`` for the gradient of ``sum(f)`` by ``jax.grad`` (a backward pass).
"""

from __future__ import annotations

from typing import Any

import jax
import jax.numpy as jnp

import native_model

OPS = native_model.Ops(sqrt=jnp.sqrt, log=jnp.log, where=jnp.where, clip01=lambda x: jnp.clip(x, 0.0, 1.0),
                       at_least=jnp.maximum)


def as_material(material: dict[str, Any]) -> dict[str, jax.Array]:
    """Every parameter as a float32 array (numbers as 0-d arrays)."""
    return {name: jnp.asarray(value, jnp.float32) for name, value in material.items()}


@jax.jit
def eval(material: dict[str, jax.Array], wi: jax.Array, wo: jax.Array) -> jax.Array:
    """f ``(N, 3)``; ``material`` holds all 11 parameters (as_material)."""
    return native_model.f(OPS, material, wi, wo)


def _f_of_slots(slots: jax.Array, wi: jax.Array, wo: jax.Array) -> jax.Array:
    return native_model.f(OPS, native_model.material_of_slots(slots), wi, wo)


@jax.jit
def jacobian(slots: jax.Array, wi: jax.Array, wo: jax.Array) -> jax.Array:
    """∂f_c/∂slot_k ``(N, 3, 13)`` for per-element slots ``(N, 13)`` (native_model.SLOTS)."""
    return jax.vmap(jax.jacfwd(_f_of_slots))(slots, wi, wo)


def _sum_f(wanted: dict[str, jax.Array], fixed: dict[str, jax.Array], wi: jax.Array, wo: jax.Array) -> jax.Array:
    return jnp.sum(native_model.f(OPS, {**fixed, **wanted}, wi, wo))


# grad_sum(wanted, fixed, wi, wo): the gradient of sum(f) with respect to the parameters in ``wanted``
grad_sum = jax.jit(jax.grad(_sum_f))
