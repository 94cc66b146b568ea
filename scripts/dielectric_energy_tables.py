#!/usr/bin/env python3
"""Writes cpp/src/dielectric_energy_tables.cpp (and the sizes in
cpp/include/principled_brdf/dielectric_energy_tables.hpp): the missing energy of
the 2015 solid's rough interface and of its metal, the tables of their energy
compensation (Kulla & Conty 2017; docs/energy-compensation.md).

    E_η(μ; r)     the directional albedo, reflection + transmission in importance
                  mode, of a white GGX dielectric interface of relative index η
                  seen from the outside at cos θv = μ (alpha = max(0.001, r²), the
                  model's separable Smith G1(wo) G1(wi), exact Fresnel factor);
    E_1/η(μ; r)   the same seen from the inside;
    E_c(μ; r)     a white conductor's (F = 1, reflection only), for the metal;
    1 - Ē         2 ∫0^1 (1 - E(μ)) μ dμ of the tables' interpolant, exactly.

Each albedo is an expectation over the visible normals of wo (Heitz 2018), at
which the light is reflected with the Fresnel factor F and refracted with 1 - F;
for the model's f the weight f |cos θl| / pdf of each is then G1(wi) (in
importance mode the η_t² of the transmission cancels the Jacobian's), so

    E(μ) = ∫ over the visible normals [F G1(wr) [wr above] + (1 - F) G1(wt) [wt below]].

The visible normal is mapped from the unit disk (Heitz 2018, eq. in §4); the
disk is integrated in polar coordinates, uniform in the angle and Gauss-Legendre
in the radius, each ray split where the light starts to be totally reflected
(found by bisection), whose square-root edge would otherwise dominate the
error: about 2e-4 against twice the points in each direction, checked by
tests/energy/test_dielectric_energy_tables.py against the whole-sphere
quadrature of the float64 reference.

Nodes: r_j = j / 32, x_k = 0.6 (k / 24)² in x = (η - 1) / (η + 1) (η from
1.001 to 4, the nodes uniform in sqrt(x), dense near η = 1, where the inside's
albedo below the critical angle changes fastest with η; beyond η = 4, the
lookup clamps x to 0.6), and in the cosine: outside
μ_i = i / 64 (μ = 0 evaluated at 1e-5); inside q_i = i / 32 in
    q = (1 - μ) / (1 - μc)  for μ >= μc,   q = 2 - μ / μc  below,
μc = sqrt(1 - 1/η²) the critical angle's cosine, so that the edge of total
internal reflection, which moves from μ = 0.04 to 0.97 as η goes from 1.001
to 4, is a node of every row (q = 1) and rows of neighbouring η share it. The
lookup is linear in each. The inside's mean m̄ = 2 ∫ (1 - E) μ dμ depends on
the material's own μc (q maps to μ linearly on each side of it): with the
moments of a row's interpolant, A = 2 ∫0^1 m dq, B = 2 ∫0^1 m q dq and
C = 2 ∫1^2 m (2 - q) dq,
    m̄ = (1 - μc) A - (1 - μc)² B + μc² C,
exact for the interpolant at the material's η.

Usage: python scripts/dielectric_energy_tables.py [--output-dir DIR] (two
processes, about 8 minutes).
"""

from __future__ import annotations

import argparse
import pathlib
from multiprocessing import Pool

import numpy as np

COSINES = 65
ROUGHNESSES = 33
IORS = 25
LARGEST_X = 0.6
MU_FLOOR = 1e-5
SMALLEST_ETA = 1.001
RADII = 96
ANGLES = 256
ROOT = pathlib.Path(__file__).resolve().parent.parent
HEADER = pathlib.Path("cpp/include/principled_brdf/dielectric_energy_tables.hpp")
SOURCE = pathlib.Path("cpp/src/dielectric_energy_tables.cpp")


def cosine_nodes() -> np.ndarray:
    return np.linspace(0.0, 1.0, COSINES)


def roughness_nodes() -> np.ndarray:
    return np.linspace(0.0, 1.0, ROUGHNESSES)


def x_nodes() -> np.ndarray:
    return LARGEST_X * np.linspace(0.0, 1.0, IORS) ** 2


def eta_of_x(x: float) -> float:
    return max((1.0 + x) / (1.0 - x), SMALLEST_ETA)


def critical_cosine(eta: float) -> float:
    return float(np.sqrt(1.0 - 1.0 / (eta * eta)))


