"""docs/model-2015.md: the 2015 solid (``model="disney2015"``) in the float64
reference and the SIMD kernels, against the independent numpy transcription
(tests/numpy_model_2015.py), and its properties over the whole sphere.

Tolerances. The reference against the transcription: every lobe within
``1e-12 (|numpy| + max |numpy| of that lobe over the batch)`` — relative 1e-12
where the lobe is anywhere near its scale; far in the tail of a sharp lobe
(a GGX transmission of alpha 0.01 at 1e-10 of its peak) both float64 forms
lose digits to the conditioning of the half vector, which an mpmath
evaluation of such a pair shows (both 2e-10 off), so the bound there is
absolute at 1e-12 of the lobe's largest value (1e-11 for the clearcoat:
RTOL). The kernels against the
reference: the errors of docs/validation.md's SIMD bounds, over the sphere.
"""

from __future__ import annotations

import numpy as np
import pytest

import numpy_model_2015
import principled_brdf as pb
from conftest import seeded_rng

ISAS = pb.cpu_info()["available"]
LOBES_2015 = ("diffuse", "sheen", "specular", "clearcoat", "transmission")
MODES = ("radiance", "importance")
# the transcription's GTR1 denominator 1 + (a² - 1) cos²θh cancels near the clearcoat's peak (a few 1e-12 seen)
RTOL = {"clearcoat": 1e-11}


def sphere_directions(rng, n):
    w = rng.normal(size=(n, 3))
    return w / np.linalg.norm(w, axis=1, keepdims=True)


def random_2015_material(rng, n, edge_fraction=0.2):
    """Per-element parameters of the 2015 solid over its domains, with edge values."""
    def scalar(lo, hi, edges):
        values = rng.uniform(lo, hi, n)
        at_edge = rng.random(n) < edge_fraction
        values[at_edge] = rng.choice(edges, int(at_edge.sum()))
        return values

    base = rng.uniform(0.0, 1.0, (n, 3))
    base[rng.random(n) < 0.05] = 0.0
    return {
        "base_color": base,
        "metallic": scalar(0, 1, (0.0, 1.0)),
        "specular": scalar(0, 3, (0.0, 0.5, 2.0)),
        "specular_tint": scalar(0, 1, (0.0, 1.0)),
        "roughness": scalar(0.02, 1, (0.05, 1.0)),
        "anisotropic": scalar(0, 1, (0.0, 1.0)),
        "sheen": scalar(0, 1, (0.0, 1.0)),
        "sheen_tint": scalar(0, 1, (0.0, 1.0)),
        "clearcoat": scalar(0, 1, (0.0, 1.0)),
        "clearcoat_gloss": scalar(0, 1, (0.0, 1.0)),
        "spec_trans": scalar(0, 1, (0.0, 1.0)),
        "flatness": scalar(0, 1, (0.0, 1.0)),
    }


@pytest.fixture(scope="module")
def triples():
    rng = seeded_rng("bsdf2015", "triples")
    n = 100_000
    params = random_2015_material(rng, n)
    return params, sphere_directions(rng, n), sphere_directions(rng, n)


@pytest.mark.parametrize("mode", MODES)
def test_reference_matches_the_numpy_transcription(triples, mode):
    params, wi, wo = triples
    reference = pb.reference.eval_lobes(pb.Material(**params), wi, wo, model="disney2015", mode=mode)
    transcription = numpy_model_2015.eval_lobes(params, wi, wo, model="disney2015", mode=mode)
    for name in LOBES_2015:
        ours, theirs = getattr(reference, name), getattr(transcription, name)
        assert np.abs(theirs).max() > 0, f"{name}: the random pairs never reach this lobe"
        bound = RTOL.get(name, 1e-12) * (np.abs(theirs) + np.abs(theirs).max())
        worst = np.argmax((np.abs(ours - theirs) / bound).max(axis=1))
        assert np.all(np.abs(ours - theirs) <= bound), (
            f"{name} ({mode}): {ours[worst]} vs {theirs[worst]} at wi {wi[worst]}, wo {wo[worst]}")
    assert np.all(reference.multiple_scattering == 0)
    np.testing.assert_allclose(pb.reference.eval(pb.Material(**params), wi, wo, model="disney2015", mode=mode),
                               sum(getattr(reference, name) for name in LOBES_2015), rtol=1e-14, atol=0)


