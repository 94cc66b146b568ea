"""Speed of the library's PyTorch and JAX operations (principled_brdf.torch,
principled_brdf.jax) beside the same BRDF written natively in each framework
(bench/native_torch.py, bench/native_jax.py), and pb.eval / pb.eval_grad from numpy.

Pairs/s per call size, forward and backward; the backward passes are the
gradient of sum(f) in a per-element roughness and base_color (the other
parameters one value each: every lobe on, principled_brdf.benchmark.MATERIAL).
Each cell is the best of --repeats repetitions of enough calls to last
--min-time seconds; JAX results are waited for (block_until_ready). The
native versions are checked against pb.reference first (bench/native_check.py).

    python bench/interop_speed.py [--sizes 16,256,4096,65536,1048576] [--threads 2] [--torch-threads 1,2]
"""

from __future__ import annotations

import argparse
import time
from typing import Any, Callable

import jax
import jax.numpy as jnp
import numpy as np
import torch

import native_check
import native_jax
import native_model
import native_torch
import principled_brdf as pb
from principled_brdf import jax as pbj
from principled_brdf import torch as pbt
from principled_brdf.benchmark import MATERIAL


def inputs(n: int, seed: int = 3) -> dict[str, Any]:
    """Pairs, and the benchmark material with a per-element roughness and base_color, as numpy float32."""
    rng = np.random.default_rng(seed)
    wi, wo = native_check.hemisphere(rng, n, 0.05), native_check.hemisphere(rng, n, 0.05)
    material = {name: np.float32(value) for name, value in MATERIAL.items() if name != "base_color"}
    material["roughness"] = rng.uniform(0.2, 0.8, n).astype(np.float32)
    material["base_color"] = rng.uniform(0.1, 0.9, (n, 3)).astype(np.float32)
    return {"wi": wi, "wo": wo, "material": material}


def numpy_calls(x: dict[str, Any]) -> dict[str, Callable[[], Any]]:
    material = pb.Material(**x["material"])
    return {"pb.eval (numpy)": lambda: pb.eval(material, x["wi"], x["wo"]),
            "pb.eval_grad (numpy, 13 slots)": lambda: pb.eval_grad(material, x["wi"], x["wo"])}


def torch_calls(x: dict[str, Any]) -> dict[str, Callable[[], Any]]:
    wi, wo = torch.from_numpy(x["wi"]), torch.from_numpy(x["wo"])
    constant = {k: torch.from_numpy(np.asarray(v)) for k, v in x["material"].items()}
    wanted = {k: constant[k].clone().requires_grad_() for k in native_check.BACKWARD}
    material = {**constant, **wanted}

    def backward(evaluate: Callable[..., torch.Tensor]) -> Callable[[], Any]:
        def call() -> None:
            for v in wanted.values():
                v.grad = None
            evaluate(material, wi, wo).sum().backward()
        return call

    return {"pbt.eval forward": lambda: pbt.eval(constant, wi, wo),
            "native torch forward": lambda: native_torch.eval(constant, wi, wo),
            "pbt.eval forward+backward": backward(pbt.eval),
            "native torch forward+backward": backward(native_torch.eval)}


def jax_calls(x: dict[str, Any]) -> dict[str, Callable[[], Any]]:
    wi, wo = jnp.asarray(x["wi"]), jnp.asarray(x["wo"])
    material = native_jax.as_material(x["material"])
    wanted = {k: material[k] for k in native_check.BACKWARD}
    fixed = {k: v for k, v in material.items() if k not in wanted}
    slots = jnp.concatenate([material["base_color"]] + [jnp.broadcast_to(material[s], wi.shape[:1])[:, None]
                                                         for s in native_model.SLOTS[3:]], axis=-1)

    def library_sum(wanted: dict[str, jax.Array], fixed: dict[str, jax.Array], wi: jax.Array,
                    wo: jax.Array) -> jax.Array:
        return jnp.sum(pbj.eval({**fixed, **wanted}, wi, wo))

    library_eval = jax.jit(lambda m, wi, wo: pbj.eval(m, wi, wo))
    library_grad = jax.jit(jax.grad(library_sum))
    return {"pbj.eval jit forward": lambda: library_eval(material, wi, wo).block_until_ready(),
            "native JAX jit forward": lambda: native_jax.eval(material, wi, wo).block_until_ready(),
            "pbj.eval jit(grad)": lambda: jax.block_until_ready(library_grad(wanted, fixed, wi, wo)),
            "native JAX jit(grad)": lambda: jax.block_until_ready(native_jax.grad_sum(wanted, fixed, wi, wo)),
            "native JAX jit(vmap(jacfwd)), 13 slots": lambda: native_jax.jacobian(slots, wi, wo).block_until_ready()}


