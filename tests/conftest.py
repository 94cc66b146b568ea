"""Shared fixtures and helpers for the test suite.

Importable from any test module (pytest puts ``tests/`` on ``sys.path``)::

    from conftest import random_directions, random_material_arrays, MODELS

All randomness comes from ``numpy.random.Generator`` objects built from fixed
seeds, so every run sees the same inputs.
"""

from __future__ import annotations

import zlib

import numpy as np
import pytest

import numpy_model
import principled_brdf as pb

MODELS = ("disney2014", "disney2012")
LOBES = ("diffuse", "sheen", "specular", "clearcoat")

SEED = 20240517

# Values at (or on the edge of) the domains of docs/model.md, "The model" that random draws should
# include. Unbounded parameters get a few values above the BRDF Explorer's UI
# range, since the domains allow them.
EDGE_VALUES = {
    "metallic": (0.0, 1.0),
    "subsurface": (0.0, 1.0),
    "specular": (0.0, 1.0, 2.0),
    "specular_tint": (0.0, 1.0),
    "roughness": (0.0, 1.0, 0.001, 0.03, 1.5),
    "anisotropic": (0.0, 1.0),
    "sheen": (0.0, 1.0, 2.0),
    "sheen_tint": (0.0, 1.0),
    "clearcoat": (0.0, 1.0, 2.0),
    "clearcoat_gloss": (0.0, 1.0),
}

# Ranges for the random (non-edge) draws of each scalar parameter.
RANGES = {
    "metallic": (0.0, 1.0),
    "subsurface": (0.0, 1.0),
    "specular": (0.0, 2.0),
    "specular_tint": (0.0, 1.0),
    "roughness": (0.0, 1.0),
    "anisotropic": (0.0, 1.0),
    "sheen": (0.0, 2.0),
    "sheen_tint": (0.0, 1.0),
    "clearcoat": (0.0, 2.0),
    "clearcoat_gloss": (0.0, 1.0),
}

SCALAR_PARAMETERS = tuple(RANGES)

# docs/model.md, "The model" domains restated for the tests (the library's own table is checked against it)
TABLE_DOMAINS = {
    "base_color": (0.0, np.inf),
    "metallic": (0.0, 1.0),
    "subsurface": (0.0, 1.0),
    "specular": (0.0, np.inf),
    "specular_tint": (0.0, 1.0),
    "roughness": (0.0, np.inf),
    "anisotropic": (0.0, 1.0),
    "sheen": (0.0, np.inf),
    "sheen_tint": (0.0, 1.0),
    "clearcoat": (0.0, np.inf),
    "clearcoat_gloss": (0.0, 1.0),
    "spec_trans": (0.0, 1.0),  # docs/model-2015.md
    "flatness": (0.0, 1.0),
    "diff_trans": (0.0, 2.0),
}
BOUNDED_PARAMETERS = ("metallic", "subsurface", "specular_tint", "anisotropic", "sheen_tint", "clearcoat_gloss",
                      "spec_trans", "flatness", "diff_trans")
NON_NEGATIVE_PARAMETERS = ("base_color", "specular", "roughness", "sheen", "clearcoat")


def seeded_rng(*keys) -> np.random.Generator:
    """A generator whose seed is a fixed function of ``keys`` (e.g. a test's name)."""
    key = "/".join(str(k) for k in keys).encode()
    return np.random.default_rng([SEED, zlib.crc32(key)])


# --------------------------------------------------------------------------
# directions


def directions_from_cos(rng: np.random.Generator, cos_theta: np.ndarray) -> np.ndarray:
    """Unit vectors with the given ``cos θ`` and a uniformly random azimuth."""
    cos_theta = np.asarray(cos_theta, dtype=np.float64)
    phi = rng.uniform(0.0, 2.0 * np.pi, cos_theta.shape)
    sin_theta = np.sqrt(np.maximum(0.0, 1.0 - cos_theta * cos_theta))
    return np.stack([sin_theta * np.cos(phi), sin_theta * np.sin(phi), cos_theta], axis=-1)


def random_directions(
    rng: np.random.Generator,
    n,
    min_cos: float = 1e-4,
    grazing_fraction: float = 0.25,
    grazing_cos: float = 0.05,
) -> np.ndarray:
    """``n`` (int or shape) unit vectors in the upper hemisphere with ``cos θ >= min_cos``.

    About ``1 - grazing_fraction`` are uniform in solid angle over
    ``cos θ in [min_cos, 1]``; the rest have ``cos θ`` log-uniform in
    ``[min_cos, max(grazing_cos, min_cos)]`` (near the horizon), and a few are exactly the
    normal. Set ``grazing_fraction=0`` for a plain uniform hemisphere.
    """
    shape = (n,) if np.isscalar(n) else tuple(n)
    count = int(np.prod(shape, dtype=np.int64))
    cos_theta = rng.uniform(min_cos, 1.0, count)
    if grazing_fraction > 0 and count:
        grazing = rng.random(count) < grazing_fraction
        hi = max(grazing_cos, min_cos)
        cos_theta[grazing] = np.exp(rng.uniform(np.log(min_cos), np.log(hi), int(grazing.sum())))
        normal = rng.random(count) < 0.01
        cos_theta[normal] = 1.0
    return directions_from_cos(rng, cos_theta).reshape(shape + (3,))


