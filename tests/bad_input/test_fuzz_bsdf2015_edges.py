"""A fuzz of the 2015 models at their domains' edges (docs/bad-input.md,
docs/model-2015.md): every parameter at a bound, inside, or per element
mixing both, the index of refraction from 1 to MAX_IOR and just beyond it,
and pairs over the whole sphere, the horizon and the poles included. Every
entry point returns finite, non-negative results that agree with the float64
reference, or raises a ValueError naming the argument: never NaN, never a
silently empty sample."""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import principled_brdf as pb
from principled_brdf.material import MAX_BSDF_SPECULAR, MAX_IOR

FUZZ = settings(derandomize=True, max_examples=60, deadline=None, database=None,
                suppress_health_check=list(HealthCheck))
ISAS = pb.cpu_info()["available"]
N = 40
MODELS = ("disney2015", "disney2015_thin")
IORS = (1.0, 1.001, 1.5, 2.4, MAX_IOR)
REFUSED_SPECULAR = (float(np.nextafter(MAX_BSDF_SPECULAR, 13.0)), 12.49998, 12.5, 1e4)


def edge_directions(rng) -> np.ndarray:
    """Unit vectors over the sphere with the poles, the horizon and near-horizon ones mixed in."""
    v = rng.normal(size=(N, 3))
    v[:4] = [[0, 0, 1], [0, 0, -1], [1, 0, 0], [0, 0.6, 0.8]]
    v[4:8, 2] *= 1e-4
    return (v / np.linalg.norm(v, axis=1, keepdims=True)).astype(np.float32)


@st.composite
def edge_material(draw, model, rng):
    kwargs = {}
    for name, info in pb.PARAMETERS.items():
        if name == "subsurface" or (name == "diff_trans" and model == "disney2015") or name == "specular":
            continue
        lower, upper = info.lower, info.upper if np.isfinite(info.upper) else 1.0
        kind = draw(st.sampled_from(("lower", "upper", "inside", "mixed", "default")))
        shape = (N, 3) if info.slots == 3 else (N,)
        value = {"lower": np.full(shape, lower), "upper": np.full(shape, upper),
                 "inside": rng.uniform(lower, upper, shape),
                 "mixed": np.where(rng.random(shape) < 0.5, lower, upper), "default": None}[kind]
        if value is not None:
            kwargs[name] = value[0] if kind in ("lower", "upper") else value
    ior = draw(st.sampled_from(IORS + ("mixed", "refused")))
    if ior == "mixed":
        kwargs["ior"] = rng.choice(IORS, N)
    elif ior == "refused":
        kwargs["specular"] = draw(st.sampled_from(REFUSED_SPECULAR))
    else:
        kwargs["ior"] = ior
    return pb.Material(**kwargs, bright_base_color=True)


def reflection_pairs(wi, wo):
    """Pairs the float32 kernels must match to 1e-3: both directions on one side and clear of
    the horizon (transmission near the critical angle is conditioned by κ: test_bsdf2015.py)."""
    return (wi[:, 2] * wo[:, 2] > 0) & (np.abs(wi[:, 2]) > 0.05) & (np.abs(wo[:, 2]) > 0.05)


def assert_agrees(actual, expected, where):
    scale = np.maximum(np.abs(expected), 1e-6 * max(1.0, float(np.abs(expected).max(initial=0.0))))
    error = np.where(where[:, None], np.abs(actual - expected) / scale, 0.0)
    assert error.max(initial=0.0) <= 1e-3, error.max()


@FUZZ
@given(data=st.data(), seed=st.integers(0, 2**32 - 1), model=st.sampled_from(MODELS), isa=st.sampled_from(ISAS),
       entry=st.sampled_from(("eval", "eval_lobes", "pdf", "eval_pdf", "eval_grad", "direction_grad", "sample")))
def test_fuzz_bsdf2015_at_the_edges(data, seed, model, isa, entry):
    rng = np.random.default_rng(seed)
    material = data.draw(edge_material(model, rng))
    wi, wo = edge_directions(rng), edge_directions(rng)
    if np.any(material.specular > MAX_BSDF_SPECULAR):
        call = {"sample": lambda: pb.sample(material, wo, seed=1, model=model, isa=isa)}.get(
            entry, lambda: pb.eval(material, wi, wo, model=model, isa=isa))
        try:
            call()
        except ValueError as error:
            assert str(error).startswith("specular"), error
            assert "MAX_IOR = 10" in str(error), error
            return
        raise AssertionError("a specular beyond MAX_IOR's was accepted")
    flat = material.reshape(-1) if material.shape else material
    if entry == "sample":
        s = pb.sample(flat, wo, seed=seed % 1000, model=model, isa=isa)
        for array in (s.wi, s.pdf, s.weight):
            assert np.isfinite(array).all()
        assert (s.pdf >= 0).all() and (s.weight >= 0).all()
        lit = s.pdf > 0
        expected = pb.reference.pdf(flat, s.wi, wo, model=model)
        np.testing.assert_allclose(s.pdf[lit], expected[lit], rtol=2e-3)
        return
    if entry == "pdf":
        p = pb.pdf(flat, wi, wo, model=model, isa=isa)
        assert np.isfinite(p).all() and (p >= 0).all()
        return
    if entry == "direction_grad":
        g = pb.eval_grad(flat, wi, wo, model=model, isa=isa, wrt=["wi", "wo"])
        assert np.isfinite(g.jacobian).all()
        return
    result = {"eval": lambda: pb.eval(flat, wi, wo, model=model, isa=isa),
              "eval_lobes": lambda: pb.eval_lobes(flat, wi, wo, model=model, isa=isa).total(),
              "eval_pdf": lambda: pb.eval_pdf(flat, wi, wo, model=model, isa=isa).value,
              "eval_grad": lambda: pb.eval_grad(flat, wi, wo, model=model, isa=isa)}[entry]()
    value = result.value if entry == "eval_grad" else result
    if entry == "eval_grad":
        assert np.isfinite(result.jacobian).all()
    assert np.isfinite(value).all() and (value >= 0).all()
    expected = pb.reference.eval(flat, wi.astype(np.float64), wo.astype(np.float64), model=model)
    rough = np.broadcast_to(flat.roughness >= 0.05, (N,))
    assert_agrees(value, expected, reflection_pairs(wi, wo) & rough)


@FUZZ
@given(seed=st.integers(0, 2**32 - 1), ior=st.sampled_from(IORS), side=st.sampled_from((1.0, -1.0)))
def test_fuzz_bsdf2015_albedo_at_every_ior(seed, ior, side):
    """The albedo of white rough glass from either side is positive (rough glass loses up to
    two thirds at grazing views, without energy compensation) and at most 1 for every
    accepted η: every η the domain takes draws samples from outside."""
    rng = np.random.default_rng(seed)
    roughness = float(rng.choice([0.0, 0.3, 1.0]))
    m = pb.Material(base_color=(1, 1, 1), spec_trans=1, roughness=roughness, ior=ior)
    a = pb.albedo(m, side * np.array([0.2, 0.9]), model="disney2015", samples=4096, seed=seed % 1000,
                  mode="importance")
    assert np.isfinite(a.total).all()
    assert (a.total > 0.1).all() and (a.total <= 1 + 5 * a.total_error + 1e-3).all(), (a.total, a.total_error)
