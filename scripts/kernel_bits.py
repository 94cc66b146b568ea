"""The SIMD kernels' outputs on fixed inputs, as one SHA-256 digest per
(instruction set, model, output): a refactoring of the model that must not
change a bit is checked against tests/kernel_bits.json.

    python3 scripts/kernel_bits.py > tests/kernel_bits.json   # record (only when bits may change)

The inputs are drawn from a fixed seed: 2^20 pairs over the whole parameter
domain (per element), half of the directions near the horizon, and a few
uniform materials; each output's float32 bytes are hashed.
"""

from __future__ import annotations

import hashlib
import json
import sys

import numpy as np

import principled_brdf as pb

PAIRS = 1 << 20
GRADIENT_PAIRS = 1 << 16


BRDF_LOBES = 5  # diffuse, sheen, specular, clearcoat, multiple_scattering


def directions(rng: np.random.Generator, n: int) -> np.ndarray:
    v = rng.normal(size=(n, 3))
    v[:, 2] = np.abs(v[:, 2])
    v[: n // 2, 2] *= 1e-3  # near the horizon
    return (v / np.linalg.norm(v, axis=1, keepdims=True)).astype(np.float32)


def per_element_material(rng: np.random.Generator, n: int) -> pb.Material:
    unit = lambda: np.where(rng.random(n) < 0.1, rng.integers(0, 2, n), rng.random(n))  # noqa: E731
    return pb.Material(base_color=rng.random((n, 3)), metallic=unit(), subsurface=unit(), specular=2 * rng.random(n),
                       specular_tint=unit(), roughness=unit(), anisotropic=unit(), sheen=unit(), sheen_tint=unit(),
                       clearcoat=unit(), clearcoat_gloss=unit())


UNIFORM = {"default": pb.Material(), "gold": pb.Material(base_color=(1.0, 0.71, 0.29), metallic=1.0, roughness=0.3),
           "plastic": pb.Material(base_color=(0.9, 0.9, 0.9), roughness=0.5, clearcoat=1.0, sheen=0.5)}


def digest(*arrays: np.ndarray) -> str:
    h = hashlib.sha256()
    for array in arrays:
        h.update(np.ascontiguousarray(array).tobytes())
    return h.hexdigest()[:32]


def kernel_bits(isa: str) -> dict[str, str]:
    rng = np.random.default_rng(20261204)
    wi, wo = directions(rng, PAIRS), directions(rng, PAIRS)
    materials = {"per_element": per_element_material(rng, PAIRS), **UNIFORM}
    u = rng.random((PAIRS, 3)).astype(np.float32)
    bits = {}
    for model in ("disney2014", "disney2012"):
        for name, m in materials.items():
            key = f"{model}/{name}"
            bits[f"{key}/eval"] = digest(pb.eval(m, wi, wo, model=model, isa=isa))
            # the BRDF lobes (the 2015 models' transmission, 0 here, joined the table after the bits were recorded)
            bits[f"{key}/eval_lobes"] = digest(*pb.eval_lobes(m, wi, wo, model=model, isa=isa)[:BRDF_LOBES])
            bits[f"{key}/eval_compensated"] = digest(pb.eval(m, wi, wo, model=model, isa=isa,
                                                             energy_compensation=True))
            bits[f"{key}/pdf"] = digest(pb.pdf(m, wi, wo, model=model, isa=isa))
            bits[f"{key}/eval_pdf"] = digest(*pb.eval_pdf(m, wi, wo, model=model, isa=isa, cosine=True))
            s, lobes = pb.sample(m, wo, u=u, model=model, isa=isa, with_lobes=True)
            bits[f"{key}/sample"] = digest(s.wi, s.pdf, s.weight, s.lobe, *lobes[:BRDF_LOBES])
            g_m = m if m.is_uniform else m[:GRADIENT_PAIRS]
            g = pb.eval_grad(g_m, wi[:GRADIENT_PAIRS], wo[:GRADIENT_PAIRS], model=model, isa=isa)
            bits[f"{key}/eval_grad"] = digest(g.value, g.jacobian)
    return bits


def main() -> None:
    record = {isa: kernel_bits(isa) for isa in pb.cpu_info()["available"]}
    json.dump(record, sys.stdout, indent=1, sort_keys=True)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