def inside_cosine_nodes(eta: float) -> np.ndarray:
    """μ at the inside's nodes q_i = 2 i / (COSINES - 1) for index η."""
    q = np.linspace(0.0, 2.0, COSINES)
    mu_c = critical_cosine(eta)
    return np.where(q <= 1.0, 1.0 - q * (1.0 - mu_c), mu_c * (2.0 - q))


def fresnel(c: np.ndarray, eta_t: float) -> np.ndarray:
    """The unpolarised dielectric reflectance at cos c, η_t the far side's index over the near side's."""
    g2 = eta_t * eta_t - 1.0 + c * c
    g = np.sqrt(np.maximum(g2, 0.0))
    a = (g - c) / (g + c)
    b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0)
    return np.where(g2 > 0.0, 0.5 * a * a * (1.0 + b * b), 1.0)


def smith_g1(w: np.ndarray, alpha: float) -> np.ndarray:
    z = np.abs(w[..., 2])
    return 2.0 * z / (z + np.sqrt(alpha * alpha * (w[..., 0] ** 2 + w[..., 1] ** 2) + z * z))


class VisibleNormals:
    """The visible normals of wo = (sin θv, 0, μ) under GGX of alpha, from the unit disk."""

    def __init__(self, mu: float, alpha: float):
        self.wo = np.array([np.sqrt(1.0 - mu * mu), 0.0, mu])
        self.alpha = alpha
        stretched = np.array([alpha * self.wo[0], 0.0, mu])
        self.v = stretched / np.linalg.norm(stretched)
        self.t1 = np.array([0.0, 1.0, 0.0])
        self.t2 = np.cross(self.v, self.t1)

    def normal(self, r: np.ndarray, phi: np.ndarray) -> np.ndarray:
        p1, p2 = r * np.cos(phi), r * np.sin(phi)
        s = 0.5 * (1.0 + self.v[2])
        p2 = (1.0 - s) * np.sqrt(1.0 - p1 * p1) + s * p2
        pz = np.sqrt(np.maximum(0.0, 1.0 - p1 * p1 - p2 * p2))
        n = p1[..., None] * self.t1 + p2[..., None] * self.t2 + pz[..., None] * self.v
        h = np.stack([self.alpha * n[..., 0], self.alpha * n[..., 1], np.maximum(0.0, n[..., 2])], axis=-1)
        return h / np.linalg.norm(h, axis=-1, keepdims=True)


def _weight(wo: np.ndarray, h: np.ndarray, alpha: float, eta_t: float | None) -> np.ndarray:
    """F G1(wr) [wr above] + (1 - F) G1(wt) [wt below]; eta_t None: a white conductor (F = 1)."""
    c = h @ wo
    wr = 2.0 * c[..., None] * h - wo
    if eta_t is None:
        return smith_g1(wr, alpha) * (wr[..., 2] > 0.0)
    f = fresnel(c, eta_t)
    ratio = 1.0 / eta_t
    sin2 = ratio * ratio * (1.0 - c * c)
    cos_t = np.sqrt(np.maximum(1.0 - sin2, 0.0))
    wt = (ratio * c - cos_t)[..., None] * h - ratio * wo
    return f * smith_g1(wr, alpha) * (wr[..., 2] > 0.0) + (1.0 - f) * smith_g1(wt, alpha) * (wt[..., 2] < 0.0) * (sin2 < 1.0)


def albedo(mu: float, roughness: float, eta_t: float | None, radii: int = RADII, angles: int = ANGLES) -> float:
    """E(μ; r) by the quadrature of the module's comment (eta_t < 1: from the inside)."""
    alpha = max(0.001, roughness * roughness)
    normals = VisibleNormals(max(mu, MU_FLOOR), alpha)
    phi = (np.arange(angles) + 0.5) * (2.0 * np.pi / angles)
    split = np.ones(angles)
    critical2 = 1.0 - eta_t * eta_t if eta_t is not None and eta_t < 1.0 else -1.0
    if critical2 > 0.0:  # where along each ray total internal reflection starts (c² < 1 - η_t²)
        reflected = lambda r: (normals.normal(r, phi) @ normals.wo) ** 2 < critical2  # noqa: E731
        lo, hi = np.zeros(angles), np.ones(angles)
        for _ in range(48):
            mid = 0.5 * (lo + hi)
            inside = reflected(mid)
            hi, lo = np.where(inside, mid, hi), np.where(inside, lo, mid)
        split = np.where(reflected(np.ones(angles)), 0.5 * (lo + hi), 1.0)
    x, w = np.polynomial.legendre.leggauss(radii)
    u, wu = 0.5 * (x + 1.0), 0.5 * w
    total = 0.0
    # [0, split] clustered towards split, [split, 1] towards split: r = split ∓ L (1 - u)² or u²
    for start, end, towards_start in ((np.zeros(angles), split, False), (split, np.ones(angles), True)):
        length = (end - start)[:, None]
        if towards_start:
            r, dr = start[:, None] + length * u * u, length * 2.0 * u
        else:
            r, dr = start[:, None] + length * (1.0 - (1.0 - u) ** 2), length * 2.0 * (1.0 - u)
        h = normals.normal(r, phi[:, None])
        total += float((_weight(normals.wo, h, alpha, eta_t) * r * dr * wu).sum())
    return total * (2.0 * np.pi / angles) / np.pi  # the disk's area π