def below_horizon_directions(rng: np.random.Generator, n) -> np.ndarray:
    """Unit vectors with ``cos θ <= 0`` (some exactly on the horizon)."""
    shape = (n,) if np.isscalar(n) else tuple(n)
    count = int(np.prod(shape, dtype=np.int64))
    cos_theta = -rng.uniform(0.0, 1.0, count)
    cos_theta[rng.random(count) < 0.1] = 0.0
    cos_theta[rng.random(count) < 0.02] = -1.0
    return directions_from_cos(rng, cos_theta).reshape(shape + (3,))


def reflect_about_normal(w: np.ndarray) -> np.ndarray:
    """The mirror direction of ``w`` about ``n = z`` (specular peak)."""
    return w * np.array([-1.0, -1.0, 1.0])


def clamp_cos_theta(w: np.ndarray, min_cos: float) -> np.ndarray:
    """Unit vectors ``w`` with ``cos θ`` raised to at least ``min_cos`` (azimuth kept)."""
    w = np.array(w, dtype=np.float64, copy=True)
    low = w[..., 2] < min_cos
    if np.any(low):
        xy = w[low][:, :2]
        norm = np.linalg.norm(xy, axis=-1, keepdims=True)
        xy = np.where(norm > 0, xy / np.where(norm > 0, norm, 1.0), [1.0, 0.0])
        w[low] = np.concatenate([xy * np.sqrt(1.0 - min_cos * min_cos), np.full((len(xy), 1), min_cos)], axis=-1)
    return w


def random_direction_pairs(rng: np.random.Generator, n: int, min_cos: float = 1e-4, grazing_fraction: float = 0.25):
    """``(wi, wo)``, each ``(n, 3)``, in the upper hemisphere with ``cos θ >= min_cos``, stressing the peaks:
    60 % independent (``random_directions``, a ``grazing_fraction`` of them near the
    horizon), 15 % near the mirror direction, 10 % the exact mirror (h = n),
    10 % wi = wo, 5 % near wi = wo (cos θd -> 1)."""
    wi = random_directions(rng, n, min_cos=min_cos, grazing_fraction=grazing_fraction)
    wo = random_directions(rng, n, min_cos=min_cos, grazing_fraction=grazing_fraction)
    kind = rng.random(n)
    mirror = reflect_about_normal(wi)
    near = (kind >= 0.60) & (kind < 0.75)
    jitter = mirror[near] + rng.normal(0.0, 0.02, (int(near.sum()), 3))
    jitter[:, 2] = np.abs(jitter[:, 2])
    wo[near] = clamp_cos_theta(jitter / np.linalg.norm(jitter, axis=-1, keepdims=True), min_cos)
    exact = (kind >= 0.75) & (kind < 0.85)
    wo[exact] = mirror[exact]
    same = (kind >= 0.85) & (kind < 0.95)
    wo[same] = wi[same]
    close = kind >= 0.95
    jitter = wi[close] + rng.normal(0.0, 1e-4, (int(close.sum()), 3))
    jitter[:, 2] = np.abs(jitter[:, 2])
    wo[close] = clamp_cos_theta(jitter / np.linalg.norm(jitter, axis=-1, keepdims=True), min_cos)
    return wi, wo


# --------------------------------------------------------------------------
# materials


def random_base_color(rng: np.random.Generator, n: int, edge_fraction: float = 0.2) -> np.ndarray:
    color = rng.uniform(0.0, 1.0, (n, 3))
    edges = rng.random(n)
    color[edges < edge_fraction / 4] = 0.0  # black: Cdlum = 0, Ctint = 1
    white = (edges >= edge_fraction / 4) & (edges < edge_fraction / 2)
    color[white] = 1.0
    one_channel = (edges >= edge_fraction / 2) & (edges < 3 * edge_fraction / 4)  # saturated
    color[one_channel] = color[one_channel] * (rng.integers(0, 3, (int(one_channel.sum()), 1)) == np.arange(3))
    bright = (edges >= 3 * edge_fraction / 4) & (edges < edge_fraction)
    color[bright] *= 3.0  # >1 is inside the domain (>= 0 each)
    return color


