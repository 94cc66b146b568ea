"""docs/model-2015.md, "The thin sheet": ``model="disney2015_thin"`` in the float64
reference and the SIMD kernels against the independent numpy transcription
(tests/numpy_model_2015.py), its properties (two-sided, plainly reciprocal, the
diffuse split ``(1 - dt) : dt``), its sampler against its pdf over the whole
sphere from both faces, and the albedo bound. Tolerances as tests/model/test_bsdf2015.py.
"""

from __future__ import annotations

import numpy as np
import pytest

import chi_square as cs
import numpy_model_2015
import principled_brdf as pb
from conftest import seeded_rng
from test_bsdf2015 import FLOOR, RTOL, random_2015_material, sphere_directions

ISAS = pb.cpu_info()["available"]
THIN = "disney2015_thin"
LOBES_THIN = ("diffuse", "sheen", "specular", "clearcoat", "transmission", "diffuse_transmission")


def random_thin_material(rng, n):
    params = random_2015_material(rng, n)
    diff_trans = rng.uniform(0.0, 2.0, n)
    diff_trans[rng.random(n) < 0.2] = rng.choice((0.0, 1.0, 2.0), 1)
    return params | {"diff_trans": diff_trans}


@pytest.fixture(scope="module")
def triples():
    rng = seeded_rng("bsdf2015-thin", "triples")
    n = 100_000
    return random_thin_material(rng, n), sphere_directions(rng, n), sphere_directions(rng, n)


def mirrored(w):
    return w * [1.0, 1.0, -1.0]


def test_reference_matches_the_numpy_transcription(triples):
    params, wi, wo = triples
    reference = pb.reference.eval_lobes(pb.Material(**params), wi, wo, model=THIN)
    transcription = numpy_model_2015.eval_lobes(params, wi, wo, model=THIN)
    for name in LOBES_THIN:
        ours, theirs = getattr(reference, name), getattr(transcription, name)
        assert np.abs(theirs).max() > 0, f"{name}: the random pairs never reach this lobe"
        bound = RTOL.get(name, 1e-12) * (np.abs(theirs) + np.abs(theirs).max())
        worst = np.argmax((np.abs(ours - theirs) / bound).max(axis=1))
        assert np.all(np.abs(ours - theirs) <= bound), (
            f"{name}: {ours[worst]} vs {theirs[worst]} at wi {wi[worst]}, wo {wo[worst]}")
    assert np.all(reference.multiple_scattering == 0)
    # importance mode is radiance mode: the sheet does not bend the light
    material = pb.Material(**params)
    np.testing.assert_array_equal(pb.reference.eval(material, wi, wo, model=THIN, mode="importance"),
                                  pb.reference.eval(material, wi, wo, model=THIN))


def test_two_sided_and_plainly_reciprocal(triples):
    params, wi, wo = triples
    material = pb.Material(**params)
    f = pb.reference.eval(material, wi, wo, model=THIN)
    np.testing.assert_array_equal(pb.reference.eval(material, mirrored(wi), mirrored(wo), model=THIN), f)
    np.testing.assert_allclose(pb.reference.eval(material, wo, wi, model=THIN), f, rtol=1e-9,
                               atol=1e-12 * np.abs(f).max())
    lobes = pb.reference.eval_lobes(material, wi, wo, model=THIN)
    through = wi[:, 2] * wo[:, 2] < 0
    assert np.all(lobes.transmission[~through] == 0) and np.all(lobes.diffuse_transmission[~through] == 0)
    assert np.all(lobes.diffuse[through] == 0) and np.all(lobes.specular[through] == 0)


def test_the_diffuse_splits_between_the_faces_as_1_minus_dt_to_dt():
    """At diff_trans 2 dt the reflected diffuse is (1 - dt) times the opaque sheet's, and the diffuse
    transmission is dt w_D c / π: with roughness 0 the diffuse shape is 1 at normal
    incidence, so reflected : transmitted is exactly (1 - dt) : dt there."""
    wi, wo = np.array([[0.3, 0.1, np.sqrt(0.9)]]), np.array([[-0.2, 0.4, np.sqrt(0.8)]])
    base = dict(base_color=(0.3, 0.6, 0.2), roughness=0.4, sheen=0.5, metallic=0.3)
    opaque = pb.reference.eval_lobes(pb.Material(**base), wi, wo, model=THIN)
    for dt in (0.0, 0.25, 0.5, 1.0):
        material = pb.Material(**base, diff_trans=2 * dt)
        reflected = pb.reference.eval_lobes(material, wi, wo, model=THIN)
        through = pb.reference.eval_lobes(material, mirrored(wi), wo, model=THIN)
        np.testing.assert_allclose(reflected.diffuse, (1 - dt) * opaque.diffuse, rtol=1e-14)
        np.testing.assert_allclose(reflected.sheen, (1 - dt) * opaque.sheen, rtol=1e-14)
        np.testing.assert_allclose(through.diffuse_transmission, dt * 0.7 * np.array([[0.3, 0.6, 0.2]]) / np.pi,
                                   rtol=1e-14)
    flat = dict(base_color=(0.3, 0.6, 0.2), roughness=0.0, diff_trans=0.6)
    normal = np.array([[0.0, 0.0, 1.0]])
    reflected = pb.reference.eval_lobes(pb.Material(**flat), normal, normal, model=THIN).diffuse
    transmitted = pb.reference.eval_lobes(pb.Material(**flat), -normal, normal, model=THIN).diffuse_transmission
    np.testing.assert_allclose(reflected / transmitted, (1 - 0.3) / 0.3, rtol=1e-14)


