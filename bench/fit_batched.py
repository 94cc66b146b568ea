"""The batched solver of pb.fit: one iteration (the normal equations of every
problem, one pass of the kernels) against one eval pass over the same pairs,
and whole fits of textures of texels (every parameter, the default log loss,
synthetic measurements of the model with 2 % noise), with the instruction set.

    python3 bench/fit_batched.py [--texels 64] [--pairs 512] [--repeats 5] [--threads 2]
        [--eval-subsets]

``--texels T`` fits T x T texels; the 1024² texture of docs/fitting.md is
measured as a slice (e.g. ``--texels 128 --pairs 256``) and extrapolated by
the texel count. ``--eval-subsets`` times eval_grad with one column, a few,
all 13 and the six direction components, and eval_vjp (and the directions'
product), against eval in cache (``--subset-pairs`` a call).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import principled_brdf as pb
from principled_brdf import _core, _derivatives
from principled_brdf._gradient import GRADIENT_NAMES


def unit(rng: np.random.Generator, n: int) -> np.ndarray:
    v = rng.normal(size=(n, 3))
    v[:, 2] = np.abs(v[:, 2]) + 0.05
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def best_of(repeats: int, call) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return min(times)


def texture(rng: np.random.Generator, count: int) -> pb.Material:
    return pb.Material(base_color=rng.uniform(0.05, 0.9, (count, 1, 3)), metallic=rng.uniform(0, 1, (count, 1)),
                       roughness=rng.uniform(0.1, 0.9, (count, 1)), specular=rng.uniform(0.2, 0.8, (count, 1)),
                       sheen=rng.uniform(0, 0.5, (count, 1)), clearcoat=rng.uniform(0, 0.5, (count, 1)))


def eval_subsets(repeats: int, threads: int, pairs: int) -> None:
    rng = np.random.default_rng(2)
    n = pairs
    wi, wo = unit(rng, n).astype(np.float32), unit(rng, n).astype(np.float32)
    m = pb.Material(base_color=(0.7, 0.4, 0.2), roughness=0.4, metallic=0.3, sheen=0.2, clearcoat=0.3)
    inner = max(1, (1 << 20) // n)
    f = np.empty((n, 3), np.float32)  # outputs allocated once: the kernels' time, not the page faults'
    base = best_of(repeats, lambda: [pb.eval(m, wi, wo, threads=threads, out=f) for _ in range(inner)])
    print(f"eval_grad / eval at {n} pairs in cache, uniform material ({threads} threads, out= preallocated):")
    every = list(GRADIENT_NAMES) + list(pb.DIRECTION_NAMES)
    for wrt in (["roughness"], ["clearcoat_gloss"], ["base_color"], ["base_color", "roughness", "metallic"], None,
                ["wi", "wo"], every):
        columns = len(GRADIENT_NAMES) if wrt is None else len(pb.eval_grad(m, wi[:1], wo[:1], wrt=wrt).names)
        jacobian = np.empty((n, 3, columns), np.float32)
        t = best_of(repeats, lambda: [pb.eval_grad(m, wi, wo, wrt=wrt, threads=threads, out=(f, jacobian))
                                      for _ in range(inner)])
        label = "all 13" if wrt is None else "all 19 (13 slots, 6 directions)" if wrt is every else ", ".join(wrt)
        print(f"  {label:40s} {base / t:.2f}x  ({n * inner / t / 1e6:.1f} M pairs/s)")
    g = rng.normal(size=(n, 3)).astype(np.float32)
    for wrt in (["roughness"], None):
        t = best_of(repeats, lambda: [pb.eval_vjp(m, wi, wo, g, wrt=wrt, threads=threads) for _ in range(inner)])
        label = "eval_vjp " + ("all 13" if wrt is None else ", ".join(wrt))
        print(f"  {label:40s} {base / t:.2f}x  ({n * inner / t / 1e6:.1f} M pairs/s)")
    # the directions' product, as principled_brdf.torch and .jax call it in their backward passes
    t = best_of(repeats, lambda: [_derivatives.direction_vjp(m, wi, wo, g, threads=threads) for _ in range(inner)])
    print(f"  {'direction vjp (wi, wo)':40s} {base / t:.2f}x  ({n * inner / t / 1e6:.1f} M pairs/s)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--texels", type=int, default=64)
    parser.add_argument("--pairs", type=int, default=512)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--eval-subsets", action="store_true")
    parser.add_argument("--fit-only", action="store_true",
                        help="only the whole fit (a 1024² texture: the per-element eval beside one iteration "
                             "would hold every texel's parameters for every pair)")
    parser.add_argument("--subset-pairs", type=int, default=16384,
                        help="pairs a call for --eval-subsets (in L2; large enough that the call's Python "
                             "overhead is small)")
    args = parser.parse_args()
    print(f"instruction set {pb.cpu_info()['isa']}, {args.threads} threads")
    if args.eval_subsets:
        eval_subsets(args.repeats, args.threads, args.subset_pairs)
    rng = np.random.default_rng(1)
    count, n = args.texels * args.texels, args.pairs
    wi, wo = unit(rng, n), unit(rng, n)
    truth = texture(rng, count)
    measured = pb.eval(truth, wi.astype(np.float32), wo.astype(np.float32)).astype(np.float64)
    measured *= rng.lognormal(0.0, 0.02, measured.shape)
    pairs = count * n
    print(f"{args.texels} x {args.texels} texels x {n} pairs = {pairs / 1e6:.1f} M pairs")

    if not args.fit_only:
        one_iteration(wi, wo, truth, measured, args.repeats, args.threads)
    whole_fit(wi, wo, measured, args.threads)


def one_iteration(wi, wo, truth, measured, repeats: int, threads: int) -> None:
    """The normal equations of every problem, every parameter, against one eval pass."""
    count, n = len(truth.roughness), len(wi)
    pairs = count * n
    wi32, wo32 = wi.astype(np.float32), wo.astype(np.float32)
    start = pb.Material().packed(()).reshape(-1)[:len(GRADIENT_NAMES)]  # the fitted models' slots
    slots = np.ascontiguousarray(np.broadcast_to(start, (count, start.size)), dtype=np.float32)
    target = np.log1p(measured * np.maximum(wi[:, 2], 0)[:, None]).astype(np.float32)
    scale = np.ones_like(target)
    gain = np.ones(count, np.float32)
    problems = np.arange(count, dtype=np.int64)
    every = list(range(len(GRADIENT_NAMES)))
    equations = best_of(repeats, lambda: _core.normal_equations(
        wi=wi32, wo=wo32, slots=slots, target=target, scale=scale, gain=gain, problems=problems, columns=every, loss=1,
        cosine=True, model=0, threads=threads))
    textured = pb.Material(**{name: np.broadcast_to(getattr(truth, name), (count, n, 3) if name == "base_color"
                              else (count, n)) for name in pb.PARAMETERS})
    pb.eval(textured, wi32, wo32, threads=threads)  # (a first call, not timed)
    per_element = best_of(repeats, lambda: pb.eval(textured, wi32, wo32, threads=threads))
    uniform = best_of(repeats, lambda: pb.eval(pb.Material(roughness=0.4, clearcoat=0.2, sheen=0.2),
                                               np.broadcast_to(wi32, (count, n, 3)),
                                               np.broadcast_to(wo32, (count, n, 3)), threads=threads))
    print(f"one iteration (13 parameters): {equations * 1e3:.1f} ms, {pairs / equations / 1e6:.1f} M pairs/s; "
          f"eval per-element material {per_element * 1e3:.1f} ms ({equations / per_element:.2f}x), "
          f"uniform material {uniform * 1e3:.1f} ms ({equations / uniform:.2f}x)")
    for columns, label in (([GRADIENT_NAMES.index("roughness")], "roughness"), ([0, 1, 2, 7], "base_color, roughness")):
        t = best_of(repeats, lambda: _core.normal_equations(
            wi=wi32, wo=wo32, slots=slots, target=target, scale=scale, gain=gain, problems=problems, columns=columns,
            loss=1, cosine=True, model=0, threads=threads))
        print(f"one iteration ({label}): {t * 1e3:.1f} ms ({t / per_element:.2f}x the per-element eval)")


def whole_fit(wi, wo, measured, threads: int) -> None:
    """pb.fit with its defaults, every texel."""
    count, n = measured.shape[0], len(wi)
    start = time.perf_counter()
    result = pb.fit(wi, wo, measured, threads=threads)
    elapsed = time.perf_counter() - start
    iterations = result.iterations
    print(f"fit of {len(result.names)} parameters: {elapsed:.2f} s, "
          f"{elapsed / count * 1e3:.3f} ms a texel; iterations median {int(np.median(iterations))}, "
          f"max {int(iterations.max())}; converged {int(result.success.sum())} of {count}")
    print(f"  extrapolated to 1024 x 1024 texels x {n} pairs: {elapsed * (1024 * 1024) / count / 60:.1f} min")


if __name__ == "__main__":
    main()