def random_scalar_parameter(rng: np.random.Generator, name: str, n: int, edge_fraction: float = 0.2) -> np.ndarray:
    lo, hi = RANGES[name]
    values = rng.uniform(lo, hi, n)
    edges = rng.random(n) < edge_fraction
    values[edges] = rng.choice(EDGE_VALUES[name], int(edges.sum()))
    return values


def random_material_arrays(rng: np.random.Generator, n: int, edge_fraction: float = 0.2) -> dict:
    """Per-element parameters for ``n`` materials: ``{name: (n,) array, base_color: (n, 3)}``.

    Values cover the domains of docs/model.md, "The model"; a fraction ``edge_fraction`` of each
    parameter is set to an edge value (roughness 0 and 1, anisotropic 1,
    specular 2, clearcoat_gloss 0 and 1, metallic 0 and 1, black base color,
    sheen and clearcoat up to 2, ...), drawn independently per parameter.
    """
    params = {"base_color": random_base_color(rng, n, edge_fraction)}
    for name in SCALAR_PARAMETERS:
        params[name] = random_scalar_parameter(rng, name, n, edge_fraction)
    return params


def random_material_dict(rng: np.random.Generator, edge_fraction: float = 0.2) -> dict:
    """One uniform material's parameters as Python floats / a 3-tuple."""
    arrays = random_material_arrays(rng, 1, edge_fraction)
    return {
        name: (tuple(float(c) for c in value[0]) if name == "base_color" else float(value[0]))
        for name, value in arrays.items()
    }


def material_element(params: dict, i: int) -> dict:
    """The ``i``-th element of per-element parameters, as a uniform parameter dict."""
    return {name: value[i] for name, value in params.items()}


def corner_materials() -> list:
    """Named corner-case materials (uniform), for parametrised tests."""
    return [
        ("default", {}),
        ("mirror_dielectric", dict(roughness=0.0)),
        ("mirror_metal", dict(roughness=0.0, metallic=1.0, base_color=(0.95, 0.64, 0.54))),
        ("rough_metal", dict(roughness=1.0, metallic=1.0)),
        ("aniso_full", dict(anisotropic=1.0, roughness=0.3)),
        ("aniso_mirror", dict(anisotropic=1.0, roughness=0.0)),
        ("black", dict(base_color=(0.0, 0.0, 0.0), sheen=1.0, sheen_tint=1.0, specular_tint=1.0)),
        ("white_subsurface", dict(base_color=(1.0, 1.0, 1.0), subsurface=1.0, roughness=1.0)),
        ("sheen_cloth", dict(sheen=2.0, sheen_tint=1.0, roughness=0.8)),
        ("clearcoat_gloss", dict(clearcoat=2.0, clearcoat_gloss=1.0)),
        ("clearcoat_satin", dict(clearcoat=1.0, clearcoat_gloss=0.0)),
        ("specular_2", dict(specular=2.0, specular_tint=1.0)),
        ("everything", dict(metallic=0.5, subsurface=0.5, specular=1.5, specular_tint=0.5, roughness=0.2,
                            anisotropic=0.7, sheen=1.0, sheen_tint=0.3, clearcoat=1.5, clearcoat_gloss=0.6)),
    ]


# --------------------------------------------------------------------------
# comparisons


def max_relative_error(actual, expected, floor: float = 1e-300) -> float:
    """max |actual - expected| / max(|expected|, floor), elementwise; 0 for exact agreement."""
    actual = np.asarray(actual, dtype=np.float64)
    expected = np.asarray(expected, dtype=np.float64)
    denom = np.maximum(np.abs(expected), floor)
    err = np.abs(actual - expected) / denom
    return float(err.max()) if err.size else 0.0


def assert_relative_close(actual, expected, rtol: float, floor: float = 1e-300, what: str = "") -> None:
    """Every element within ``rtol`` relative to ``max(|expected|, floor)``; reports the worst."""
    actual = np.asarray(actual, dtype=np.float64)
    expected = np.asarray(expected, dtype=np.float64)
    assert actual.shape == expected.shape, f"{what}: shape {actual.shape} != {expected.shape}"
    assert np.all(np.isfinite(actual)), f"{what}: non-finite values"
    denom = np.maximum(np.abs(expected), floor)
    err = np.abs(actual - expected) / denom
    if err.size and err.max() > rtol:
        i = np.unravel_index(int(np.argmax(err)), err.shape)
        raise AssertionError(
            f"{what}: relative error {err[i]:.3e} > {rtol:g} at {i}: actual {actual[i]!r}, expected {expected[i]!r}"
        )


# --------------------------------------------------------------------------
# float64 conditioning of Schlick(cos θd) = (1 - cos θd)^5