def test_every_side_of_the_interface_is_reached(triples):
    params, wi, wo = triples
    lobes = pb.reference.eval_lobes(pb.Material(**params), wi, wo, model="disney2015")
    outside, light_outside = wo[:, 2] > 0, wi[:, 2] > 0
    reached = lambda lobe, mask: np.any(lobe[mask] > 0)  # noqa: E731
    assert reached(lobes.diffuse, outside & light_outside)
    assert reached(lobes.transmission, outside & ~light_outside)  # light from inside
    assert reached(lobes.transmission, ~outside & light_outside)  # viewer inside
    assert reached(lobes.specular, ~outside & ~light_outside)  # reflection inside
    assert not reached(lobes.diffuse + lobes.sheen + lobes.clearcoat, ~outside | ~light_outside)


def test_generalised_reciprocity(triples):
    """Radiance mode: f(wi, wo) / n(wo)² = f(wo, wi) / n(wi)², n the index on each direction's side."""
    params, wi, wo = triples
    material = pb.Material(**params)
    forward = pb.reference.eval(material, wi, wo, model="disney2015")
    backward = pb.reference.eval(material, wo, wi, model="disney2015")
    eta = numpy_model_2015.eta_of_specular(params["specular"])
    index = lambda w: np.where(w[:, 2] > 0, 1.0, eta)[:, None]  # noqa: E731
    np.testing.assert_allclose(forward / index(wo) ** 2, backward / index(wi) ** 2, rtol=1e-9,
                               atol=1e-12 * np.abs(forward).max())


def test_importance_differs_by_eta_t_squared_in_the_transmission_only(triples):
    params, wi, wo = triples
    material = pb.Material(**params)
    radiance = pb.reference.eval_lobes(material, wi, wo, model="disney2015")
    importance = pb.reference.eval_lobes(material, wi, wo, model="disney2015", mode="importance")
    eta = numpy_model_2015.eta_of_specular(params["specular"])
    eta_t = np.where(wo[:, 2] > 0, eta, 1.0 / eta)[:, None]
    np.testing.assert_allclose(importance.transmission, radiance.transmission * eta_t**2, rtol=1e-14)
    for name in ("diffuse", "sheen", "specular", "clearcoat"):
        np.testing.assert_array_equal(getattr(importance, name), getattr(radiance, name))


def test_no_transmission_without_spec_trans_and_the_2014_diffuse_outside():
    rng = seeded_rng("bsdf2015", "opaque")
    n = 20_000
    wi, wo = sphere_directions(rng, n), sphere_directions(rng, n)
    opaque = pb.Material(base_color=rng.uniform(0, 1, (n, 3)), roughness=rng.uniform(0.05, 1, n),
                         metallic=rng.uniform(0, 1, n), sheen=rng.uniform(0, 1, n))
    lobes = pb.reference.eval_lobes(opaque, wi, wo, model="disney2015")
    assert np.all(lobes.transmission == 0)
    assert np.all(lobes.total()[wo[:, 2] < 0] == 0)  # nothing from inside an opaque solid
    brdf = pb.reference.eval_lobes(opaque, wi, wo, model="disney2014")
    np.testing.assert_allclose(lobes.diffuse, brdf.diffuse, rtol=1e-13, atol=0)  # f_L + f_R is 2012's Fd
    np.testing.assert_allclose(lobes.sheen, brdf.sheen, rtol=1e-13, atol=0)


# --------------------------------------------------------------------------
# the kernels

FLOOR = 1e-6


def transmittance_conditioning(material, wi, wo):
    """κ = c² / (2 η_t² |cos²θt|), the magnification of a relative error in the microfacet cosine c = wo·h
    into the transmittance 1 - F_D near the critical angle (cos²θt -> 0 from inside); 0 for other pairs.
    The kernels form c in float32, so their transmission can only be as good as κ times its rounding there."""
    eta = numpy_model_2015.eta_of_specular(material.specular)
    inside = wo[:, 2] < 0
    mirror = np.where(inside[:, None], [1.0, 1.0, -1.0], 1.0)  # the viewer's side up
    v, light = wo * mirror, wi * mirror
    eta_t = np.where(inside, 1.0 / eta, eta)
    h = v + eta_t[:, None] * light
    c = np.abs(np.sum(v * h, axis=1)) / np.linalg.norm(h, axis=1)
    cos2_t = (c * c + eta_t * eta_t - 1.0) / eta_t**2
    with np.errstate(divide="ignore", invalid="ignore"):
        kappa = c * c / (2 * eta_t**2 * np.abs(cos2_t))  # (either side of the critical angle)
    return np.where((v[:, 2] > 0) & (light[:, 2] < 0), kappa, 0.0)


