"""Recover a roughness texture and a base_color texture from rendered
observations, by gradient descent through the library's kernels: once with
PyTorch's Adam (principled_brdf.torch), once with JAX (principled_brdf.jax).

Each texel is seen under the same K light/view pairs; the observations are the
float64 reference's f times cos θl. The unknowns live in unconstrained
variables mapped into the parameters' domains by a sigmoid.

    python examples/inverse_rendering.py            # both frameworks, a picture in inverse_rendering.png
"""

from __future__ import annotations

import sys
from typing import NamedTuple

import numpy as np

import principled_brdf as pb


class Problem(NamedTuple):
    wi: np.ndarray  # (K, 1, 1, 3) float32
    wo: np.ndarray  # (K, 1, 1, 3) float32
    observed: np.ndarray  # (K, H, W, 3) float32
    roughness: np.ndarray  # (H, W) the truth
    base_color: np.ndarray  # (H, W, 3) the truth


def problem(size: int = 24, pairs: int = 32, seed: int = 1) -> Problem:
    """A smooth roughness texture and a colour pattern, observed under ``pairs`` directions."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:size, 0:size] / (size - 1)
    roughness = 0.2 + 0.5 * (0.5 + 0.5 * np.sin(2.5 * np.pi * x) * np.cos(1.5 * np.pi * y))
    base_color = np.stack([0.2 + 0.6 * x, 0.3 + 0.4 * y, 0.7 - 0.5 * x * y], axis=-1)
    # views spread over the hemisphere; half of the lights near the mirror direction (the highlight fixes roughness)
    wo = pb.frames.spherical_to_direction(rng.uniform(0.0, 1.2, pairs), rng.uniform(0, 2 * np.pi, pairs))
    mirror = wo * np.float64([-1, -1, 1])
    scattered = pb.frames.spherical_to_direction(rng.uniform(0.0, 1.3, pairs), rng.uniform(0, 2 * np.pi, pairs))
    near = mirror + 0.25 * rng.normal(size=(pairs, 3))
    near[:, 2] = np.abs(near[:, 2]) + 0.1
    wi = np.where(np.arange(pairs)[:, None] % 2 == 0, scattered, near)
    wi /= np.linalg.norm(wi, axis=-1, keepdims=True)
    wi, wo = (w[:, None, None, :] for w in (wi, wo))
    truth = pb.Material(roughness=roughness, base_color=base_color)
    observed = pb.reference.eval(truth, wi, wo, cosine=True)
    return Problem(wi.astype(np.float32), wo.astype(np.float32), observed.astype(np.float32), roughness, base_color)


def _logit(p: np.ndarray) -> np.ndarray:
    return np.log(p / (1 - p))


START_ROUGHNESS, START_COLOR = 0.5, 0.5  # every texel starts here


def recover_torch(p: Problem, steps: int = 300, rate: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    import torch

    from principled_brdf import torch as pbt

    shape = p.roughness.shape
    x = torch.full(shape, float(_logit(np.float64(START_ROUGHNESS))), requires_grad=True)
    y = torch.full(shape + (3,), float(_logit(np.float64(START_COLOR))), requires_grad=True)
    wi, wo, observed = (torch.from_numpy(a) for a in (p.wi, p.wo, p.observed))
    target = torch.log1p(observed)
    optimizer = torch.optim.Adam([x, y], lr=rate)
    for _ in range(steps):
        optimizer.zero_grad()
        f = pbt.eval({"roughness": torch.sigmoid(x), "base_color": torch.sigmoid(y)}, wi, wo, cosine=True)
        loss = torch.mean((torch.log1p(f) - target) ** 2)
        loss.backward()
        optimizer.step()
    return torch.sigmoid(x).detach().numpy(), torch.sigmoid(y).detach().numpy()


def recover_jax(p: Problem, steps: int = 300, rate: float = 0.1) -> tuple[np.ndarray, np.ndarray]:
    import jax
    import jax.numpy as jnp

    from principled_brdf import jax as pbj

    target = jnp.log1p(p.observed)

    def loss(variables):
        x, y = variables
        f = pbj.eval({"roughness": jax.nn.sigmoid(x), "base_color": jax.nn.sigmoid(y)}, p.wi, p.wo, cosine=True)
        return jnp.mean((jnp.log1p(f) - target) ** 2)

    @jax.jit
    def adam_step(state, step):
        """Adam (Kingma & Ba 2015) with β1 0.9, β2 0.999, ε 1e-8."""
        variables, first, second = state
        grads = jax.grad(loss)(variables)
        first = jax.tree.map(lambda m, g: 0.9 * m + 0.1 * g, first, grads)
        second = jax.tree.map(lambda v, g: 0.999 * v + 0.001 * g * g, second, grads)
        t = step + 1.0
        variables = jax.tree.map(lambda w, m, v: w - rate * (m / (1 - 0.9 ** t)) / (jnp.sqrt(v / (1 - 0.999 ** t)) + 1e-8),
                                 variables, first, second)
        return (variables, first, second), None

    shape = p.roughness.shape
    variables = (jnp.full(shape, _logit(START_ROUGHNESS), jnp.float32),
                 jnp.full(shape + (3,), _logit(START_COLOR), jnp.float32))
    zeros = jax.tree.map(jnp.zeros_like, variables)
    (variables, _, _), _ = jax.lax.scan(adam_step, (variables, zeros, zeros), jnp.arange(steps, dtype=jnp.float32))
    x, y = variables
    return np.asarray(jax.nn.sigmoid(x)), np.asarray(jax.nn.sigmoid(y))


def errors(p: Problem, roughness: np.ndarray, base_color: np.ndarray) -> tuple[float, float]:
    """The largest absolute error of each texture."""
    return float(np.abs(roughness - p.roughness).max()), float(np.abs(base_color - p.base_color).max())


def main() -> None:
    p = problem()
    results = {}
    for name, recover in (("PyTorch", recover_torch), ("JAX", recover_jax)):
        results[name] = recover(p)
        r_error, c_error = errors(p, *results[name])
        print(f"{name}: largest error roughness {r_error:.4f}, base_color {c_error:.4f}")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(2, 3, figsize=(9, 6), constrained_layout=True)
    for column, (title, (roughness, color)) in enumerate([("truth", (p.roughness, p.base_color))] + list(results.items())):
        axes[0, column].imshow(roughness, vmin=0, vmax=1, cmap="gray")
        axes[1, column].imshow(pb.linear_to_srgb(np.clip(color, 0, 1)))
        axes[0, column].set_title(f"{title}: roughness")
        axes[1, column].set_title(f"{title}: base_color")
    for axis in axes.flat:
        axis.set_axis_off()
    out = sys.argv[1] if len(sys.argv) > 1 else "inverse_rendering.png"
    figure.savefig(out, dpi=100)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
