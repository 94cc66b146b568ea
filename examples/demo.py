"""The README's main job: evaluate millions of direction pairs with the SIMD
kernel, print the throughput beside the memory roofline and the float64
reference, check a sample against the reference, and write a picture.

    python examples/demo.py [--pairs 4194304] [--output principled_brdf_demo.png]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import principled_brdf as pb
from principled_brdf import _core
from principled_brdf.render import render_sphere, to_srgb8


def random_pairs(n: int, seed: int = 7):
    rng = np.random.default_rng(seed)

    def hemisphere():
        v = rng.normal(size=(n, 3)).astype(np.float32)
        v[:, 2] = np.abs(v[:, 2]) + 1e-3
        return v / np.linalg.norm(v, axis=1, keepdims=True)

    return hemisphere(), hemisphere()


def best_seconds(fn, repeats: int = 5) -> float:
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return min(times)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=1 << 22)
    parser.add_argument("--output", default="principled_brdf_demo.png")
    args = parser.parse_args(argv)

    info = pb.cpu_info()
    print(f"principled-brdf {pb.__version__}: {info['isa']} ({info['float_lanes']} float lanes), "
          f"{info['threads']} threads")
    material = pb.Material(base_color=(0.9, 0.55, 0.25), metallic=0.3, roughness=0.35, anisotropic=0.4,
                           sheen=0.3, clearcoat=0.6, clearcoat_gloss=0.8)
    n = args.pairs
    wi, wo = random_pairs(n)
    out = np.empty_like(wi)

    eval_s = best_seconds(lambda: pb.eval(material, wi, wo, out=out, check=False))
    checked_s = best_seconds(lambda: pb.eval(material, wi, wo))
    roofline_s = best_seconds(lambda: _core.memory_roofline(wi, wo, out, 0))
    subset = 100_000
    reference_s = best_seconds(lambda: pb.reference.eval(material, wi[:subset], wo[:subset]), repeats=2) * n / subset
    gigabytes = 36 * n / 1e9  # wi, wo read, f written: 12 bytes each per pair

    print(f"\nevaluating f(wi, wo) for {n:,} pairs (RGB float32):")
    rows = [
        ("SIMD eval", eval_s),
        ("SIMD eval, checked, fresh output", checked_s),
        ("memory roofline (same bytes, copy)", roofline_s),
        ("float64 reference", reference_s),
    ]
    for name, seconds in rows:
        print(f"  {name:<36} {n / seconds / 1e6:9.1f} M pairs/s  {gigabytes / seconds:6.1f} GB/s"
              f"  {roofline_s / seconds:6.2f}x roofline")

    f = pb.eval(material, wi[:subset], wo[:subset])
    ref = pb.reference.eval(material, wi[:subset].astype(np.float64), wo[:subset].astype(np.float64))
    error = np.max(np.abs(f - ref) / np.maximum(np.abs(ref), 1e-6))
    print(f"\nmax relative error vs the float64 reference on {subset:,} pairs: {error:.2e}")

    roughness = np.linspace(0.05, 1.0, 6)
    spheres = [render_sphere(pb.Material(base_color=(0.9, 0.55, 0.25), metallic=metallic, roughness=r,
                                         clearcoat=0.5 * (1 - metallic)), resolution=160)
               for metallic in (0.0, 1.0) for r in roughness]
    rows_of_spheres = [np.concatenate(spheres[i * 6:(i + 1) * 6], axis=1) for i in range(2)]
    image = to_srgb8(np.concatenate(rows_of_spheres, axis=0))
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plt.imsave(args.output, image)
    print(f"wrote {args.output}: dielectric (top) and metal (bottom), roughness "
          f"{roughness[0]:.2f} to {roughness[-1]:.2f} left to right")


if __name__ == "__main__":
    main()