@pytest.fixture(scope="module")
def float32_case():
    rng = seeded_rng("bsdf2015-thin", "simd")
    n = 200_000
    params = random_thin_material(rng, n)
    material = pb.Material(**{k: np.asarray(v, np.float32) for k, v in params.items()})
    wi, wo = (sphere_directions(rng, n).astype(np.float32) for _ in range(2))
    return material, wi, wo


@pytest.mark.parametrize("isa", ISAS)
def test_simd_matches_the_reference_over_the_sphere(float32_case, isa):
    material, wi, wo = float32_case
    reference = pb.reference.eval_lobes(material, wi.astype(np.float64), wo.astype(np.float64), model=THIN)
    simd = pb.eval_lobes(material, wi, wo, model=THIN, isa=isa)
    results = {name: getattr(simd, name) for name in LOBES_THIN} | {"total": pb.eval(material, wi, wo, model=THIN, isa=isa)}
    expected = {name: getattr(reference, name) for name in LOBES_THIN} | {"total": reference.total()}
    for name, ours in results.items():
        assert np.all(np.isfinite(ours)), f"{isa} {name}: non-finite output"
        errors = np.abs(ours - expected[name]) / np.maximum(np.abs(expected[name]), FLOOR)
        assert np.percentile(errors, 99.99) <= 1e-4, f"{isa} {name}: p99.99 {np.percentile(errors, 99.99):.3g}"
        assert errors.max() <= 1e-3, f"{isa} {name}: max {errors.max():.3g}"
    uniform = pb.Material(base_color=(0.3, 0.7, 0.2), diff_trans=1.0, spec_trans=0.3, roughness=0.5)
    per_element = uniform.replace(roughness=np.full(len(wi), 0.5, np.float32))
    np.testing.assert_array_equal(pb.eval(uniform, wi, wo, model=THIN, isa=isa),
                                  pb.eval(per_element, wi, wo, model=THIN, isa=isa))


def test_pdf_and_sample_agree_with_the_reference_and_each_other():
    rng = seeded_rng("bsdf2015-thin", "sample")
    n = 50_000
    params = random_thin_material(rng, n)
    material = pb.Material(**{k: np.asarray(v, np.float32) for k, v in params.items()})
    wo = sphere_directions(rng, n).astype(np.float32)
    u = rng.random((n, 3)).astype(np.float32)
    reference = pb.reference.sample(material, wo.astype(np.float64), u.astype(np.float64), model=THIN)
    valid = reference.pdf > 0
    assert valid.mean() > 0.8 and np.any(reference.lobe == 3) and np.any(reference.lobe == 4)
    through = reference.wi[:, 2] * wo[:, 2] < 0
    assert np.all(through[valid & (reference.lobe >= 3)]) and not np.any(through[valid & (reference.lobe < 3)])
    drawn = material[valid]
    np.testing.assert_allclose(reference.pdf[valid], pb.reference.pdf(drawn, reference.wi[valid], wo[valid], model=THIN),
                               rtol=1e-12)
    f = pb.reference.eval(drawn, reference.wi[valid], wo[valid], model=THIN)
    np.testing.assert_allclose(reference.weight[valid], f * np.abs(reference.wi[valid, 2:3]) / reference.pdf[valid, None],
                               rtol=1e-12, atol=0)
    probabilities = pb.reference.lobe_probabilities(material, wo.astype(np.float64), model=THIN)
    np.testing.assert_allclose(probabilities.sum(axis=-1), 1.0, rtol=1e-12)
    for isa in ISAS:
        simd = pb.sample(material, wo, u=u, model=THIN, isa=isa)
        same_lobe = simd.lobe == reference.lobe
        assert same_lobe.mean() > 0.999, isa
        close = same_lobe & valid & (reference.pdf > 1e-3)
        np.testing.assert_allclose(simd.wi[close], reference.wi[close], atol=2e-4)
        assert np.percentile(np.abs(simd.pdf[close] / reference.pdf[close] - 1), 99) < 1e-3, isa


# --------------------------------------------------------------------------
# the sampler's distribution over the sphere, from both faces

