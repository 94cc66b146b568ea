"""docs/validation.md: the float32 SIMD kernel against the float64 reference evaluated on
the same float32 inputs, on every instruction set this machine runs, for the
total and every lobe, both models.

Error per channel: |simd - ref| / max(|ref|, 1e-6), over 10^6 random
(material, wi, wo) triples with per-element materials across docs/model.md, "The model".
"""

import numpy as np
import pytest

import principled_brdf as pb
from conftest import LOBES, MODELS, random_direction_pairs, random_material_arrays, seeded_rng

ISAS = pb.cpu_info()["available"]
N = 1_000_000
FLOOR = 1e-6

# regime: (min cos θ, fraction near the horizon, bound at the 99.99th percentile, bound at the maximum)
REGIMES = {
    "cos>=0.05": (0.05, 0.0, 5e-6, 5e-5),
    "cos>=1e-4": (1e-4, 0.5, 5e-5, 1e-3),
}


def relative_errors(simd, ref):
    return np.abs(simd.astype(np.float64) - ref) / np.maximum(np.abs(ref), FLOOR)


@pytest.fixture(scope="module", params=[(r, m) for r in REGIMES for m in MODELS], ids=lambda p: f"{p[0]}-{p[1]}")
def case(request):
    regime, model = request.param
    min_cos, grazing, _, _ = REGIMES[regime]
    rng = seeded_rng("simd-accuracy", regime, model)
    wi, wo = random_direction_pairs(rng, N, min_cos=min_cos, grazing_fraction=grazing)
    wi, wo = wi.astype(np.float32), wo.astype(np.float32)
    material = pb.Material(**random_material_arrays(rng, N))
    # the reference sees exactly the float32 inputs (and float32-representable parameters)
    material = pb.Material(**{k: np.asarray(v, np.float32) for k, v in material.as_dict().items()})
    reference = pb.reference.eval_lobes(material, wi.astype(np.float64), wo.astype(np.float64), model=model)
    return regime, model, material, wi, wo, reference


@pytest.mark.parametrize("isa", ISAS)
def test_simd_matches_reference(case, isa):
    regime, model, material, wi, wo, reference = case
    _, _, percentile_bound, max_bound = REGIMES[regime]
    simd_lobes = pb.eval_lobes(material, wi, wo, model=model, isa=isa)
    simd_total = pb.eval(material, wi, wo, model=model, isa=isa)
    results = dict(zip(LOBES, simd_lobes))
    results["total"] = simd_total
    expected = dict(zip(LOBES, reference))
    expected["total"] = reference.total()
    for name, simd in results.items():
        errors = relative_errors(simd, expected[name])
        assert np.all(np.isfinite(simd)), f"{isa} {name}: non-finite output"
        worst = np.unravel_index(np.argmax(errors), errors.shape)
        assert np.percentile(errors, 99.99) <= percentile_bound, (
            f"{isa} {model} {name}: 99.99th percentile {np.percentile(errors, 99.99):.3g} > {percentile_bound:g}")
        assert errors.max() <= max_bound, (
            f"{isa} {model} {name}: max {errors.max():.3g} > {max_bound:g} at {worst[0]}: "
            f"simd {simd[worst]}, ref {expected[name][worst]}, wi {wi[worst[0]]}, wo {wo[worst[0]]}, "
            f"material {[(k, v[worst[0]]) for k, v in material.as_dict().items()]}")


@pytest.mark.parametrize("isa", ISAS)
def test_layouts_and_cosine_agree(isa):
    rng = seeded_rng("layouts", isa)
    n = 10_001  # not a multiple of any SIMD width: exercises the tail
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, n))
    material = pb.Material(**random_material_arrays(rng, n))
    aos = pb.eval(material, wi, wo, isa=isa)
    soa = pb.eval(material, np.ascontiguousarray(wi.T), np.ascontiguousarray(wo.T), layout="soa", isa=isa)
    np.testing.assert_array_equal(aos, soa.T)
    with_cos = pb.eval(material, wi, wo, cosine=True, isa=isa)
    np.testing.assert_allclose(with_cos, aos * wi[:, 2:3], rtol=1e-6, atol=0)
    lobes = pb.eval_lobes(material, wi, wo, isa=isa)
    np.testing.assert_allclose(sum(lobes), aos, rtol=2e-6, atol=1e-30)


@pytest.mark.parametrize("isa", ISAS)
def test_the_clearcoat_over_its_whole_gloss_range_matches_the_reference(isa):
    # GTR1's norm (a² - 1) / (π ln a²) takes the kernels' own ln of every batch's
    # a² in [1e-6, 1e-2] for a per-element clearcoat_gloss: a sweep of 4097 values
    gloss = np.linspace(0.0, 1.0, 4097)
    material = pb.Material(clearcoat=1.0, clearcoat_gloss=gloss)
    wi = np.broadcast_to(np.float32([0.28, -0.1, 0.9547775]), (gloss.size, 3))
    wo = np.broadcast_to(np.float32([-0.3, 0.2, 0.9327379]), (gloss.size, 3))
    simd = pb.eval_lobes(material, wi, wo, isa=isa).clearcoat[:, 0].astype(np.float64)
    expected = pb.reference.eval_lobes(material, wi.astype(np.float64), wo.astype(np.float64)).clearcoat[:, 0]
    np.testing.assert_allclose(simd, expected, rtol=2e-6, atol=0)