@pytest.fixture(scope="module")
def float32_case():
    rng = seeded_rng("bsdf2015", "simd")
    n = 200_000
    params = random_2015_material(rng, n)
    material = pb.Material(**{k: np.asarray(v, np.float32) for k, v in params.items()})
    wi, wo = (sphere_directions(rng, n).astype(np.float32) for _ in range(2))
    return material, wi, wo


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("mode", MODES)
def test_simd_matches_the_reference_over_the_sphere(float32_case, isa, mode):
    material, wi, wo = float32_case
    reference = pb.reference.eval_lobes(material, wi.astype(np.float64), wo.astype(np.float64), model="disney2015",
                                        mode=mode)
    simd = pb.eval_lobes(material, wi, wo, model="disney2015", mode=mode, isa=isa)
    total = pb.eval(material, wi, wo, model="disney2015", mode=mode, isa=isa)
    results = {name: getattr(simd, name) for name in LOBES_2015} | {"total": total}
    expected = {name: getattr(reference, name) for name in LOBES_2015} | {"total": reference.total()}
    # the float32 rounding of c magnified by κ, as a share of the 1e-4 bound
    conditioning = 1.0 + 1e-2 * transmittance_conditioning(material, wi.astype(np.float64), wo.astype(np.float64))
    for name, ours in results.items():
        assert np.all(np.isfinite(ours)), f"{isa} {name}: non-finite output"
        errors = np.abs(ours - expected[name]) / np.maximum(np.abs(expected[name]), FLOOR)
        if name in ("transmission", "total"):
            errors = errors / conditioning[:, None]
        assert np.percentile(errors, 99.99) <= 1e-4, f"{isa} {mode} {name}: p99.99 {np.percentile(errors, 99.99):.3g}"
        assert errors.max() <= 1e-3, f"{isa} {mode} {name}: max {errors.max():.3g}"


@pytest.mark.parametrize("isa", ISAS)
def test_simd_layouts_cosine_and_uniform_materials_agree(isa):
    rng = seeded_rng("bsdf2015", "layouts", isa)
    n = 10_001  # not a multiple of any SIMD width: the tail
    wi, wo = (sphere_directions(rng, n).astype(np.float32) for _ in range(2))
    glass = pb.Material(base_color=(0.9, 0.95, 1.0), spec_trans=1.0, roughness=0.2, ior=1.5)
    aos = pb.eval(glass, wi, wo, model="disney2015", isa=isa)
    soa = pb.eval(glass, np.ascontiguousarray(wi.T), np.ascontiguousarray(wo.T), layout="soa", model="disney2015", isa=isa)
    np.testing.assert_array_equal(aos, soa.T)
    per_element = pb.eval(glass.replace(roughness=np.full(n, 0.2)), wi, wo, model="disney2015", isa=isa)
    np.testing.assert_array_equal(aos, per_element)
    with_cos = pb.eval(glass, wi, wo, cosine=True, model="disney2015", isa=isa)
    np.testing.assert_allclose(with_cos, aos * np.abs(wi[:, 2:3]), rtol=1e-6, atol=0)
    threads = [pb.eval(glass, wi, wo, model="disney2015", isa=isa, threads=t) for t in (1, 2)]
    np.testing.assert_array_equal(threads[0], threads[1])


def test_pdf_and_sample_agree_with_the_reference_and_each_other():
    rng = seeded_rng("bsdf2015", "sample")
    n = 50_000
    params = random_2015_material(rng, n)
    material = pb.Material(**{k: np.asarray(v, np.float32) for k, v in params.items()})
    wo = sphere_directions(rng, n).astype(np.float32)
    u = rng.random((n, 3)).astype(np.float32)
    reference = pb.reference.sample(material, wo.astype(np.float64), u.astype(np.float64), model="disney2015")
    valid = reference.pdf > 0
    assert valid.mean() > 0.8 and np.any(reference.lobe == 3) and np.any(reference.wi[valid, 2] * wo[valid, 2] < 0)
    # the sample's pdf is pdf() at the pair drawn, its weight f |cos θl| / pdf
    drawn = material[valid]
    np.testing.assert_allclose(reference.pdf[valid], pb.reference.pdf(drawn, reference.wi[valid], wo[valid],
                                                                       model="disney2015"), rtol=1e-12)
    f = pb.reference.eval(drawn, reference.wi[valid], wo[valid], model="disney2015")
    np.testing.assert_allclose(reference.weight[valid], f * np.abs(reference.wi[valid, 2:3]) / reference.pdf[valid, None],
                               rtol=1e-12, atol=0)
    for isa in ISAS:
        simd = pb.sample(material, wo, u=u, model="disney2015", isa=isa)
        same_lobe = simd.lobe == reference.lobe
        assert same_lobe.mean() > 0.999, isa
        close = same_lobe & valid & (reference.pdf > 1e-3)
        np.testing.assert_allclose(simd.wi[close], reference.wi[close], atol=2e-4)
        assert np.percentile(np.abs(simd.pdf[close] / reference.pdf[close] - 1), 99) < 1e-3, isa
        wi32 = reference.wi.astype(np.float32)[close]
        simd_pdf = pb.pdf(material[close], wi32, wo[close], model="disney2015", isa=isa)
        reference_pdf = pb.reference.pdf(material[close], wi32.astype(np.float64), wo[close], model="disney2015")
        assert np.percentile(np.abs(simd_pdf / reference_pdf - 1), 99.9) < 1e-4, isa


