"""Checks of the native PyTorch and JAX versions (native_torch.py, native_jax.py)
against the library's float64 reference: f on random pairs and materials, and
the derivatives in the 13 parameter slots (jax.jacfwd; torch's and JAX's
backward passes). bench/interop_speed.py runs them before timing, and
tests/interop/test_native_versions_agree.py in the test suite.
"""

from __future__ import annotations

from typing import Any

import numpy as np

import native_model
import principled_brdf as pb

# float32 against float64: the native versions reach 1.3e-5 relative down to cos θ = 1e-4
VALUE_RTOL = 1e-4
# derivatives, relative to the largest of their column (a slot's derivative over the pairs)
GRADIENT_RTOL = 1e-4
# the parameters given per element and differentiated in the timed backward passes
BACKWARD = ("base_color", "roughness")
BACKWARD_SLOTS = [0, 1, 2, native_model.SLOTS.index("roughness")]


def hemisphere(rng: np.random.Generator, n: int, min_cos: float) -> np.ndarray:
    """``n`` unit float32 directions, uniform in solid angle above cos θ = min_cos."""
    cos = rng.uniform(min_cos, 1.0, n)
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    sin = np.sqrt(1.0 - cos * cos)
    return np.stack([sin * np.cos(phi), sin * np.sin(phi), cos], axis=-1).astype(np.float32)


def random_inputs(seed: int, n: int, interior: bool = False) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray]:
    """A random float32 material a pair (every parameter per element) and the pairs.
    ``interior``: away from the kinks (the alphas' clamp, the horizon), for derivatives."""
    rng = np.random.default_rng(seed)
    low = 0.1 if interior else 0.0
    material = {"base_color": rng.uniform(low, 1.0, (n, 3))}
    for name in native_model.SLOTS[3:]:
        material[name] = rng.uniform(low, 0.9 if interior else 1.0, n)
    if interior:
        material["roughness"] = rng.uniform(0.25, 0.9, n)
    min_cos = 0.2 if interior else 1e-3
    wi, wo = hemisphere(rng, n, min_cos), hemisphere(rng, n, min_cos)
    return {k: v.astype(np.float32) for k, v in material.items()}, wi, wo


def reference(material: dict[str, np.ndarray], wi: np.ndarray, wo: np.ndarray) -> Any:
    """pb.reference.eval_grad (float64) of the float32 inputs: ``value`` and ``jacobian`` (N, 3, 13)."""
    return pb.reference.eval_grad(pb.Material(**material), wi.astype(np.float64), wo.astype(np.float64))


def assert_values(name: str, value: np.ndarray, expected: np.ndarray) -> None:
    error = np.abs(value - expected) / np.maximum(np.abs(expected), 1e-6)
    assert error.max() <= VALUE_RTOL, f"{name}: f differs from pb.reference.eval by {error.max():.2e} relative"


def assert_jacobian(name: str, jacobian: np.ndarray, expected: np.ndarray) -> None:
    """``jacobian`` (..., 13) against ``expected``, each slot relative to its largest value."""
    scale = np.abs(expected).reshape(-1, expected.shape[-1]).max(axis=0)
    error = np.abs(jacobian - expected) / np.maximum(scale, 1e-6)
    assert error.max() <= GRADIENT_RTOL, (f"{name}: derivatives differ from pb.reference.eval_grad by "
                                          f"{error.max():.2e} of their scale")


def contracted(expected: Any) -> np.ndarray:
    """The gradient of sum(f) in each slot, per pair (N, 13), from the reference's Jacobian."""
    return expected.jacobian.sum(axis=1)


def check_jax(seed: int = 7, n: int = 512) -> None:
    import jax.numpy as jnp

    import native_jax

    material, wi, wo = random_inputs(seed, n)
    value = native_jax.eval(native_jax.as_material(material), jnp.asarray(wi), jnp.asarray(wo))
    assert_values("native JAX", np.asarray(value), reference(material, wi, wo).value)

    material, wi, wo = random_inputs(seed + 1, n, interior=True)
    expected = reference(material, wi, wo)
    slots = np.concatenate([material["base_color"], np.stack([material[s] for s in native_model.SLOTS[3:]], axis=-1)],
                           axis=-1)
    jacobian = native_jax.jacobian(jnp.asarray(slots), jnp.asarray(wi), jnp.asarray(wo))
    assert_jacobian("native JAX jacfwd", np.asarray(jacobian), expected.jacobian)
    # the backward pass the benchmark times: per-element base_color and roughness
    m = native_jax.as_material(material)
    wanted = {name: m.pop(name) for name in BACKWARD}
    grad = native_jax.grad_sum(wanted, m, jnp.asarray(wi), jnp.asarray(wo))
    assert_jacobian("native JAX grad", _slots_of(grad), contracted(expected)[:, BACKWARD_SLOTS])


def check_torch(seed: int = 7, n: int = 512) -> None:
    import torch

    import native_torch

    material, wi, wo = random_inputs(seed, n)
    value = native_torch.eval(native_torch.as_material({k: torch.from_numpy(v) for k, v in material.items()}),
                              torch.from_numpy(wi), torch.from_numpy(wo))
    assert_values("native torch", value.numpy(), reference(material, wi, wo).value)

    material, wi, wo = random_inputs(seed + 1, n, interior=True)
    m = {k: torch.from_numpy(v).requires_grad_(k in BACKWARD) for k, v in material.items()}
    native_torch.eval(m, torch.from_numpy(wi), torch.from_numpy(wo)).sum().backward()
    assert_jacobian("native torch backward", _slots_of({k: m[k].grad for k in BACKWARD}),
                    contracted(reference(material, wi, wo))[:, BACKWARD_SLOTS])


def _slots_of(gradients: dict[str, Any]) -> np.ndarray:
    """The gradients of BACKWARD (per element) as one array (N, 4): base_color's three slots, roughness."""
    return np.concatenate([np.asarray(gradients["base_color"]), np.asarray(gradients["roughness"])[:, None]], axis=-1)
