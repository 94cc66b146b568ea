#!/usr/bin/env python3
"""Writes cpp/src/energy_tables.cpp (and the sizes in
cpp/include/principled_brdf/energy_tables.hpp): the primary specular lobe's
missing energy 1 - E(μ; r) and 1 - E_avg(r) for each model, the tables
of the multiple-scattering compensation (Kulla & Conty 2017, docs/model.md).

    E(μ; r)  = ∫ Gs Ds cos θl dωl    at cos θv = μ, F = 1, ax = ay = max(0.001, r²),
               the model's own Gs (2014: anisotropic Smith; 2012: alpha_g)
    E_avg(r) = 2 ∫0^1 E(μ; r) μ dμ   (Kulla & Conty 2017, the average albedo)

Gs Ds is the float64 reference's specular lobe of a white metal (base_color 1,
metallic 1: Fs = 1). The quadrature is over the half vector h, with the
measure D cos θh dωh (the GGX draw, Walter et al. 2007 eq. 35-36) taken in
y = ln tan θh, where it is a smooth bell of width O(1) about ln alpha:

    E = ∫ Gs Ds cos θl 4 (wo·h) dωh = ∫ [f cos θl 4 (wo·h) / (D cos θh)] D cos θh dωh

Gauss-Legendre in y and φ, split where the reflected direction starts to
cross the horizon (θh = (90° - θv) / 2, below which every φ reflects above
it); beyond, up to θh = (90° + θv) / 2, where none does, φ runs to its
horizon crossing, cos φ = -μ cos 2θh / (sin θv sin 2θh), and y is clustered
at both ends, where that range opens and closes like a square root; the
integrand is smooth on every piece (converged to 1e-8 at 64 points a side).

The lookup is linear in μ on intervals spaced geometrically in ν = μ + 1/8,
16 an octave of ν from 1/8: μ steps of 1/128 below μ = 1/8, 1/64 to 3/8, 1/32
to 7/8, then 1/16 to μ = 1, which starts an interval of its own (slope 0).
The interval of ν and its bounds are ν's float32 exponent and top 4 mantissa
bits, so a lookup needs no division and μ less a bound is exact. Each
interval stores 1 - E at its end and the slope from its start: the line is
written from the end because 1 - E falls towards 0 as μ -> 1 at low
roughness, where from the start it would be the difference of two nearly
equal terms, rounded relative to them rather than to itself.

E_avg is the exact integral of that interpolant (from the stored float32
values and slopes), so that ∫ f_ms cos θl over the hemisphere is exactly
(1 - E(μo)) times the F_avg factor at every roughness node, and linear in r
between them like the lookup: the white furnace then errs only by the
interpolation error of E at μo.

Usage: python scripts/energy_tables.py [--points 64] [--output-dir DIR]
(needs the installed package; two processes; under a minute).
"""

from __future__ import annotations

import argparse
import pathlib
from multiprocessing import Pool

import numpy as np

# Nodes in ν = μ + OFFSET: ν_b = 2^(b // 16 - 3) (1 + (b % 16) / 16), each an interval's
# start, the last at μ = 1 (ν = 1 + OFFSET, slope 0); roughness rows
# r_j = j / (ROUGHNESSES - 1), so that r (ROUGHNESSES - 1) and its fraction are exact in float32.
INTERVALS = 51  # 3 octaves of ν from 1/8, [1, 1 + 1/8], then μ = 1
PER_OCTAVE = 16
OFFSET = 2.0 ** -3
ROUGHNESSES = 65
MU_FLOOR = 1e-6  # μ = 0 evaluated here (the quadrature degenerates at 0; E's limit is reached)
SPAN = 16.0  # the y range either side of ln alpha: the measure beyond is below 1e-13
MODELS = ("disney2014", "disney2012")
ROOT = pathlib.Path(__file__).resolve().parent.parent
HEADER = pathlib.Path("cpp/include/principled_brdf/energy_tables.hpp")
SOURCE = pathlib.Path("cpp/src/energy_tables.cpp")


def _gauss(n: int, a: float, b: float) -> tuple[np.ndarray, np.ndarray]:
    x, w = np.polynomial.legendre.leggauss(n)
    return a + (x + 1.0) * (b - a) / 2.0, w * (b - a) / 2.0


