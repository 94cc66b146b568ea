"""A grid of views against a texture, read in place (broadcast), against the same
call on materialised contiguous copies: pairs/s of each and their ratio, one
thread and all threads, interleaved repetitions, the best of each.

    python3 bench/broadcast.py [--repeats 9]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import principled_brdf as pb


def unit(rng: np.random.Generator, shape: tuple[int, ...]) -> np.ndarray:
    v = rng.normal(size=shape + (3,))
    v[..., 2] = np.abs(v[..., 2])
    return (v / np.linalg.norm(v, axis=-1, keepdims=True)).astype(np.float32)


def case(rng: np.random.Generator, texture_shape: tuple[int, ...], views_shape: tuple[int, ...]):
    """(broadcast arguments, materialised ones, leading shape): views against a texture, a light overhead."""
    texture = pb.Material(roughness=rng.uniform(0.05, 1, texture_shape).astype(np.float32),
                          base_color=rng.random(texture_shape + (3,)).astype(np.float32))
    views = unit(rng, views_shape + (1,) * len(texture_shape))
    light = np.float32([0.0, 0.0, 1.0])
    leading = views_shape + texture_shape
    copies = pb.Material(roughness=np.ascontiguousarray(np.broadcast_to(texture.roughness, leading), np.float32),
                         base_color=np.ascontiguousarray(np.broadcast_to(texture.base_color, leading + (3,)),
                                                         np.float32))
    view_copies = np.ascontiguousarray(np.broadcast_to(views, leading + (3,)))
    return (texture, views, light), (copies, view_copies, light), leading


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=9)
    args = parser.parse_args()
    rng = np.random.default_rng(1)
    print(pb.cpu_info()["isa"])
    for texture_shape, views_shape in (((256, 256), (8, 8)), ((128, 128), (16, 16))):
        broadcast, contiguous, leading = case(rng, texture_shape, views_shape)
        out = np.empty(leading + (3,), np.float32)
        pairs = out.size // 3
        print(f"views {views_shape + (1, 1, 3)} against a {texture_shape} texture, {pairs} pairs")
        for threads in (1, None):
            calls = {"broadcast": broadcast, "contiguous": contiguous}
            best = {name: np.inf for name in calls}
            for _ in range(args.repeats):
                for name, arguments in calls.items():
                    start = time.perf_counter()
                    pb.eval(*arguments, out=out, threads=threads)
                    best[name] = min(best[name], time.perf_counter() - start)
            rates = {name: pairs / seconds / 1e6 for name, seconds in best.items()}
            print(f"  threads {threads or pb.cpu_info()['threads']}: broadcast {rates['broadcast']:.0f} M pairs/s, "
                  f"contiguous {rates['contiguous']:.0f} M pairs/s, "
                  f"time ratio {best['broadcast'] / best['contiguous']:.2f}")


if __name__ == "__main__":
    main()