SAMPLES = 200_000
MATERIALS = {
    "leaf": dict(base_color=(0.25, 0.55, 0.1), roughness=0.5, diff_trans=1.2, sheen=0.3),
    "paper": dict(base_color=(0.95, 0.9, 0.8), roughness=0.9, diff_trans=1.6, flatness=0.5),
    "frosted-sheet": dict(base_color=(0.9, 0.95, 1.0), spec_trans=1.0, roughness=0.3, ior=1.5),
    "everything": dict(base_color=(0.7, 0.4, 0.2), spec_trans=0.5, diff_trans=0.8, roughness=0.45, anisotropic=0.6,
                       metallic=0.1, clearcoat=0.5, clearcoat_gloss=0.7, ior=1.45),
}
VIEWS = {"front-30": 30.0, "front-75": 75.0, "back-40": 140.0}
CASES = [(m, v) for m in MATERIALS for v in VIEWS]
SIMD_CASES = [("everything", "back-40")]
THRESHOLD = cs.sidak_threshold(len(CASES) + len(SIMD_CASES) * len(ISAS))


def view(theta_degrees):
    theta = np.radians(theta_degrees)
    return np.array([np.sin(theta) * np.cos(0.3), np.sin(theta) * np.sin(0.3), np.cos(theta)])


def chi_square(material, wo, drawn):
    mirror = np.array([-wo[0], -wo[1], wo[2]])
    alpha = max(float(material.roughness) ** 2, 0.05)
    return cs.chi_square_test(drawn.wi, lambda w: pb.reference.pdf(material, w, wo, model=THIN), sphere=True,
                              invalid=drawn.pdf == 0, peaks=[mirror, -wo], peak_width=alpha, cos_breaks=[-wo[2]])


@pytest.mark.parametrize("case", CASES, ids=[f"{m}-{v}" for m, v in CASES])
def test_the_reference_sampler_draws_its_pdf_over_the_sphere(case):
    name, view_name = case
    material, wo = pb.Material(**MATERIALS[name]), view(VIEWS[view_name])
    u = seeded_rng("bsdf2015-thin-chi-square", name, view_name).random((SAMPLES, 3))
    drawn = pb.reference.sample(material, wo, u, model=THIN)
    assert (drawn.wi[:, 2] * wo[2] < 0).mean() > 0.05, "the case must exercise the transmission"
    result = chi_square(material, wo, drawn)
    assert result.p_value > THRESHOLD, f"{name} {view_name}: {result.describe()}"


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("case", SIMD_CASES, ids=[f"{m}-{v}" for m, v in SIMD_CASES])
def test_the_simd_sampler_draws_the_reference_pdf(case, isa):
    name, view_name = case
    material, wo = pb.Material(**MATERIALS[name]), view(VIEWS[view_name])
    drawn = pb.sample(material, wo.astype(np.float32), n=SAMPLES, seed=7, model=THIN, isa=isa)
    result = chi_square(material, wo.astype(np.float32).astype(np.float64), drawn)
    assert result.p_value > THRESHOLD, f"{isa} {name} {view_name}: {result.describe()}"


def test_the_albedo_bound_and_the_faces():
    """White, spec_trans 1: the albedo over the sphere is at most 1 + 2e-3 (what the rough microfacet
    lobes lose is not given back); a diffusing sheet's albedo is the same from either face."""
    clear = pb.Material(base_color=(1, 1, 1), spec_trans=1.0, roughness=0.3, ior=1.5)
    cos_o = np.array([0.95, 0.6, 0.2, -0.6])
    result = pb.albedo(clear, cos_o, samples=1 << 17, seed=5, model=THIN)
    assert np.all(result.total[:, 0] <= 1 + 2e-3 + 3 * result.total_error[:, 0]), result.total
    assert np.all(result.transmittance[:, 0] > 0.5), result.transmittance
    paper = pb.Material(**MATERIALS["paper"])
    front, back = (pb.albedo(paper, c, samples=1 << 16, seed=5, model=THIN) for c in (0.7, -0.7))
    np.testing.assert_array_equal(front.total, back.total)
    assert np.all(front.transmittance > 0.2 * front.total)


def test_the_thin_model_reads_diff_trans_and_not_subsurface():
    assert pb.eval(pb.Material(diff_trans=1.0), [0, 0, -1], [0, 0, 1], model=THIN).max() > 0
    with pytest.raises(ValueError, match="subsurface"):
        pb.eval(pb.Material(subsurface=0.5), [0, 0, 1], [0, 0, 1], model=THIN)
    with pytest.raises(ValueError, match="diff_trans"):
        pb.eval(pb.Material(diff_trans=1.0), [0, 0, 1], [0, 0, 1], model="disney2015")
    with pytest.raises(ValueError, match="energy_compensation"):
        pb.eval(pb.Material(), [0, 0, 1], [0, 0, 1], model=THIN, energy_compensation=True)