# cos θd = wi.h is computed to a few ulp times 1/|H| (H = wi + wo cancels when
# wi ~ -wo, possible only near the horizon), and (1 - cos θd)^5 turns an
# absolute error δ in cos θd into a relative error 5 δ / (1 - cos θd) in FH.
# Two float64 evaluations of the same FH (reference vs numpy model, or
# f(wi, wo) vs f(wo, wi), which uses wo.h) can therefore differ by about
#     40 eps / ((1 - cos θd) cos θd)      (|H| = 2 cos θd)
SCHLICK_CONDITIONING = 40 * np.finfo(np.float64).eps


def one_minus_cos_theta_d(wi, wo):
    """1 - cos θd without cancellation: sin²θd / (1 + cos θd), with sin θd = |wi - wo| / 2."""
    wi = np.asarray(wi, dtype=np.float64)
    wo = np.asarray(wo, dtype=np.float64)
    cos_d = np.linalg.norm(wi + wo, axis=-1) / 2.0
    sin2_d = np.sum((wi - wo) ** 2, axis=-1) / 4.0
    return sin2_d / (1.0 + cos_d)


def schlick_tolerance(wi, wo, share=1.0, rtol: float = 1e-12):
    """Per element and channel: ``rtol + share * 40 eps / ((1 - cos θd) cos θd)``, shaped (..., 3).

    ``share`` is the fraction of the compared value carried by FH
    (``numpy_model.schlick_fractions``). Both factors of the denominator are
    floored at eps, below which neither implementation resolves them.
    """
    eps = np.finfo(np.float64).eps
    share = np.asarray(share, dtype=np.float64)
    cos_d = np.linalg.norm(np.asarray(wi, dtype=np.float64) + np.asarray(wo, dtype=np.float64), axis=-1) / 2.0
    gap = np.maximum(one_minus_cos_theta_d(wi, wo), eps) * np.maximum(cos_d, eps)
    return rtol + share * SCHLICK_CONDITIONING / gap[..., None]


def lobe_tolerances(material, wi, wo, model: str = "disney2014", rtol: float = 1e-12) -> dict:
    """``{lobe: tolerance}`` for the four lobes and ``"total"`` (the worst lobe's), each (..., 3)."""
    wi, wo = np.broadcast_arrays(np.asarray(wi, dtype=np.float64), np.asarray(wo, dtype=np.float64))
    shares = numpy_model.schlick_fractions(material, wi, wo, model)
    per_lobe = {name: schlick_tolerance(wi, wo, getattr(shares, name), rtol) for name in LOBES}
    per_lobe["total"] = np.maximum.reduce([per_lobe[name] for name in LOBES])
    return per_lobe


def assert_close_with_tolerance(actual, expected, tol, what: str = "") -> None:
    """|actual - expected| <= tol * max(|actual|, |expected|, 1e-300), elementwise (tol broadcasts)."""
    actual = np.asarray(actual, dtype=np.float64)
    expected = np.asarray(expected, dtype=np.float64)
    assert actual.shape == expected.shape, f"{what}: shape {actual.shape} != {expected.shape}"
    assert np.all(np.isfinite(actual)), f"{what}: non-finite values"
    err = np.abs(actual - expected) / np.maximum(np.maximum(np.abs(expected), np.abs(actual)), 1e-300)
    ratio = err / tol
    if ratio.size and ratio.max() > 1.0:
        i = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
        raise AssertionError(
            f"{what}: relative error {err[i]:.3e} > allowed {np.broadcast_to(tol, err.shape)[i]:.3e} at {i}: "
            f"{actual[i]!r} vs {expected[i]!r}"
        )


# --------------------------------------------------------------------------
# fixtures


@pytest.fixture
def rng(request) -> np.random.Generator:
    """A generator seeded from the test's node id: fixed per test, different across tests."""
    return seeded_rng(request.node.nodeid)


@pytest.fixture(params=MODELS)
def model(request) -> str:
    return request.param


@pytest.fixture
def default_material() -> pb.Material:
    return pb.Material()


# The tests a run selected (after -k and -m), for fixtures that run the heavy
# cases of a module together before its tests read their results.
SELECTED_TESTS = pytest.StashKey[list]()


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    config.stash[SELECTED_TESTS] = items


@pytest.fixture
def no_work(monkeypatch):
    """The command line's jobs themselves fail the test: a refused option never starts one
    (nor hangs the test)."""
    import principled_brdf.benchmark
    import principled_brdf.demo

    def job(*args, **kwargs):
        raise AssertionError("the job started")

    monkeypatch.setattr(pb.render, "render_sphere", job)
    monkeypatch.setattr(pb.render, "_sample", job)
    monkeypatch.setattr(principled_brdf.demo, "run", job)
    monkeypatch.setattr(principled_brdf.demo, "cpu_info", job)
    monkeypatch.setattr(principled_brdf.benchmark, "compare_with_numpy", job)