def directional_albedo(mu: float, roughness: float, model: str, points: int = 96) -> float:
    """E(μ; r) of the primary specular lobe with F = 1 by the quadrature above."""
    import principled_brdf as pb

    alpha = max(0.001, roughness * roughness)
    a2 = alpha * alpha
    log_alpha = np.log(alpha)
    material = pb.Material(base_color=(1.0, 1.0, 1.0), metallic=1.0, roughness=roughness)
    sin_o = np.sqrt(max(0.0, 1.0 - mu * mu))
    wo = np.array([sin_o, 0.0, mu])
    theta_o = np.arccos(mu)
    # every φ reflects above the horizon below θh = (90° - θv) / 2, none above (90° + θv) / 2
    theta_star, theta_end = (np.pi / 2 - theta_o) / 2, (np.pi / 2 + theta_o) / 2
    y_star = np.log(np.tan(theta_star)) if theta_star > 0 else -np.inf
    y_end = np.log(np.tan(theta_end)) if theta_end < np.pi / 2 else np.inf
    lo, hi = log_alpha - SPAN, log_alpha + SPAN
    pieces = []
    if y_star > lo:
        pieces.append((lo, min(y_star, hi), False))
    if y_star < hi and sin_o > 0:
        pieces.append((max(y_star, lo), min(y_end, hi), True))
    total = 0.0
    xs, ws = np.polynomial.legendre.leggauss(points)
    for y0, y1, cut in pieces:
        if cut:  # φ's range opens and closes like a square root at the ends: y = y0 + (y1 - y0)(1 - cos πs) / 2
            s, w_s = _gauss(points, 0.0, 1.0)
            y = y0 + (y1 - y0) * (1.0 - np.cos(np.pi * s)) / 2.0
            w_y = w_s * (y1 - y0) * np.pi * np.sin(np.pi * s) / 2.0
        else:
            y, w_y = _gauss(points, y0, y1)
        t2 = np.exp(2.0 * y)  # tan²θh
        c2 = 1.0 / (1.0 + t2)
        cos_h, sin_h = np.sqrt(c2), np.sqrt(t2 * c2)
        density = 2.0 * a2 * t2 / (a2 + t2) ** 2  # d(GGX cdf)/dy
        if cut:
            phi_max = np.arccos(np.clip(-mu * (2.0 * c2 - 1.0) / (sin_o * 2.0 * sin_h * cos_h), -1.0, 1.0))
        else:
            phi_max = np.full(points, np.pi)
        phi = (xs[None, :] + 1.0) * phi_max[:, None] / 2.0
        w_phi = ws[None, :] * phi_max[:, None] / 2.0
        h = np.stack([sin_h[:, None] * np.cos(phi), sin_h[:, None] * np.sin(phi),
                      np.broadcast_to(cos_h[:, None], phi.shape)], axis=-1)
        d = h @ wo
        wi = 2.0 * d[..., None] * h - wo
        ok = (wi[..., 2] > 0.0) & (d > 0.0)
        wi = np.where(ok[..., None], wi, np.array([0.0, 0.0, 1.0]))
        f = pb.reference.eval_lobes(material, wi, wo, model=model).specular[..., 0]
        ggx = a2 / (np.pi * (c2 * (a2 - 1.0) + 1.0) ** 2)
        weight = np.where(ok, f * wi[..., 2] * 4.0 * d / (ggx[:, None] * cos_h[:, None]), 0.0)
        total += float((weight * (w_y * density)[:, None] * w_phi / np.pi).sum())  # φ over [0, π]: half, doubled
    return total