def missing_row(job: tuple[float, float | None]) -> np.ndarray:
    """1 - E at every cosine node, for (roughness, η_t or None): inside (η_t < 1) at the nodes in q."""
    roughness, eta_t = job
    nodes = inside_cosine_nodes(1.0 / eta_t) if eta_t is not None and eta_t < 1.0 else cosine_nodes()
    return np.maximum(1.0 - np.array([albedo(mu, roughness, eta_t) for mu in nodes]), 0.0)


def average_of_rows(missing: np.ndarray) -> np.ndarray:
    """2 ∫0^1 m(μ) μ dμ of the piecewise linear interpolant of each row (exact)."""
    mu = cosine_nodes()
    a, b = missing[..., :-1], missing[..., 1:]
    m0, m1 = mu[:-1], mu[1:]
    # ∫ over [m0, m1] of (a (m1 - μ) + b (μ - m0)) / Δ · μ dμ = Δ (a (2 m0 + m1) + b (m0 + 2 m1)) / 6
    return 2.0 * np.sum((m1 - m0) * (a * (2.0 * m0 + m1) + b * (m0 + 2.0 * m1)) / 6.0, axis=-1)


def inside_moments(missing: np.ndarray) -> np.ndarray:
    """(A, B, C) of the module's comment for each row of the inside's interpolant in q (exact)."""
    q = np.linspace(0.0, 2.0, COSINES)
    half = (COSINES - 1) // 2
    a, b = missing[..., :-1], missing[..., 1:]
    q0, q1 = q[:-1], q[1:]
    d = q1 - q0
    integral = d * (a + b) / 2.0  # ∫ m dq over each interval
    first = d * (a * (2.0 * q0 + q1) + b * (q0 + 2.0 * q1)) / 6.0  # ∫ m q dq
    upper, lower = slice(0, half), slice(half, COSINES - 1)
    return np.stack([2.0 * integral[..., upper].sum(-1), 2.0 * first[..., upper].sum(-1),
                     2.0 * (2.0 * integral[..., lower].sum(-1) - first[..., lower].sum(-1))], axis=0)


def tables(processes: int = 2) -> dict[str, np.ndarray]:
    """float32 tables: outside and inside (IORS, ROUGHNESSES, COSINES), conductor (ROUGHNESSES, COSINES)."""
    jobs = [(float(r), eta_of_x(x)) for x in x_nodes() for r in roughness_nodes()]
    jobs += [(float(r), 1.0 / eta_of_x(x)) for x in x_nodes() for r in roughness_nodes()]
    jobs += [(float(r), None) for r in roughness_nodes()]
    with Pool(processes) as pool:
        rows = np.array(pool.map(missing_row, jobs)).astype(np.float32)
    per_side = IORS * ROUGHNESSES
    outside = rows[:per_side].reshape(IORS, ROUGHNESSES, COSINES)
    inside = rows[per_side:2 * per_side].reshape(IORS, ROUGHNESSES, COSINES)
    conductor = rows[2 * per_side:]
    return {"outside": outside, "inside": inside, "conductor": conductor}


def _floats(values: np.ndarray, per_line: int = 8) -> str:
    def literal(v: float) -> str:  # a C++ float literal: "0" needs its point
        text = f"{float(np.float32(v)):.9g}"
        return (text if any(c in text for c in ".e") else text + ".0") + "f"

    flat = [literal(v) for v in np.asarray(values).ravel()]
    lines = [", ".join(flat[i:i + per_line]) for i in range(0, len(flat), per_line)]
    return ",\n    ".join(lines)


