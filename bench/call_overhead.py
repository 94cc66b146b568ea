"""The fixed cost of a call from Python: each SIMD entry point on 16 pairs (the
kernel's share is well under a microsecond), and a Material's construction.
Best of 5 runs of 2,000 calls each, in microseconds per call.

    python bench/call_overhead.py
"""

import timeit

import numpy as np

import principled_brdf as pb


def main() -> None:
    rng = np.random.default_rng(1)
    directions = rng.normal(size=(16, 3)).astype(np.float32)
    directions[:, 2] = np.abs(directions[:, 2])
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    wi, wo = directions, directions[::-1].copy()
    out = np.empty_like(wi)
    material = pb.Material(base_color=(0.82, 0.67, 0.16), metallic=0.2, roughness=0.4, clearcoat=0.5)
    calls = {
        "pb.Material(base_color=..., metallic=..., roughness=..., clearcoat=...)":
            lambda: pb.Material(base_color=(0.82, 0.67, 0.16), metallic=0.2, roughness=0.4, clearcoat=0.5),
        "pb.eval(m, wi, wo)": lambda: pb.eval(material, wi, wo),
        "pb.eval(m, wi, wo, out=out)": lambda: pb.eval(material, wi, wo, out=out),
        "pb.eval_pdf(m, wi, wo)": lambda: pb.eval_pdf(material, wi, wo),
        "pb.eval_lobes(m, wi, wo)": lambda: pb.eval_lobes(material, wi, wo),
        "pb.pdf(m, wi, wo)": lambda: pb.pdf(material, wi, wo),
        "pb.eval_grad(m, wi, wo)": lambda: pb.eval_grad(material, wi, wo),
        "pb.sample(m, wo, seed=1)": lambda: pb.sample(material, wo, seed=1),
    }
    for name, call in calls.items():
        call()  # the first call's caches (the material's float32 check) are not the fixed cost
        seconds = min(timeit.repeat(call, number=2000, repeat=5)) / 2000
        print(f"{seconds * 1e6:8.1f} us  {name}")


if __name__ == "__main__":
    main()
