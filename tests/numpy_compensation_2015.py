"""An independent float64 transcription of the 2015 solid's energy compensation
(docs/energy-compensation.md, "The rough dielectric"), written from the docs'
equations in numpy, never from the C++ code; the tables are read from the
generated source (cpp/src/dielectric_energy_tables.cpp) and interpolated here.

Conventions as tests/numpy_model_2015.py's: local frame, wi towards the light,
wo towards the viewer, the outside on the side of n (index 1), the inside of
index η. ``multiple_scattering(params, wi, wo, mode)`` is the lobe the option
adds, (N, 3), f without the cosine.
"""

from __future__ import annotations

import functools
import pathlib
import re

import numpy as np

from numpy_model_2015 import DEFAULTS, _p, eta_of_specular

ROOT = pathlib.Path(__file__).resolve().parent.parent


@functools.lru_cache(maxsize=1)
def tables() -> dict[str, np.ndarray | float | int]:
    """The generated tables (float32 values as float64) and their node counts."""
    header = (ROOT / "cpp/include/principled_brdf/dielectric_energy_tables.hpp").read_text()
    sizes = {name: float(value.rstrip("f")) for name, value in
             re.findall(r"inline constexpr (?:int|float) (k\w+) = ([0-9.]+f?);", header)}
    source = (ROOT / "cpp/src/dielectric_energy_tables.cpp").read_text()
    out: dict[str, np.ndarray | float | int] = {}
    for name, body in re.findall(r"const float (k\w+)\[[^=]*= \{(.*?)\};", source, re.S):
        literals = re.findall(r"(-?[0-9.]+(?:e[-+]?[0-9]+)?)f", body)
        out[name] = np.array(literals, dtype=np.float32).astype(np.float64)  # the float literals' values
    cosines, roughnesses, iors = int(sizes["kCosines"]), int(sizes["kEnergyRoughnesses"]), int(sizes["kIors"])
    out["interface"] = out.pop("kInterfaceMissing").reshape(2, iors, roughnesses, cosines)
    out["outside_average"] = out.pop("kOutsideMissingAverage").reshape(iors, roughnesses)
    out["inside_moments"] = out.pop("kInsideMoments").reshape(3, iors, roughnesses)
    out["conductor"] = out.pop("kConductorMissing").reshape(roughnesses, cosines)
    out["conductor_average"] = out.pop("kConductorMissingAverage")
    out["largest_x"] = float(np.float32(sizes["kLargestX"]))
    return out


def _node(y, nodes):
    """The node below y in [0, nodes - 1] (at most nodes - 2) and the fraction past it."""
    k = np.minimum(np.floor(y), nodes - 2).astype(int)
    return k, y - k


def _lerp(a, b, t):
    return a + (b - a) * t


def _positions(roughness, eta):
    """(j, t_r) in the roughness nodes and (k, t_x) in sqrt(x), x = (η - 1) / (η + 1)."""
    t = tables()
    roughnesses, iors = t["conductor"].shape[0], t["interface"].shape[1]
    j, along_r = _node(np.clip(roughness, 0.0, 1.0) * (roughnesses - 1), roughnesses)
    x = np.minimum((eta - 1.0) / (eta + 1.0), t["largest_x"])
    k, along_x = _node(np.sqrt(x) * (iors - 1) / np.sqrt(t["largest_x"]), iors)  # nodes uniform in sqrt(x)
    return j, along_r, k, along_x


def _in_row(rows, y):
    """Rows (N, cosines) read linearly at y (N,) in [0, cosines - 1], the rows' node coordinate."""
    i, along = _node(y, rows.shape[-1])
    n = np.arange(len(y))
    return _lerp(rows[n, i], rows[n, i + 1], along)


def critical_cosine(eta):
    """μc = sqrt(1 - 1/η²) at the tables' η (x clamped to their range)."""
    x = np.minimum((eta - 1.0) / (eta + 1.0), tables()["largest_x"])
    eta_table = (1.0 + x) / (1.0 - x)
    return np.sqrt(1.0 - 1.0 / eta_table**2)


def cosine_coordinate(side, mu, eta):
    """Where μ falls in a row's nodes: μ (cosines - 1) outside; inside
    q (cosines - 1) / 2, q = (1 - μ) / (1 - μc) above μc, 2 - μ / μc below."""
    cosines = tables()["conductor"].shape[1]
    mu = np.clip(mu, 0.0, 1.0)
    if side == 0:
        return mu * (cosines - 1)
    mu_c = critical_cosine(eta)
    q = np.where(mu >= mu_c, (1.0 - mu) / (1.0 - mu_c), 2.0 - mu / mu_c)
    return np.clip(q, 0.0, 2.0) * (cosines - 1) / 2.0