def write(t: dict[str, np.ndarray], out: pathlib.Path) -> None:
    outside_average = average_of_rows(t["outside"].astype(np.float64))
    inside_moments_ = inside_moments(t["inside"].astype(np.float64))
    conductor_average = average_of_rows(t["conductor"].astype(np.float64))
    header = f"""// Generated by scripts/dielectric_energy_tables.py; do not edit.
// The missing energy of the 2015 solid's rough dielectric interface and of a
// white conductor, for their energy compensation (Kulla & Conty 2017;
// docs/energy-compensation.md), with r_j = j / (kEnergyRoughnesses - 1) and
// x_k = kLargestX (k / (kIors - 1))² in x = (η - 1) / (η + 1):
//   kInterfaceMissing[0][(k kEnergyRoughnesses + j) kCosines + i] = 1 - E_η(μ_i; r_j, η_k) seen from outside,
//       μ_i = i / (kCosines - 1);
//   kInterfaceMissing[1][...] = 1 - E_1/η seen from inside at q_i = 2 i / (kCosines - 1),
//       q = (1 - μ) / (1 - μc) above the critical cosine μc = sqrt(1 - 1/η²), 2 - μ / μc below
//       (one array: a lane's side is an offset);
//   kConductorMissing[j kCosines + i] = 1 - E_c(μ_i; r_j);
//   kOutsideMissingAverage[k kEnergyRoughnesses + j], kConductorMissingAverage[j]: 2 ∫ (1 - E) μ dμ
//       of the interpolant, exactly;
//   kInsideMoments[n][k kEnergyRoughnesses + j]: A, B, C of the inside's rows, whose mean at the
//       material's μc is (1 - μc) A - (1 - μc)² B + μc² C (scripts/dielectric_energy_tables.py).
// The values are in cpp/src/dielectric_energy_tables.cpp.
#pragma once

namespace principled_brdf::energy {{

inline constexpr int kCosines = {COSINES};
inline constexpr int kEnergyRoughnesses = {ROUGHNESSES};
inline constexpr int kIors = {IORS};
inline constexpr float kLargestX = {LARGEST_X}f;
inline constexpr int kInterfaceSide = kIors * kEnergyRoughnesses * kCosines;  // one side's table

extern const float kInterfaceMissing[2][kInterfaceSide];
extern const float kOutsideMissingAverage[kIors * kEnergyRoughnesses];
extern const float kInsideMoments[3][kIors * kEnergyRoughnesses];
extern const float kConductorMissing[kEnergyRoughnesses * kCosines];
extern const float kConductorMissingAverage[kEnergyRoughnesses];

}}  // namespace principled_brdf::energy
"""

    def array(name: str, values: np.ndarray) -> str:
        if values.ndim > 1:
            inner = ",\n".join(f"    {{\n    {_floats(row)}}}" for row in values)
            return f"alignas(64) const float {name}[{len(values)}][{values[0].size}] = {{\n{inner}}};\n"
        return f"alignas(64) const float {name}[{values.size}] = {{\n    {_floats(values)}}};\n"

    body = "\n".join([array("kInterfaceMissing", np.stack([t["outside"], t["inside"]]).reshape(2, -1)),
                      array("kOutsideMissingAverage", outside_average.ravel()),
                      array("kInsideMoments", inside_moments_.reshape(3, -1)),
                      array("kConductorMissing", t["conductor"].ravel()),
                      array("kConductorMissingAverage", conductor_average)])
    source = f"""// Generated by scripts/dielectric_energy_tables.py ({RADII} x {ANGLES} points a quadrature); do not edit.
// The tables of principled_brdf/dielectric_energy_tables.hpp.
#include "principled_brdf/dielectric_energy_tables.hpp"

namespace principled_brdf::energy {{

{body}
}}  // namespace principled_brdf::energy
"""
    for path, text in ((out / HEADER, header), (out / SOURCE, source)):
        if not path.exists() or path.read_text() != text:  # an unchanged header rebuilds no kernel
            path.write_text(text)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--output-dir", type=pathlib.Path, default=ROOT)
    parser.add_argument("--processes", type=int, default=2)
    parser.add_argument("--cache", type=pathlib.Path, help="an .npz of the tables: read if it exists, else written")
    args = parser.parse_args()
    if args.cache is not None and args.cache.exists():
        t = dict(np.load(args.cache))
    else:
        t = tables(args.processes)
        if args.cache is not None:
            np.savez(args.cache, **t)
    write(t, args.output_dir)


if __name__ == "__main__":
    main()
