"""docs/validation.md: the float64 reference against an independent numpy transcription of
docs/model.md, "The model" (tests/numpy_model.py).

Tolerance (stated once, used throughout): every channel of every lobe and of the
sum must satisfy

    |ref - model| <= tol * max(|ref|, |model|, 1e-300),
    tol = 1e-12 + s * 40 eps / ((1 - cos θd) cos θd)          (eps = 2.2e-16)

where s in [0, 1] is the share of that lobe's value carried by its
``FH = Schlick(cos θd) = (1 - cos θd)^5`` factor (``numpy_model.schlick_fractions``:
0 for diffuse, 1 for sheen, |1 - Cspec0| FH / Fs for specular, 0.96 FH / Fr for
clearcoat). The second term is not slack in the formula; it is the float64
conditioning of FH: cos θd is computed to a few ulp (times 1/|wi + wo| when
wi ~ -wo near the horizon), and the fifth power of 1 - cos θd turns that into
a relative error of ~5 * (few ulp) / (1 - cos θd) in FH (seen: 3e-9 on a sheen
lobe of 1e-33 at 1 - cos θd = 7e-7). Diffuse and clearcoat are thus held to
~1e-12 everywhere; for 0.01 <= 1 - cos θd (most random pairs) the bound is below
~1.1e-12 unless cos θd is tiny, and a separate test checks plain 1e-12 on
those pairs.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import numpy_model
import principled_brdf as pb
from conftest import (
    LOBES,
    MODELS,
    assert_close_with_tolerance,
    assert_relative_close,
    below_horizon_directions,
    random_directions,
    random_material_arrays,
    random_material_dict,
    lobe_tolerances,
    one_minus_cos_theta_d,
    random_direction_pairs,
    reflect_about_normal,
    seeded_rng,
)

RTOL = 1e-12
N_RANDOM = 200_000


@pytest.fixture(scope="module")
def random_triples():
    rng = seeded_rng("test_reference", "random_triples")
    params = random_material_arrays(rng, N_RANDOM)
    wi, wo = random_direction_pairs(rng, N_RANDOM)
    return params, wi, wo


# --------------------------------------------------------------------------
# reference vs numpy model


@pytest.mark.parametrize("model", MODELS)
def test_matches_numpy_model_per_element(random_triples, model):
    params, wi, wo = random_triples
    ref = pb.reference.eval_lobes(pb.Material(**params), wi, wo, model=model)
    expected = numpy_model.eval_lobes(params, wi, wo, model)
    tol = lobe_tolerances(params, wi, wo, model)
    for name in LOBES:
        assert_close_with_tolerance(getattr(ref, name), getattr(expected, name), tol[name], f"{model} {name}")
    total = pb.reference.eval(pb.Material(**params), wi, wo, model=model)
    assert_close_with_tolerance(total, expected.total(), tol["total"], f"{model} total")


@pytest.mark.parametrize("model", MODELS)
def test_matches_numpy_model_plain_1e12_where_well_conditioned(random_triples, model):
    params, wi, wo = random_triples
    cos_d = np.linalg.norm(wi + wo, axis=-1) / 2.0
    keep = (one_minus_cos_theta_d(wi, wo) >= 0.01) & (cos_d >= 0.01)
    assert keep.mean() > 0.75
    params = {name: value[keep] for name, value in params.items()}
    wi, wo = wi[keep], wo[keep]
    ref = pb.reference.eval_lobes(pb.Material(**params), wi, wo, model=model)
    expected = numpy_model.eval_lobes(params, wi, wo, model)
    for name in LOBES:
        assert_relative_close(getattr(ref, name), getattr(expected, name), RTOL, what=f"{model} {name}")
    assert_relative_close(ref.total(), expected.total(), RTOL, what=f"{model} total")


@pytest.mark.parametrize("model", MODELS)
def test_uniform_materials_match_numpy_model(model):
    rng = seeded_rng("uniform_materials", model)
    for _ in range(20):
        params = random_material_dict(rng)
        wi, wo = random_direction_pairs(rng, 2000)
        ref = pb.reference.eval_lobes(pb.Material(**params), wi, wo, model=model)
        expected = numpy_model.eval_lobes(params, wi, wo, model)
        tol = lobe_tolerances(params, wi, wo, model)
        for name in LOBES:
            assert_close_with_tolerance(getattr(ref, name), getattr(expected, name), tol[name], f"{params} {name}")


@pytest.mark.parametrize("model", MODELS)
def test_eval_is_sum_of_lobes(random_triples, model):
    params, wi, wo = random_triples
    material = pb.Material(**params)
    total = pb.reference.eval(material, wi, wo, model=model)
    lobes = pb.reference.eval_lobes(material, wi, wo, model=model)
    assert_relative_close(total, lobes.total(), 1e-15, what="eval vs sum of eval_lobes")


def test_models_differ_only_in_specular_g(random_triples):
    params, wi, wo = random_triples
    material = pb.Material(**params)
    a = pb.reference.eval_lobes(material, wi, wo, model="disney2014")
    b = pb.reference.eval_lobes(material, wi, wo, model="disney2012")
    for name in ("diffuse", "sheen", "clearcoat"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert np.mean(a.specular != b.specular) > 0.5
    assert np.array_equal(pb.reference.eval(material, wi, wo), pb.reference.eval(material, wi, wo, model="disney2014"))


# --------------------------------------------------------------------------
# materials: uniform vs per element, broadcasting


@pytest.mark.parametrize("model", MODELS)
def test_uniform_and_per_element_give_identical_results(model):
    rng = seeded_rng("uniform_vs_per_element", model)
    n = 5000
    wi, wo = random_direction_pairs(rng, n)
    for _ in range(10):
        params = random_material_dict(rng)
        uniform = pb.Material(**params)
        per_element = pb.Material(
            **{k: np.broadcast_to(np.asarray(v, dtype=float), (n, 3) if k == "base_color" else (n,)) for k, v in params.items()}
        )
        assert uniform.is_uniform and per_element.shape == (n,)
        a = pb.reference.eval_lobes(uniform, wi, wo, model=model)
        b = pb.reference.eval_lobes(per_element, wi, wo, model=model)
        for name in LOBES:
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def test_mixed_uniform_and_per_element_parameters():
    rng = seeded_rng("mixed_uniform_per_element")
    n = 3000
    wi, wo = random_direction_pairs(rng, n)
    arrays = random_material_arrays(rng, n)
    uniform = random_material_dict(rng)
    # every other parameter per element, the rest uniform
    names = list(arrays)
    mixed = {name: (arrays[name] if i % 2 == 0 else uniform[name]) for i, name in enumerate(names)}
    full = {
        name: (arrays[name] if i % 2 == 0 else np.broadcast_to(np.asarray(uniform[name], float), arrays[name].shape))
        for i, name in enumerate(names)
    }
    a = pb.reference.eval(pb.Material(**mixed), wi, wo)
    b = pb.reference.eval(pb.Material(**full), wi, wo)
    np.testing.assert_array_equal(a, b)
    tol = lobe_tolerances(mixed, wi, wo)["total"]
    assert_close_with_tolerance(a, numpy_model.eval(mixed, wi, wo), tol, "mixed uniform/per element")


def test_broadcasting_of_leading_shapes():
    rng = seeded_rng("broadcasting")
    wi = random_directions(rng, (5, 1))
    wo = random_directions(rng, (1, 4))
    roughness = np.array([0.0, 0.2, 0.6, 1.0])
    base_color = rng.uniform(0, 1, (5, 1, 3))
    material = pb.Material(roughness=roughness, base_color=base_color, clearcoat=0.7, sheen=0.5)
    assert material.shape == (5, 4)
    f = pb.reference.eval(material, wi, wo)
    lobes = pb.reference.eval_lobes(material, wi, wo)
    assert f.shape == (5, 4, 3) and f.dtype == np.float64
    assert all(lobe.shape == (5, 4, 3) for lobe in lobes)
    for i in range(5):
        for j in range(4):
            single = pb.Material(roughness=roughness[j], base_color=base_color[i, 0], clearcoat=0.7, sheen=0.5)
            expected = pb.reference.eval(single, wi[i, 0], wo[0, j])
            np.testing.assert_array_equal(f[i, j], expected)
    wi_b, wo_b = np.broadcast_arrays(wi, wo)
    params = dict(roughness=roughness, base_color=base_color, clearcoat=0.7, sheen=0.5)
    tol = lobe_tolerances(params, wi_b, wo_b)["total"]
    assert_close_with_tolerance(f, numpy_model.eval(params, wi, wo), tol, "broadcast")


def test_material_shape_can_extend_the_directions():
    wi = np.array([0.0, 0.6, 0.8])
    wo = np.array([0.28, -0.96, 0.0]) * 0.6 + np.array([0.0, 0.0, 0.8])
    roughness = np.linspace(0.0, 1.0, 7)
    f = pb.reference.eval(pb.Material(roughness=roughness), wi, wo)
    assert f.shape == (7, 3)
    for k, r in enumerate(roughness):
        np.testing.assert_array_equal(f[k], pb.reference.eval(pb.Material(roughness=r), wi, wo))


def test_single_pair_and_empty_batch():
    n = np.array([0.0, 0.0, 1.0])
    assert pb.reference.eval(pb.Material(), n, n).shape == (3,)
    assert pb.reference.eval(pb.Material(), [0, 0, 1], (0, 0, 1)).shape == (3,)
    empty = pb.reference.eval(pb.Material(), np.zeros((0, 3)), np.zeros((0, 3)))
    assert empty.shape == (0, 3) and empty.dtype == np.float64
    lobes = pb.reference.eval_lobes(pb.Material(), np.zeros((2, 0, 3)), n)
    assert all(lobe.shape == (2, 0, 3) for lobe in lobes)


def test_float32_and_integer_directions_are_accepted():
    rng = seeded_rng("dtypes")
    wi, wo = random_direction_pairs(rng, 100)
    m = pb.Material(roughness=0.4)
    f32 = pb.reference.eval(m, wi.astype(np.float32), wo.astype(np.float32))
    f64 = pb.reference.eval(m, wi.astype(np.float32).astype(np.float64), wo.astype(np.float32).astype(np.float64))
    np.testing.assert_array_equal(f32, f64)
    axis = np.array([[0, 0, 1]], dtype=np.int64)
    np.testing.assert_array_equal(pb.reference.eval(m, axis, axis), pb.reference.eval(m, axis.astype(float), axis))


# --------------------------------------------------------------------------
# cosine option, hemisphere


@pytest.mark.parametrize("model", MODELS)
def test_cosine_option_multiplies_by_cos_theta_l(random_triples, model):
    params, wi, wo = random_triples
    params = {k: v[:20000] for k, v in params.items()}
    wi, wo = wi[:20000], wo[:20000]
    material = pb.Material(**params)
    f = pb.reference.eval(material, wi, wo, model=model)
    fc = pb.reference.eval(material, wi, wo, model=model, cosine=True)
    assert_relative_close(fc, f * wi[:, 2:3], 1e-15, what="eval cosine")
    # cos θl, not cos θv
    assert not np.allclose(fc, f * wo[:, 2:3], rtol=1e-6)
    lobes = pb.reference.eval_lobes(material, wi, wo, model=model)
    lobes_c = pb.reference.eval_lobes(material, wi, wo, model=model, cosine=True)
    for name in LOBES:
        assert_relative_close(getattr(lobes_c, name), getattr(lobes, name) * wi[:, 2:3], 1e-15, what=name)


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("cosine", [False, True])
def test_below_horizon_is_exactly_zero(model, cosine):
    rng = seeded_rng("below_horizon", model, cosine)
    n = 4000
    params = random_material_arrays(rng, n)
    # some materials with very large values (mirror peaks, strong clearcoat)
    params["roughness"][: n // 4] = 0.0
    params["clearcoat"][: n // 4] = 2.0
    above = random_directions(rng, n)
    below = below_horizon_directions(rng, n)
    # exact mirror pairs straddling the horizon test the largest D values
    for wi, wo in (
        (below, above),
        (above, below),
        (below, below_horizon_directions(rng, n)),
        (below, reflect_about_normal(below)),
        (below, -reflect_about_normal(below)),
    ):
        material = pb.Material(**params)
        f = pb.reference.eval(material, wi, wo, model=model, cosine=cosine)
        assert np.all(f == 0.0), "f must be exactly 0 below the horizon"
        lobes = pb.reference.eval_lobes(material, wi, wo, model=model, cosine=cosine)
        for name in LOBES:
            assert np.all(getattr(lobes, name) == 0.0), name


@pytest.mark.parametrize("model", MODELS)
def test_exactly_on_the_horizon_is_zero(model):
    # docs/model.md, "The model": f = 0 when cos θ <= 0 (the shader's test is `< 0`; the README's definition is normative)
    horizon = np.array([[1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [np.sqrt(0.5), np.sqrt(0.5), 0.0]])
    up = np.array([[0.0, 0.0, 1.0], [0.6, 0.0, 0.8], [-0.6, 0.0, 0.8]])
    material = pb.Material(roughness=0.3, sheen=1.0, clearcoat=1.0, subsurface=1.0)
    for wi, wo in ((horizon, up), (up, horizon), (horizon, horizon)):
        assert np.all(pb.reference.eval(material, wi, wo, model=model) == 0.0)
    assert np.all(numpy_model.eval(material, horizon, up, model) == 0.0)


# --------------------------------------------------------------------------
# spot values derived by hand


def _unit(x, y, z):
    return np.array([x, y, z], dtype=np.float64)


N = _unit(0.0, 0.0, 1.0)
SIN60 = math.sqrt(0.75)


def _spot_default_normal_incidence():
    # Default material, wi = wo = n: cos θl = cos θv = cos θh = cos θd = 1, FL = FV = FH = 0, h = n.
    # diffuse: Fd = mix(1, Fd90, 0)^2 = 1 -> base/π (subsurface 0, metallic 0)
    # specular: alpha = 0.5^2 = 0.25, ax = ay = 0.25;
    #   Ds = 1 / (π ax ay (0 + 0 + 1)^2) = 1 / (π 0.0625) = 16/π
    #   Fs = Cspec0 = 0.5 * 0.08 * mix(1, Ctint, 0) = 0.04
    #   S(n) = 1 / (1 + sqrt(0 + 0 + 1)) = 1/2 -> Gs = 1/4   (2012: Siso(n, g) = 1/(1 + 1) too)
    #   -> 0.25 * 0.04 * 16/π = 0.16/π
    # sheen 0, clearcoat 0.  f = (base + 0.16)/π = (0.98, 0.83, 0.32)/π
    base = np.array([0.82, 0.67, 0.16])
    return {}, N, N, {"total": (base + 0.16) / math.pi, "diffuse": base / math.pi, "specular": np.full(3, 0.16 / math.pi)}


def _spot_subsurface_normal_incidence():
    # subsurface 1, wi = wo = n: Fss90 = roughness * 1, FL = FV = 0 -> Fss = 1,
    # ss = 1.25 (1 * (1/(1 + 1) - 0.5) + 0.5) = 1.25 * 0.5 = 0.625 -> diffuse = 0.625 base/π
    # metallic 0.2 scales it by 0.8: 0.5 base / π.
    base = np.array([0.3, 0.6, 0.9])
    return dict(base_color=base, subsurface=1.0, metallic=0.2), N, N, {"diffuse": 0.5 * base / math.pi}


def _spot_metal_normal_incidence():
    # metallic 1, base (0.9, 0.6, 0.2), roughness 0.3, wi = wo = n:
    # alpha = 0.09, Ds = 1/(π 0.09^2) = 1/(0.0081 π); Fs = Cspec0 = base (FH = 0);
    # Gs = 1/4; diffuse and sheen weighted by (1 - 1) = 0 -> f = base / (0.0324 π)
    base = np.array([0.9, 0.6, 0.2])
    return dict(base_color=base, metallic=1.0, roughness=0.3, sheen=1.0), N, N, {"total": base / (0.0324 * math.pi)}


def _spot_mirror_metal_normal_incidence():
    # roughness 0: ax = ay = max(0.001, 0) = 0.001, Ds(n) = 1/(π 1e-6); Gs = 1/4; metal -> Fs = base
    # f = base * 0.25e6 / π
    base = np.array([1.0, 0.5, 0.0])
    return dict(base_color=base, metallic=1.0, roughness=0.0), N, N, {"total": base * 0.25e6 / math.pi}


def _spot_clearcoat_gloss_normal_incidence():
    # base black, specular 0 -> diffuse 0, Cspec0 = 0, Fs = mix(0, 1, FH = 0) = 0 -> specular 0
    # clearcoat 1, gloss 1: ac = mix(0.1, 0.001, 1) = 0.001, ac^2 = 1e-6, cos θh = 1:
    #   Dr = (1e-6 - 1) / (π ln(1e-6) (1e-6 * 1 + 0)) = (1 - 1e-6) / (π 1e-6 * 6 ln 10)
    #   Fr = 0.04, Siso(n, 0.25) = 1/(1 + sqrt(0.0625 + 1 - 0.0625)) = 1/2 -> Gr = 1/4
    #   f = 0.25 * 1 * 1/4 * 0.04 * Dr = 0.0025 Dr  (about 57.6)
    dr = (1 - 1e-6) / (math.pi * 1e-6 * 6 * math.log(10))
    return (
        dict(base_color=(0, 0, 0), specular=0.0, clearcoat=1.0, clearcoat_gloss=1.0),
        N,
        N,
        {"total": np.full(3, 0.0025 * dr), "clearcoat": np.full(3, 0.0025 * dr)},
    )


def _spot_rough_black_metal_mirror_60():
    # base black, metallic 1, roughness 1, clearcoat 2, gloss 0; wi = (sin60, 0, 1/2), wo = (-sin60, 0, 1/2):
    # H = (0, 0, 1) -> h = n, cos θh = 1, cos θd = wi.h = 1/2, FH = (1/2)^5 = 1/32
    # specular: ax = ay = 1, Ds = 1/(π (0 + 0 + 1)^2) = 1/π
    #   S(w) = 1/(1/2 + sqrt(3/4 + 0 + 1/4)) = 2/3 -> Gs = 4/9  (2012: alpha_g = 1, Siso = 1/(1/2 + 1) = 2/3 too)
    #   Fs = mix(Cspec0 = 0, 1, 1/32) = 1/32 -> specular = 4/9 * 1/32 / π = 1/(72 π)
    # clearcoat: ac = 0.1, ac^2 = 0.01, Dr = 0.99 / (π ln(0.01) * 0.01 ... sign) = 0.99 / (0.02 π ln 10) = 99/(2 π ln 10)
    #   Fr = 0.04 + 0.96/32 = 0.07
    #   Siso(1/2, 1/4) = 1/(1/2 + sqrt(1/16 + 1/4 - 1/64)) = 1/(1/2 + sqrt(19)/8) = 8/(4 + sqrt 19)
    #   Gr = 64 / (4 + sqrt 19)^2
    #   clearcoat = 0.25 * 2 * Gr * 0.07 * Dr
    # diffuse = sheen = 0 (metallic 1)
    wi, wo = _unit(SIN60, 0.0, 0.5), _unit(-SIN60, 0.0, 0.5)
    specular = 1.0 / (72.0 * math.pi)
    dr = 99.0 / (2.0 * math.pi * math.log(10.0))
    gr = 64.0 / (4.0 + math.sqrt(19.0)) ** 2
    clearcoat = 0.25 * 2.0 * gr * 0.07 * dr
    return (
        dict(base_color=(0, 0, 0), metallic=1.0, roughness=1.0, clearcoat=2.0, clearcoat_gloss=0.0, sheen=1.0),
        wi,
        wo,
        {"specular": np.full(3, specular), "clearcoat": np.full(3, clearcoat), "total": np.full(3, specular + clearcoat)},
    )


def _spot_sheen_and_diffuse_at_grazing():
    # wi = (sqrt(0.99), 0, 0.1), wo = (-sqrt(0.99), 0, 0.1): h = n, cos θd = 0.1, cos θl = cos θv = 0.1
    # FL = FV = FH = 0.9^5 = 0.59049
    # base (0.5, 0.25, 0.125): Cdlum = 0.15 + 0.15 + 0.0125 = 0.3125, Ctint = (1.6, 0.8, 0.4)
    # sheen 1, sheen_tint 0.5: Csheen = (1.3, 0.9, 0.7); metallic 0.25 -> x 0.75
    #   sheen = 0.59049 * (1.3, 0.9, 0.7) * 0.75
    # diffuse, roughness 0.5: Fd90 = 0.5 + 2 * 0.5 * 0.01 = 0.51,
    #   mix(1, 0.51, 0.59049) = 1 - 0.49 * 0.59049 = 0.7106599, Fd = 0.7106599^2
    #   diffuse = Fd * base / π * 0.75
    c = 0.1
    wi, wo = _unit(math.sqrt(1 - c * c), 0.0, c), _unit(-math.sqrt(1 - c * c), 0.0, c)
    fh = 0.9**5
    base = np.array([0.5, 0.25, 0.125])
    sheen = fh * np.array([1.3, 0.9, 0.7]) * 0.75
    fd = (1 - 0.49 * fh) ** 2
    diffuse = fd * base / math.pi * 0.75
    return (
        dict(base_color=base, sheen=1.0, sheen_tint=0.5, metallic=0.25, roughness=0.5),
        wi,
        wo,
        {"sheen": sheen, "diffuse": diffuse},
    )


def _spot_black_base_tints():
    # base black: Cdlum = 0 -> Ctint = (1, 1, 1) (no division by zero)
    # specular 1, specular_tint 1: Cspec0 = 0.08 * mix(1, 1, 1) = 0.08; sheen 1, sheen_tint 1: Csheen = 1
    # mirror pair at 60 deg: FH = 1/32 -> sheen = 1/32
    # roughness 1 -> specular = Gs Fs Ds = 4/9 * (0.08 + 0.92/32) / π   (Gs, Ds as in the mirror-60 spot)
    wi, wo = _unit(SIN60, 0.0, 0.5), _unit(-SIN60, 0.0, 0.5)
    return (
        dict(base_color=(0, 0, 0), specular=1.0, specular_tint=1.0, sheen=1.0, sheen_tint=1.0, roughness=1.0),
        wi,
        wo,
        {"sheen": np.full(3, 1 / 32), "specular": np.full(3, 4 / 9 * (0.08 + 0.92 / 32) / math.pi), "diffuse": np.zeros(3)},
    )


def _spot_2012_g(model):
    # white metal (Fs = Cspec0 = 1 at FH = 0), roughness 0.5, wi = wo = (0.8, 0, 0.6):
    # h = wi, cos θh = 0.6, cos θd = 1, FH = 0, alpha = 0.25, ax = ay = 0.25
    #   Ds = 1/(π a^2 ((0.8/0.25)^2 + 0.36)^2) = 1/(π 0.0625 (10.24 + 0.36)^2) = 16/(π 10.6^2) = 16/(112.36 π)
    # 2014: S = 1/(0.6 + sqrt((0.8*0.25)^2 + 0.36)) = 1/(0.6 + sqrt(0.4)), Gs = S^2
    # 2012: alpha_g = (0.5 + 0.25)^2 = 0.5625, g^2 = 0.31640625
    #   g^2 + c^2 - g^2 c^2 = 0.31640625 + 0.36 - 0.11390625 = 0.5625 -> sqrt = 0.75
    #   Siso = 1/(0.6 + 0.75) = 1/1.35, Gs = 1/1.8225
    w = _unit(0.8, 0.0, 0.6)
    ds = 16.0 / (112.36 * math.pi)
    gs = 1.0 / 1.8225 if model == "disney2012" else 1.0 / (0.6 + math.sqrt(0.4)) ** 2
    return dict(base_color=(1, 1, 1), metallic=1.0, roughness=0.5), w, w, {"total": np.full(3, gs * ds), "specular": np.full(3, gs * ds)}


def _spot_anisotropic(axis):
    # anisotropic 1: aspect = sqrt(0.1); roughness 0.5: ax = 0.25/sqrt(0.1), ay = 0.25 sqrt(0.1), ax ay = 0.0625
    # ax^2 = 0.625, ay^2 = 0.00625. White metal, wi = wo = 0.6 e + 0.8 n with e = x or y:
    # h = wi, cos θd = 1, Fs = 1
    # along x: Ds = 1/(π 0.0625 (0.36/0.625 + 0.64)^2) = 1/(π 0.0625 1.216^2)
    #          S = 1/(0.8 + sqrt(0.36 * 0.625 + 0.64)) = 1/(0.8 + sqrt(0.865))
    # along y: Ds = 1/(π 0.0625 (0.36/0.00625 + 0.64)^2) = 1/(π 0.0625 58.24^2)
    #          S = 1/(0.8 + sqrt(0.36 * 0.00625 + 0.64)) = 1/(0.8 + sqrt(0.64225))
    if axis == "x":
        w = _unit(0.6, 0.0, 0.8)
        ds = 1.0 / (math.pi * 0.0625 * 1.216**2)
        s = 1.0 / (0.8 + math.sqrt(0.865))
    else:
        w = _unit(0.0, 0.6, 0.8)
        ds = 1.0 / (math.pi * 0.0625 * 58.24**2)
        s = 1.0 / (0.8 + math.sqrt(0.64225))
    return dict(base_color=(1, 1, 1), metallic=1.0, roughness=0.5, anisotropic=1.0), w, w, {"total": np.full(3, s * s * ds)}


SPOTS = {
    "default_normal_incidence": (_spot_default_normal_incidence, MODELS),
    "subsurface_normal_incidence": (_spot_subsurface_normal_incidence, MODELS),
    "metal_normal_incidence": (_spot_metal_normal_incidence, MODELS),
    "mirror_metal_normal_incidence": (_spot_mirror_metal_normal_incidence, MODELS),
    "clearcoat_only": (_spot_clearcoat_gloss_normal_incidence, MODELS),
    "rough_black_metal_mirror_60": (_spot_rough_black_metal_mirror_60, MODELS),
    "sheen_diffuse_grazing": (_spot_sheen_and_diffuse_at_grazing, MODELS),
    "black_base_tints": (_spot_black_base_tints, MODELS),
    "g_2012": (lambda: _spot_2012_g("disney2012"), ("disney2012",)),
    "g_2014": (lambda: _spot_2012_g("disney2014"), ("disney2014",)),
    "anisotropic_x": (lambda: _spot_anisotropic("x"), ("disney2014",)),
    "anisotropic_y": (lambda: _spot_anisotropic("y"), ("disney2014",)),
}


@pytest.mark.parametrize(
    "spot, model", [(name, model) for name, (_, models) in SPOTS.items() for model in models]
)
def test_spot_value(spot, model):
    params, wi, wo, expected = SPOTS[spot][0]()
    material = pb.Material(**params)
    lobes = pb.reference.eval_lobes(material, wi, wo, model=model)
    total = pb.reference.eval(material, wi, wo, model=model)
    ours = numpy_model.eval_lobes(params, wi, wo, model)
    for name, value in expected.items():
        value = np.asarray(value, dtype=np.float64)
        got = total if name == "total" else getattr(lobes, name)
        mine = ours.total() if name == "total" else getattr(ours, name)
        assert_relative_close(got, value, RTOL, what=f"reference {spot} {name}")
        assert_relative_close(mine, value, RTOL, what=f"numpy model {spot} {name}")