def interface_missing(side, mu, roughness, eta):
    """1 - E(μ) of the white interface, side 0 outside (E_η), 1 inside (E_1/η): linear in r, x and the cosine's node."""
    side = np.broadcast_to(side, np.shape(mu))
    out = np.empty(np.shape(mu))
    for s in (0, 1):
        at = side == s
        if not at.any():
            continue
        t = tables()["interface"]
        j, ar, k, ax = _positions(roughness[at], eta[at])
        y = cosine_coordinate(s, mu[at], eta[at])
        corner = lambda dk, dj: _in_row(t[s, k + dk, j + dj], y)  # noqa: E731
        out[at] = _lerp(_lerp(corner(0, 0), corner(0, 1), ar), _lerp(corner(1, 0), corner(1, 1), ar), ax)
    return out


def _bilinear(table, roughness, eta):
    j, ar, k, ax = _positions(roughness, eta)
    return _lerp(_lerp(table[k, j], table[k, j + 1], ar), _lerp(table[k + 1, j], table[k + 1, j + 1], ar), ax)


def interface_missing_average(side, roughness, eta):
    """m̄ = 2 ∫ (1 - E) μ dμ of the interpolant: outside from its table; inside at the
    material's μc from the rows' moments, (1 - μc) A - (1 - μc)² B + μc² C."""
    if side == 0:
        return _bilinear(tables()["outside_average"], roughness, eta)
    a, b, c = (_bilinear(m, roughness, eta) for m in tables()["inside_moments"])
    mu_c = critical_cosine(eta)
    return (1.0 - mu_c) * a - (1.0 - mu_c) ** 2 * b + mu_c**2 * c


def conductor_missing(mu, roughness):
    t = tables()["conductor"]
    j, ar, _, _ = _positions(roughness, np.ones_like(roughness))
    y = cosine_coordinate(0, mu, None)
    return _lerp(_in_row(t[j], y), _in_row(t[j + 1], y), ar)


def split(roughness, eta):
    """(b outside, b inside, m̄ outside, m̄ inside): the transmitted shares of the added light."""
    outside = np.maximum(interface_missing_average(0, roughness, eta), 1e-7)
    inside = np.maximum(interface_missing_average(1, roughness, eta), 1e-7)
    mean_transmittance = 1.0 - (eta - 1.0) / (4.08567 + 1.00071 * eta)
    return (mean_transmittance * inside / (outside + inside), mean_transmittance / eta**2 * outside / (outside + inside),
            outside, inside)


def multiple_scattering(params, wi, wo, mode="radiance"):
    wi, wo = np.broadcast_arrays(np.atleast_2d(np.asarray(wi, float)), np.atleast_2d(np.asarray(wo, float)))
    n = len(wi)
    p = {name: _p(params, name, n).astype(float) for name in DEFAULTS}
    eta = eta_of_specular(p["specular"])
    roughness, metallic = p["roughness"], p["metallic"]
    w_t = (1.0 - metallic) * p["spec_trans"]
    inside = wo[:, 2] < 0
    mu_o, mu_i = np.abs(wo[:, 2]), np.abs(wi[:, 2])
    below = np.sign(wi[:, 2]) != np.sign(wo[:, 2])  # the light across the interface
    light_inside = inside != below
    b_out, b_in, m_out, m_in = split(roughness, eta)
    value = (w_t * interface_missing(inside.astype(int), mu_o, roughness, eta)
             * interface_missing(light_inside.astype(int), mu_i, roughness, eta)
             / (np.pi * np.where(light_inside, m_in, m_out)))
    b_v = np.where(inside, b_in, b_out)
    reflected = np.where(below, 0.0, value * (1.0 - b_v))
    eta_t = np.where(inside, 1.0 / eta, eta)  # the light's side's index over the viewer's
    through = value * b_v / (eta_t**2 if mode == "radiance" else 1.0)
    transmitted = np.where(below, through, 0.0)
    out = reflected[:, None] + transmitted[:, None] * np.sqrt(p["base_color"])

    # the metal: Kulla & Conty's conductor lobe, F_avg = (20 base_color + 1) / 21 (at most 1)
    m_c = np.maximum(_conductor_average(roughness), 1e-7)
    f_avg = np.minimum((20.0 * p["base_color"] + 1.0) / 21.0, 1.0)
    e_avg = 1.0 - _conductor_average(roughness)
    tint = metallic[:, None] * f_avg**2 * e_avg[:, None] / (1.0 - f_avg * (1.0 - e_avg[:, None]))
    metal = conductor_missing(mu_o, roughness) * conductor_missing(mu_i, roughness) / (np.pi * m_c)
    outside_reflection = ~inside & ~below
    out = out + np.where(outside_reflection, metal, 0.0)[:, None] * tint
    scattered = (wo[:, 2] != 0) & (wi[:, 2] != 0)
    return np.where(scattered[:, None], out, 0.0)


def _conductor_average(roughness):
    t = tables()["conductor_average"]
    j, ar, _, _ = _positions(roughness, np.ones_like(roughness))
    return _lerp(t[j], t[j + 1], ar)