def seconds_per_call(call: Callable[[], Any], repeats: int, min_time: float) -> float:
    """The best of ``repeats`` runs of enough calls to last ``min_time``, per call."""
    call()  # compilation, caches
    start, number = time.perf_counter(), 1
    call()
    once = time.perf_counter() - start
    number = max(1, int(min_time / max(once, 1e-7)))
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        for _ in range(number):
            call()
        best = min(best, (time.perf_counter() - start) / number)
    return best


def measure(sizes: list[int], repeats: int, min_time: float) -> dict[str, dict[int, float]]:
    """Seconds per call, by operation and size."""
    table: dict[str, dict[int, float]] = {}
    for n in sizes:
        x = inputs(n)
        for calls in (numpy_calls(x), torch_calls(x), jax_calls(x)):
            for name, call in calls.items():
                table.setdefault(name, {})[n] = seconds_per_call(call, repeats, min_time)
        print(f"  {n:,} pairs done", flush=True)
    return table


def print_table(table: dict[str, dict[int, float]], sizes: list[int]) -> None:
    print("| operation | " + " | ".join(f"{n:,}" for n in sizes) + " | µs a call at 16 |")
    print("|---|" + "---:|" * (len(sizes) + 1))
    for name, row in table.items():
        cells = [f"{n / row[n] / 1e6:.3g}" for n in sizes]
        small = f"{row[16] * 1e6:.0f}" if 16 in row else "—"
        print(f"| {name} | " + " | ".join(cells) + f" | {small} |")


RATIOS = [("torch forward: pbt / native", "pbt.eval forward", "native torch forward"),
          ("torch forward+backward: pbt / native", "pbt.eval forward+backward", "native torch forward+backward"),
          ("JAX forward: pbj / native", "pbj.eval jit forward", "native JAX jit forward"),
          ("JAX backward: pbj / native", "pbj.eval jit(grad)", "native JAX jit(grad)"),
          ("13-slot Jacobian: pb.eval_grad / jacfwd", "pb.eval_grad (numpy, 13 slots)",
           "native JAX jit(vmap(jacfwd)), 13 slots"),
          ("pbt forward / pb.eval", "pbt.eval forward", "pb.eval (numpy)"),
          ("pbj forward / pb.eval", "pbj.eval jit forward", "pb.eval (numpy)")]


def print_ratios(table: dict[str, dict[int, float]], sizes: list[int]) -> None:
    print("\n| speed ratio | " + " | ".join(f"{n:,}" for n in sizes) + " |")
    print("|---|" + "---:|" * len(sizes))
    for label, faster, slower in RATIOS:
        print(f"| {label} | " + " | ".join(f"{table[slower][n] / table[faster][n]:.2g}x" for n in sizes) + " |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="16,256,4096,65536,1048576")
    parser.add_argument("--threads", type=int, default=2, help="torch.set_num_threads (default 2; the library uses every core: 2 here)")
    parser.add_argument("--torch-threads", default="",
                        help="also time the torch rows with these torch.set_num_threads values, e.g. 1,2")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--min-time", type=float, default=0.05)
    args = parser.parse_args()
    sizes = [int(s) for s in args.sizes.split(",")]

    native_check.check_torch()
    native_check.check_jax()
    torch.set_num_threads(args.threads)
    info = pb.cpu_info()
    print(f"{info['isa']}, library threads {info['threads']}, torch threads {torch.get_num_threads()}, "
          f"torch {torch.__version__}, jax {jax.__version__} ({jax.devices()[0].platform}); M pairs/s, best of "
          f"{args.repeats}")
    table = measure(sizes, args.repeats, args.min_time)
    print_table(table, sizes)
    print_ratios(table, sizes)

    for threads in [int(t) for t in args.torch_threads.split(",") if t]:
        torch.set_num_threads(threads)
        print(f"\ntorch.set_num_threads({threads}): M pairs/s")
        print("| operation | " + " | ".join(f"{n:,}" for n in sizes) + " |")
        print("|---|" + "---:|" * len(sizes))
        rows: dict[str, dict[int, float]] = {}
        for n in sizes:
            for name, call in torch_calls(inputs(n)).items():
                rows.setdefault(name, {})[n] = seconds_per_call(call, args.repeats, args.min_time)
        for name, row in rows.items():
            print(f"| {name} | " + " | ".join(f"{n / row[n] / 1e6:.3g}" for n in sizes) + " |")


if __name__ == "__main__":
    main()