def interval_starts() -> np.ndarray:
    """ν_b, the start of each interval of ν."""
    b = np.arange(INTERVALS)
    return 2.0 ** (b // PER_OCTAVE - 3.0) * (1.0 + (b % PER_OCTAVE) / PER_OCTAVE)


def cosine_of(nu: np.ndarray) -> np.ndarray:
    return nu - OFFSET


def cosine_nodes() -> np.ndarray:
    """The μ at which E is computed: every interval's start, the last μ = 1."""
    return cosine_of(interval_starts())


def roughness_nodes() -> np.ndarray:
    return np.linspace(0.0, 1.0, ROUGHNESSES)


def interval_ends() -> np.ndarray:
    """μ at the end of each interval (the next one's start; 1 + 1/16 for the last)."""
    return np.append(cosine_nodes()[1:], 1.0 + 1.0 / PER_OCTAVE)


def row_of(missing: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per interval, 1 - E at its end and the slope from its start (the last: μ = 1, slope 0)."""
    return np.append(missing[1:], missing[-1]), np.append(np.diff(missing) / np.diff(cosine_nodes()), 0.0)


def lookup(values: np.ndarray, slopes: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """1 - E(μ) of one row from its intervals' values and slopes, as the library reads it."""
    mu = np.clip(mu, 0.0, 1.0)
    b = np.clip(np.searchsorted(interval_starts(), mu + OFFSET, side="right") - 1, 0, INTERVALS - 1)
    return values[b] + (mu - interval_ends()[b]) * slopes[b]


def average_of_lookup(values: np.ndarray, slopes: np.ndarray) -> float:
    """2 ∫0^1 (1 - E(μ)) μ dμ of lookup() (exact: 2-point Gauss-Legendre on each
    interval, where the integrand is quadratic)."""
    edges = cosine_nodes()
    x, w = np.polynomial.legendre.leggauss(2)
    half = np.diff(edges)[:, None] / 2.0
    mu = edges[:-1, None] + (x[None, :] + 1.0) * half
    missing = values[:-1, None] + (mu - edges[1:, None]) * slopes[:-1, None]
    return float(2.0 * np.sum(missing * mu * w[None, :] * half))


def _row(job: tuple[str, float, int]) -> np.ndarray:
    model, roughness, points = job
    mus = cosine_nodes().copy()
    mus[0] = MU_FLOOR
    return np.array([directional_albedo(m, roughness, model, points) for m in mus])


def tables(points: int = 96, processes: int = 2) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Per model: (value, slope) of 1 - E per row and interval as float32, and 1 - E_avg per row."""
    out = {}
    with Pool(processes) as pool:
        for model in MODELS:
            e = np.array(pool.map(_row, [(model, float(r), points) for r in roughness_nodes()]))
            missing = np.maximum(1.0 - e, 0.0)
            rows = [row_of(row) for row in missing]
            values = np.array([v for v, _ in rows]).astype(np.float32)
            slopes = np.array([s for _, s in rows]).astype(np.float32)
            average = np.array([average_of_lookup(v.astype(np.float64), s.astype(np.float64))
                                for v, s in zip(values, slopes)])
            out[model] = (np.stack([values, slopes], axis=-1), average)
    return out


def _floats(values: np.ndarray, per_line: int = 8) -> str:
    def literal(v: float) -> str:  # a C++ float literal: "0" needs its point
        text = f"{float(np.float32(v)):.9g}"
        return (text if any(c in text for c in ".e") else text + ".0") + "f"

    items = [literal(v) for v in values.reshape(-1)]
    return ",\n".join("        " + ", ".join(items[i:i + per_line]) for i in range(0, len(items), per_line))


def write_tables(data: dict[str, tuple[np.ndarray, np.ndarray]], root: pathlib.Path, points: int) -> None:
    missing = ",\n".join("    {\n" + _floats(data[m][0]) + "\n    }" for m in MODELS)
    average = ",\n".join("    {\n" + _floats(data[m][1]) + "\n    }" for m in MODELS)
    (root / HEADER).write_text(f"""\
// Generated by scripts/energy_tables.py; do not edit.
// The primary specular lobe's missing energy for the multiple-scattering
// compensation (Kulla & Conty 2017; docs/model.md "Energy compensation"):
//   kMissing[table][2 (j kIntervals + b)] = 1 - E(μ_b+1; r_j), and [... + 1] the slope in μ from μ_b,
//   kMissingAverage[table][j] = 1 - E_avg(r_j),
// on intervals b of ν = μ + kCosineOffset starting at ν_b = 2^(b / 16 - 3) (1 + (b % 16) / 16)
// (16 an octave; μ_b = ν_b - kCosineOffset; the last is μ = 1 alone, slope 0),
// r_j = j / (kRoughnesses - 1), table t the model table's energy_table (0: 2014, 1: 2012): within interval b,
// 1 - E = value + (μ - μ_b+1) slope, from its end (μ_51 = 1 + 1/16).
// E_avg is the exact 2 ∫ E μ dμ of that interpolant.
// The values are in cpp/src/energy_tables.cpp (so that a new table recompiles one file).
#pragma once

namespace principled_brdf::energy {{

inline constexpr int kIntervals = {INTERVALS};
inline constexpr int kIntervalsPerOctave = {PER_OCTAVE};
inline constexpr float kCosineOffset = {OFFSET!r}f;  // 1/8
inline constexpr int kRoughnesses = {ROUGHNESSES};

extern const float kMissing[2][kRoughnesses * kIntervals * 2];
extern const float kMissingAverage[2][kRoughnesses];

}}  // namespace principled_brdf::energy
""")
    (root / SOURCE).write_text(f"""\
// Generated by scripts/energy_tables.py ({points}-point Gauss-Legendre); do not edit.
// The tables of principled_brdf/energy_tables.hpp.
#include "principled_brdf/energy_tables.hpp"

namespace principled_brdf::energy {{

alignas(64) const float kMissing[2][kRoughnesses * kIntervals * 2] = {{
{missing}
}};

alignas(64) const float kMissingAverage[2][kRoughnesses] = {{
{average}
}};

}}  // namespace principled_brdf::energy
""")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--points", type=int, default=64)
    parser.add_argument("--output-dir", type=pathlib.Path, default=ROOT, help="the repository root to write into")
    args = parser.parse_args()
    write_tables(tables(args.points), args.output_dir, args.points)
    print(f"wrote {args.output_dir / HEADER} and {args.output_dir / SOURCE}")


if __name__ == "__main__":
    main()
