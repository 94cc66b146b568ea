"""docs/gradients.md, "At a parameter's bound": where a lobe's weight is
exactly 0 (flatness 0, clearcoat 0, spec_trans 0, metallic 1) the derivative
is the one-sided derivative into the domain, not 0; and an element's
derivative does not depend on its SIMD neighbours (a lobe skipped because
every lane weighs 0 must not skip its derivative). Checked in the float64
reference against one-sided differences of its own f, and in every SIMD
kernel against the reference, for both 2015 models and the 2014 model."""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb

ISAS = pb.cpu_info()["available"]

REFLECTION = (np.array([-0.5108, 0.8529, 0.1081]), np.array([-0.8155, -0.4710, 0.3364]))
TRANSMISSION = (np.array([0.1, -0.6, -0.7937]), np.array([0.0, 0.6, 0.8]))

# (model, parameter at its bound, the bound, the other parameters, the pair, the direction into the domain)
CASES = [
    ("disney2015", "flatness", 0.0, {}, REFLECTION, +1),
    ("disney2015", "clearcoat", 0.0, {}, REFLECTION, +1),
    ("disney2015", "spec_trans", 0.0, {"roughness": 0.4}, TRANSMISSION, +1),
    ("disney2015", "metallic", 1.0, {"spec_trans": 0.7, "roughness": 0.4}, TRANSMISSION, -1),
    ("disney2015", "sheen", 0.0, {}, REFLECTION, +1),
    ("disney2015_thin", "flatness", 0.0, {}, REFLECTION, +1),
    ("disney2015_thin", "clearcoat", 0.0, {}, REFLECTION, +1),
    ("disney2015_thin", "spec_trans", 0.0, {"roughness": 0.4}, TRANSMISSION, +1),
    ("disney2015_thin", "diff_trans", 0.0, {}, TRANSMISSION, +1),
    ("disney2015_thin", "metallic", 1.0, {"spec_trans": 0.7, "roughness": 0.4}, TRANSMISSION, -1),
    ("disney2014", "clearcoat", 0.0, {}, REFLECTION, +1),
    ("disney2014", "subsurface", 0.0, {}, REFLECTION, +1),
    ("disney2014", "sheen", 0.0, {}, REFLECTION, +1),
]
IDS = [f"{model}-{name}={bound:g}" for model, name, bound, *_ in CASES]


def one_sided_difference(model, name, bound, others, pair, into):
    """(f(p + h) - f(p)) / h into the domain, float64: exact for a parameter f is linear in."""
    wi, wo = pair
    h = 1e-7 * into
    f = lambda value: pb.reference.eval(pb.Material(**others, **{name: value}), wi, wo, model=model)  # noqa: E731
    return (f(bound + h) - f(bound)) / h


@pytest.mark.parametrize("model, name, bound, others, pair, into", CASES, ids=IDS)
def test_reference_derivative_at_the_bound_is_the_one_sided_difference(model, name, bound, others, pair, into):
    wi, wo = pair
    expected = one_sided_difference(model, name, bound, others, pair, into)
    assert np.abs(expected).max() > 1e-4, "the case must have a derivative to lose"
    gradient = pb.reference.eval_grad(pb.Material(**others, **{name: bound}), wi, wo, model=model, wrt=name)
    np.testing.assert_allclose(gradient.jacobian[:, 0], expected, rtol=1e-5, atol=1e-9)


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("model, name, bound, others, pair, into", CASES, ids=IDS)
def test_kernel_derivative_at_the_bound_alone_and_beside_neighbours(isa, model, name, bound, others, pair, into):
    """Element 0 at the bound, in a batch of 32 (two AVX-512 registers): its neighbours
    at the bound too, or inside the domain; the element's derivative is the same bits
    either way and agrees with the reference."""
    wi, wo = (np.tile(w.astype(np.float32), (32, 1)) for w in pair)
    inside = bound + 0.5 * into
    reference = pb.reference.eval_grad(pb.Material(**others, **{name: bound}), wi[0], wo[0], model=model, wrt=name)
    columns = []
    for neighbours in (bound, inside):
        values = np.full(32, neighbours)
        values[0] = bound
        material = pb.Material(**others, **{name: values})
        columns.append(pb.eval_grad(material, wi, wo, model=model, wrt=name, isa=isa).jacobian[0, :, 0])
    np.testing.assert_array_equal(columns[0], columns[1])
    np.testing.assert_allclose(columns[0], reference.jacobian[:, 0], rtol=1e-4, atol=1e-7)


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("model", ["disney2015", "disney2015_thin"])
def test_uniform_and_per_element_materials_agree_at_the_bounds(isa, model):
    """Every 2015 parameter at a bound at once (defaults: flatness, clearcoat, sheen,
    spec_trans 0), uniform against per-element, over pairs on the whole sphere."""
    rng = np.random.default_rng(52)
    w = rng.normal(size=(2, 1000, 3))
    wi, wo = (v / np.linalg.norm(v, axis=-1, keepdims=True) for v in w.astype(np.float64))
    wi, wo = wi.astype(np.float32), wo.astype(np.float32)
    uniform = pb.eval_grad(pb.Material(roughness=0.5), wi, wo, model=model, isa=isa).jacobian
    per_element = pb.eval_grad(pb.Material(roughness=np.full(1000, 0.5)), wi, wo, model=model, isa=isa).jacobian
    np.testing.assert_array_equal(uniform, per_element)
    reference = pb.reference.eval_grad(pb.Material(roughness=0.5), wi, wo, model=model).jacobian
    scale = np.maximum(np.abs(reference), 1e-3 * np.abs(reference).max(axis=(-2, -1), keepdims=True) + 1e-12)
    assert np.quantile(np.abs(uniform - reference) / scale, 0.9999) <= 1e-4


@pytest.mark.parametrize("model, name, bound, others, pair, into", [c for c in CASES if c[0] != "disney2014"],
                         ids=[i for i, c in zip(IDS, CASES) if c[0] != "disney2014"])
def test_torch_and_jax_derivatives_at_the_bound(model, name, bound, others, pair, into):
    """The frameworks' backward passes run the same kernels: at the bound, the gradient of
    sum(f) in the parameter is the reference's one-sided derivative (a fit started there moves)."""
    import jax
    import jax.numpy as jnp
    import torch

    from principled_brdf import jax as pbj
    from principled_brdf import torch as pbt

    wi, wo = (w.astype(np.float32)[None] for w in pair)
    expected = pb.reference.eval_grad(pb.Material(**others, **{name: bound}), wi[0], wo[0], model=model,
                                      wrt=name).jacobian[:, 0].sum()
    value = torch.tensor(bound, dtype=torch.float32, requires_grad=True)
    pbt.eval({**others, name: value}, torch.from_numpy(wi), torch.from_numpy(wo), model=model).sum().backward()
    through_jax = jax.grad(lambda v: pbj.eval({**others, name: v}, jnp.asarray(wi), jnp.asarray(wo),
                                              model=model).sum())(jnp.float32(bound))
    for actual in (float(value.grad), float(through_jax)):
        assert actual == pytest.approx(float(expected), rel=1e-4, abs=1e-7)