# --------------------------------------------------------------------------
# the rules


def test_a_model_refuses_parameters_it_does_not_read():
    wi, wo = np.array([0.0, 0.6, 0.8]), np.array([0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match="spec_trans: model 'disney2014' does not read it"):
        pb.eval(pb.Material(spec_trans=0.5), wi, wo)
    with pytest.raises(ValueError, match=r"flatness\[1\]: model 'disney2012' does not read it"):
        pb.reference.eval(pb.Material(flatness=[0.0, 0.5]), wi, wo, model="disney2012")
    with pytest.raises(ValueError, match="subsurface: model 'disney2015' does not read it.*use flatness"):
        pb.sample(pb.Material(subsurface=0.2), wo, model="disney2015", seed=1)
    with pytest.raises(ValueError, match="diff_trans: model 'disney2015' does not read it"):
        pb.pdf(pb.Material(diff_trans=1.0), wi, wo, model="disney2015")
    with pytest.raises(ValueError, match=r"specular: model 'disney2015' needs specular <= 8.36777 \(an index of "
                                         r"refraction up to MAX_IOR = 10\), got 12.5"):
        pb.eval(pb.Material(specular=12.5), wi, wo, model="disney2015")
    with pytest.raises(ValueError, match="energy_compensation: not available for model 'disney2015_thin'"):
        pb.eval(pb.Material(), wi, wo, model="disney2015_thin", energy_compensation=True)
    with pytest.raises(ValueError, match="mode: expected one of"):
        pb.eval(pb.Material(), wi, wo, model="disney2015", mode="light")
    for eval_grad in (pb.eval_grad, pb.reference.eval_grad):  # the derivatives in the directions read the same
        with pytest.raises(ValueError, match="subsurface"):
            eval_grad(pb.Material(subsurface=0.5), wi, wo, wrt="wi", model="disney2015")


def test_glass_from_either_side_in_every_entry_point():
    glass = pb.Material(ior=1.5, spec_trans=1, roughness=0.2)
    wo = np.array([0.0, 0.6, 0.8])
    below = np.array([0.0, -0.3, -np.sqrt(1 - 0.09)])
    for f in (pb.eval(glass, below, wo, model="disney2015"), pb.eval(glass, wo, below, model="disney2015"),
              pb.reference.eval(glass, below, wo, model="disney2015")):
        assert np.all(f > 0)
    drawn = pb.sample(glass, -wo, n=4096, seed=3, model="disney2015")
    assert np.any(drawn.wi[:, 2] > 0) and np.any(drawn.wi[:, 2] < 0)  # out through the surface and back inside
    assert np.all(np.isfinite(drawn.weight))
    options = dict(model="disney2015", mode="importance")
    assert pb.eval_lobes(glass, below, wo, **options).transmission.min() > 0
    both = pb.eval_pdf(glass, below, wo, **options)
    assert both.pdf > 0 and np.array_equal(both.value, pb.eval(glass, below, wo, **options))
    gradient = pb.eval_grad(glass, below, wo, **options)
    assert len(gradient.names) == 16 and np.all(np.isfinite(gradient.jacobian))
    np.testing.assert_allclose(pb.reference.eval_grad(glass, below, wo, **options).jacobian, gradient.jacobian,
                               rtol=1e-3, atol=1e-5 * np.abs(gradient.jacobian).max())
    assert set(pb.eval_vjp(glass, below, wo, np.ones(3), **options)) == set(gradient.names)
    assert pb.albedo(glass, [0.8, -0.8], samples=1024, **options).transmittance.min() > 0
    assert pb.reference.lobe_probabilities(glass, wo, model="disney2015").shape == (5,)
    assert pb.reference.sample(glass, wo, [0.99, 0.3, 0.6], **options).lobe == 3
