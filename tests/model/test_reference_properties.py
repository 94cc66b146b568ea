"""docs/validation.md on the float64 reference: properties over random materials.

Hypothesis draws one uniform material per example over the domains of docs/model.md, "The model"
(edge values included) plus an explicit direction pair; each example also
evaluates a batch of seeded random pairs (grazing down to cos θ = 1e-4, mirror
and wi = wo pairs), so 200 examples cover ~10^4 triples per property.

Where a property compares two float64 evaluations of the same quantity the
tolerance is 1e-12 relative (symmetrically, against max(|a|, |b|)), plus the
float64 conditioning of Schlick(cos θd) = (1 - cos θd)^5 near cos θd = 1 (see
``conftest.schlick_tolerance`` and tests/model/test_reference_vs_numpy_model.py).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

import principled_brdf as pb
from conftest import (
    LOBES,
    MODELS,
    assert_close_with_tolerance,
    below_horizon_directions,
    directions_from_cos,
    lobe_tolerances,
    random_direction_pairs,
    random_material_arrays,
    seeded_rng,
)

SETTINGS = settings(
    max_examples=200,
    deadline=None,
    derandomize=True,
    database=None,
    # no shrinking: on ~50 float pairs it takes minutes and the unshrunk example is reproducible anyway
    phases=(Phase.explicit, Phase.generate),
    suppress_health_check=[HealthCheck.too_slow],
)
BATCH = 48

# --------------------------------------------------------------------------
# strategies
#
# Each value comes from one drawn integer k in [0, 2^16): the lowest fifth of the
# range picks an edge value of the domain (so shrinking goes to edges), the rest
# spreads uniformly over the range. Drawing plain integers instead of
# one_of(sampled_from, floats) per parameter keeps generation ~5x cheaper.

K = 1 << 16
EDGE_SHARE = K // 5


def _value(k, lo, hi, edges):
    if k < EDGE_SHARE:
        return float(edges[k % len(edges)])
    return lo + (hi - lo) * (k - EDGE_SHARE) / (K - 1 - EDGE_SHARE)


UNIT_EDGES = (0.0, 1.0)
# (lo, hi, edges); unbounded parameters (docs/model.md, "The model": >= 0) go up to 10
SCALARS = {
    "metallic": (0.0, 1.0, UNIT_EDGES),
    "subsurface": (0.0, 1.0, UNIT_EDGES),
    "specular": (0.0, 10.0, (0.0, 0.5, 1.0, 2.0)),
    "specular_tint": (0.0, 1.0, UNIT_EDGES),
    "roughness": (0.0, 2.0, (0.0, 1e-3, 0.03, 1.0)),
    "anisotropic": (0.0, 1.0, UNIT_EDGES),
    "sheen": (0.0, 10.0, (0.0, 1.0, 2.0)),
    "sheen_tint": (0.0, 1.0, UNIT_EDGES),
    "clearcoat": (0.0, 10.0, (0.0, 1.0, 2.0)),
    "clearcoat_gloss": (0.0, 1.0, UNIT_EDGES),
}
COLOR_PRESETS = ((0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0), (0.82, 0.67, 0.16))
CHANNEL_EDGES = (0.0, 1.0, 1e-300, 0.5)


def _material(ks):
    mode, *channels = ks[:4]
    if mode < EDGE_SHARE:
        color = COLOR_PRESETS[mode % len(COLOR_PRESETS)]
    else:
        color = tuple(_value(k, 0.0, 3.0, CHANNEL_EDGES) for k in channels)
    params = {"base_color": color}
    for k, (name, (lo, hi, edges)) in zip(ks[4:], SCALARS.items()):
        params[name] = _value(k, lo, hi, edges)
    return params


MATERIALS = st.tuples(*[st.integers(0, K - 1)] * (4 + len(SCALARS))).map(_material)

COS_EDGES = (1e-4, 1e-3, 0.05, 0.5, 1.0)


def _direction(k_cos, k_phi):
    c = _value(k_cos, 1e-4, 1.0, COS_EDGES)
    phi = 2.0 * np.pi * k_phi / K
    s = np.sqrt(1.0 - c * c)
    return np.array([s * np.cos(phi), s * np.sin(phi), c])


DIRECTIONS = st.tuples(st.integers(0, K - 1), st.integers(0, K - 1)).map(lambda ks: _direction(*ks))
PHI = st.integers(0, K - 1).map(lambda k: 2.0 * np.pi * k / K)


def _direction_batch(ks):
    """One drawn pair, its mirror and retro variants, then BATCH seeded random pairs."""
    wi0, wo0 = _direction(ks[0], ks[1]), _direction(ks[2], ks[3])
    wi, wo = random_direction_pairs(np.random.default_rng(ks[4]), BATCH)
    mirror = wi0 * np.array([-1.0, -1.0, 1.0])
    return np.vstack([wi0, wi0, wi0, wi]), np.vstack([wo0, mirror, wi0, wo])


PAIRS = st.tuples(*[st.integers(0, K - 1)] * 4, st.integers(0, 2**32 - 1)).map(_direction_batch)


# --------------------------------------------------------------------------
# reciprocity, sign, finiteness, horizon


@SETTINGS
@given(params=MATERIALS, pairs=PAIRS)
def test_reciprocity(params, pairs):
    wi, wo = pairs
    material = pb.Material(**params)
    for model in MODELS:
        forward = pb.reference.eval_lobes(material, wi, wo, model=model)
        backward = pb.reference.eval_lobes(material, wo, wi, model=model)
        tol = lobe_tolerances(params, wi, wo, model)
        for name in LOBES:
            assert_close_with_tolerance(
                getattr(backward, name), getattr(forward, name), tol[name], f"{model} reciprocity {name}"
            )
        assert_close_with_tolerance(
            pb.reference.eval(material, wo, wi, model=model),
            pb.reference.eval(material, wi, wo, model=model),
            tol["total"],
            f"{model} reciprocity total",
        )


@pytest.mark.parametrize("model", MODELS)
def test_reciprocity_dense_per_element(model):
    # the same property over 10^5 seeded per-element triples (materials with edges, grazing, peaks)
    rng = seeded_rng("reciprocity_dense", model)
    params = random_material_arrays(rng, 100_000)
    wi, wo = random_direction_pairs(rng, 100_000)
    material = pb.Material(**params)
    forward = pb.reference.eval_lobes(material, wi, wo, model=model)
    backward = pb.reference.eval_lobes(material, wo, wi, model=model)
    tol = lobe_tolerances(params, wi, wo, model)
    for name in LOBES:
        assert_close_with_tolerance(getattr(backward, name), getattr(forward, name), tol[name], f"reciprocity {name}")
        assert np.all(getattr(forward, name) >= 0.0) and np.all(np.isfinite(getattr(forward, name)))


@SETTINGS
@given(params=MATERIALS, pairs=PAIRS)
def test_non_negative_and_finite(params, pairs):
    wi, wo = pairs
    material = pb.Material(**params)
    for model in MODELS:
        lobes = pb.reference.eval_lobes(material, wi, wo, model=model)
        for name in LOBES:
            value = getattr(lobes, name)
            assert np.all(np.isfinite(value)), f"{model} {name} not finite"
            assert np.all(value >= 0.0), f"{model} {name} negative"
        f = pb.reference.eval(material, wi, wo, model=model, cosine=True)
        assert np.all(np.isfinite(f)) and np.all(f >= 0.0)


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("roughness", [0.0, 1e-3, 1.0, 10.0])
@pytest.mark.parametrize("anisotropic", [0.0, 1.0])
def test_finite_at_grazing_and_at_the_peaks(model, roughness, anisotropic):
    # cos θ = 1e-4 on either side, exact mirror, exact retro-reflection, the sharpest clearcoat
    c = np.array([1e-4, 1e-4, 1e-3, 0.5, 1.0])
    wi = directions_from_cos(np.random.default_rng(1), np.repeat(c, 64))
    wo = directions_from_cos(np.random.default_rng(2), np.tile(c, 64))
    material = pb.Material(
        roughness=roughness, anisotropic=anisotropic, clearcoat=2.0, clearcoat_gloss=1.0, sheen=2.0, subsurface=1.0
    )
    for a, b in ((wi, wo), (wi, wi * np.array([-1.0, -1.0, 1.0])), (wi, wi)):
        for name, value in pb.reference.eval_lobes(material, a, b, model=model)._asdict().items():
            assert np.all(np.isfinite(value)) and np.all(value >= 0.0), name


@SETTINGS
@given(params=MATERIALS, up=DIRECTIONS, seed=st.integers(0, 2**32 - 1))
def test_zero_below_the_horizon(params, up, seed):
    down = below_horizon_directions(np.random.default_rng(seed), 16)
    up = np.broadcast_to(up, down.shape)
    material = pb.Material(**params)
    for model in MODELS:
        for wi, wo in ((down, up), (up, down), (down, down[::-1]), (down, down * np.array([-1.0, -1.0, 1.0]))):
            assert np.all(pb.reference.eval(material, wi, wo, model=model) == 0.0)
            assert all(np.all(lobe == 0.0) for lobe in pb.reference.eval_lobes(material, wi, wo, model=model))


# --------------------------------------------------------------------------
# symmetries of the frame


@SETTINGS
@given(params=MATERIALS, pairs=PAIRS)
def test_mirror_symmetry_of_the_tangent_frame(params, pairs):
    # D, G and every cosine depend on the x and y components only through their
    # squares: reflecting both directions in the x-z or y-z plane changes nothing.
    wi, wo = pairs
    material = pb.Material(**params)
    for model in MODELS:
        f = pb.reference.eval(material, wi, wo, model=model)
        for flip in ([-1.0, 1.0, 1.0], [1.0, -1.0, 1.0], [-1.0, -1.0, 1.0]):
            g = pb.reference.eval(material, wi * flip, wo * flip, model=model)
            assert_close_with_tolerance(g, f, 1e-14, f"{model} flip {flip}")


@SETTINGS
@given(params=MATERIALS, pairs=PAIRS, phi=PHI)
def test_isotropic_material_is_invariant_under_rotation_about_n(params, pairs, phi):
    wi, wo = pairs
    params = dict(params, anisotropic=0.0)
    material = pb.Material(**params)
    c, s = np.cos(phi), np.sin(phi)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    wi_r, wo_r = wi @ rotation.T, wo @ rotation.T
    for model in MODELS:
        f = pb.reference.eval(material, wi, wo, model=model)
        g = pb.reference.eval(material, wi_r, wo_r, model=model)
        # the rotation moves the inputs by an ulp or so; a peak as sharp as alpha = 0.001
        # (relative slope of D ~ 2 / alpha^2 in sin^2 θh) turns that into up to ~1e-10
        tol = lobe_tolerances(params, wi, wo, model, rtol=1e-9)["total"]
        assert_close_with_tolerance(g, f, tol, f"{model} rotation")


def test_anisotropy_stretches_along_x():
    # alpha_x > alpha_y for anisotropic > 0: a half vector tilted towards x sees a
    # wider lobe (larger D) than one tilted by the same angle towards y
    material = pb.Material(roughness=0.5, anisotropic=0.8, metallic=1.0, base_color=(1, 1, 1))
    along_x = np.array([0.6, 0.0, 0.8])
    along_y = np.array([0.0, 0.6, 0.8])
    assert np.all(pb.reference.eval(material, along_x, along_x) > pb.reference.eval(material, along_y, along_y))


# --------------------------------------------------------------------------
# structure of the model: linearity, bounds, lobes that must vanish

LINEAR_PARAMETERS = ("metallic", "subsurface", "specular", "specular_tint", "sheen", "sheen_tint", "clearcoat")


@SETTINGS
@given(params=MATERIALS, pairs=PAIRS, name=st.sampled_from(LINEAR_PARAMETERS), t=st.floats(0.0, 1.0))
def test_affine_in_the_linear_parameters(params, pairs, name, t):
    # docs/model.md, "The model": with the others fixed, f is affine in each of these parameters
    # (e.g. metallic is "a linear blend of two models").
    wi, wo = pairs
    for model in MODELS:
        f0 = pb.reference.eval(pb.Material(**dict(params, **{name: 0.0})), wi, wo, model=model)
        f1 = pb.reference.eval(pb.Material(**dict(params, **{name: 1.0})), wi, wo, model=model)
        ft = pb.reference.eval(pb.Material(**dict(params, **{name: t})), wi, wo, model=model)
        expected = f0 + (f1 - f0) * t
        assert np.all(np.abs(ft - expected) <= 1e-12 * (np.abs(f0) + np.abs(f1)) + 1e-300), f"{model} {name}"


@SETTINGS
@given(params=MATERIALS, pairs=PAIRS)
def test_diffuse_and_sheen_lobe_bounds(params, pairs):
    # Diffuse: each factor mix(1, Fd90, F) lies between min(1, Fd90) >= 0.5 and
    # max(1, Fd90), with Fd90 <= 0.5 + 2 roughness; and ss >= 1.25 * 0.5 since
    # 1/(cos θl + cos θv) >= 1/2. So, with L = base (1 - metallic) / π,
    #   0.25 L <= diffuse, and diffuse <= max(1, 0.5 + 2 roughness)^2 L when subsurface = 0.
    # Sheen: FH in [0, 1], so 0 <= sheen lobe <= sheen Csheen (1 - metallic).
    # (The lobes do not depend on the model; test_models_share_... checks that.)
    wi, wo = pairs
    base = np.asarray(params["base_color"])
    lambert = base * (1.0 - params["metallic"]) / np.pi
    lobes = pb.reference.eval_lobes(pb.Material(**params), wi, wo)
    assert np.all(lobes.diffuse >= 0.25 * lambert * (1 - 1e-14))
    smooth = pb.reference.eval_lobes(pb.Material(**dict(params, subsurface=0.0)), wi, wo).diffuse
    upper = max(1.0, 0.5 + 2.0 * params["roughness"]) ** 2
    assert np.all(smooth >= 0.25 * lambert * (1 - 1e-14))
    assert np.all(smooth <= upper * lambert * (1 + 1e-14) + 1e-300)  # + 1e-300: denormal base colors
    lum = 0.3 * base[0] + 0.6 * base[1] + 0.1 * base[2]
    tint = base / lum if lum >= 2.0 ** -126 else np.ones(3)
    c_sheen = (1.0 - params["sheen_tint"]) + tint * params["sheen_tint"]  # mix in the form that keeps tiny tints
    assert np.all(lobes.sheen <= params["sheen"] * c_sheen * (1.0 - params["metallic"]) * (1 + 1e-14) + 1e-300)


def test_white_smooth_dielectric_diffuse_never_exceeds_lambert():
    wi, wo = random_direction_pairs(np.random.default_rng(3), 20000)
    diffuse = pb.reference.eval_lobes(pb.Material(base_color=(1, 1, 1), roughness=0.0), wi, wo).diffuse
    assert diffuse.max() <= 1.0 / np.pi * (1 + 1e-14)
    assert diffuse.min() >= 0.25 / np.pi * (1 - 1e-14)


@SETTINGS
@given(params=MATERIALS, pairs=PAIRS)
def test_metal_has_no_diffuse_or_sheen_and_ignores_dielectric_parameters(params, pairs):
    wi, wo = pairs
    metal = dict(params, metallic=1.0)
    other = dict(metal, specular=0.0, specular_tint=1.0 - params["specular_tint"], subsurface=0.3, sheen=1.0, sheen_tint=0.1)
    # Cspec0 = mix(d, base, 1) = d + (base - d) * 1 is base only up to rounding of d,
    # the dielectric part (<= 0.08 specular max(Ctint) <= 0.8 specular): an absolute
    # error of a few ulp of d times Gs Ds, which the white metal's specular lobe gives.
    d_max = 0.8 * max(params["specular"], 1.0)
    for model in MODELS:
        lobes = pb.reference.eval_lobes(pb.Material(**metal), wi, wo, model=model)
        assert np.all(lobes.diffuse == 0.0) and np.all(lobes.sheen == 0.0)
        f = pb.reference.eval(pb.Material(**metal), wi, wo, model=model)
        g = pb.reference.eval(pb.Material(**other), wi, wo, model=model)
        gs_ds = pb.reference.eval_lobes(pb.Material(**dict(metal, base_color=(1, 1, 1))), wi, wo, model=model).specular
        assert np.all(np.abs(f - g) <= 1e-14 * np.maximum(np.abs(f), np.abs(g)) + 1e-15 * d_max * gs_ds), model


@SETTINGS
@given(params=MATERIALS, other=MATERIALS, pairs=PAIRS)
def test_clearcoat_is_grey_and_depends_only_on_clearcoat_parameters(params, other, pairs):
    wi, wo = pairs
    swapped = dict(other, clearcoat=params["clearcoat"], clearcoat_gloss=params["clearcoat_gloss"])
    for model in MODELS:
        a = pb.reference.eval_lobes(pb.Material(**params), wi, wo, model=model).clearcoat
        assert np.all(a[..., 0] == a[..., 1]) and np.all(a[..., 1] == a[..., 2])
        b = pb.reference.eval_lobes(pb.Material(**swapped), wi, wo, model=model).clearcoat
        assert_close_with_tolerance(b, a, 1e-14, f"{model} clearcoat vs other parameters")
        if params["clearcoat"] == 0.0:
            assert np.all(a == 0.0)


@SETTINGS
@given(params=MATERIALS, pairs=PAIRS)
def test_models_share_everything_but_the_specular_lobe(params, pairs):
    wi, wo = pairs
    material = pb.Material(**params)
    a = pb.reference.eval_lobes(material, wi, wo, model="disney2014")
    b = pb.reference.eval_lobes(material, wi, wo, model="disney2012")
    for name in ("diffuse", "sheen", "clearcoat"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
