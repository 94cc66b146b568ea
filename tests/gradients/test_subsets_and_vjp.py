"""Derivatives that compute only what is asked (docs/gradients.md): a ``wrt``
subset of eval_grad is the full Jacobian's columns, bit for bit, on every
instruction set; eval_vjp is the contraction of the Jacobian with the
cotangent (float32 within its rounding, float64 within 1e-12), summed down to
each parameter's own shape."""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb
from principled_brdf._gradient import GRADIENT_NAMES
from conftest import MODELS, random_direction_pairs, random_material_arrays, seeded_rng

ISAS = tuple(pb.cpu_info()["available"])
SUBSETS = (["roughness"], ["clearcoat_gloss"], ["base_color"], ["base_color_g", "anisotropic"],
           ["subsurface", "sheen_tint"], ["metallic", "specular", "specular_tint", "sheen", "clearcoat"],
           [name for name in GRADIENT_NAMES if name != "roughness"])


def columns_of(names):
    wanted = set()
    for name in names:
        wanted |= {GRADIENT_NAMES.index(f"{name}_{c}") for c in "rgb"} if name == "base_color" else {GRADIENT_NAMES.index(name)}
    return sorted(wanted)


def inputs(n, seed):
    rng = seeded_rng("gradient-subsets", seed)
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, n))
    return wi, wo, pb.Material(**random_material_arrays(rng, n))


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("model", MODELS)
def test_a_subset_is_the_full_jacobians_columns_bit_for_bit(isa, model):
    n = 1003  # a tail on every lane count
    wi, wo, per_element = inputs(n, model)
    uniform = pb.Material(roughness=0.4, anisotropic=0.5, sheen=0.3, clearcoat=0.7, subsurface=0.2, metallic=0.3)
    for material in (uniform, per_element):
        for cosine in (False, True):
            full = pb.eval_grad(material, wi, wo, model=model, cosine=cosine, isa=isa)
            full_soa = pb.eval_grad(material, wi.T.copy(), wo.T.copy(), model=model, cosine=cosine, isa=isa,
                                    layout="soa")
            for subset in SUBSETS:
                cols = columns_of(subset)
                part = pb.eval_grad(material, wi, wo, wrt=subset, model=model, cosine=cosine, isa=isa)
                assert part.names == tuple(GRADIENT_NAMES[k] for k in cols)
                assert part.jacobian.shape == (n, 3, len(cols))
                np.testing.assert_array_equal(part.jacobian, full.jacobian[..., cols])
                np.testing.assert_array_equal(part.value, full.value)
                soa = pb.eval_grad(material, wi.T.copy(), wo.T.copy(), wrt=subset, model=model, cosine=cosine,
                                   isa=isa, layout="soa")
                np.testing.assert_array_equal(soa.jacobian, full_soa.jacobian[:, cols])


@pytest.mark.parametrize("isa", ISAS)
def test_a_subsets_bits_do_not_depend_on_threads_or_tails(isa):
    n = 40_000
    wi, wo, material = inputs(n, "threads")
    one = pb.eval_grad(material, wi, wo, wrt="roughness", isa=isa, threads=1)
    two = pb.eval_grad(material, wi, wo, wrt="roughness", isa=isa, threads=2)
    np.testing.assert_array_equal(one.jacobian, two.jacobian)
    for start, stop in ((0, 5), (3, 30), (39_990, 40_000)):
        part = pb.eval_grad(material[start:stop], wi[start:stop], wo[start:stop], wrt="roughness", isa=isa)
        np.testing.assert_array_equal(part.jacobian, one.jacobian[start:stop])


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("model", MODELS)
def test_float32_vjp_is_the_contraction_of_the_jacobian(isa, model):
    n = 2001
    wi, wo, material = inputs(n, ("vjp", model))
    g = seeded_rng("vjp-cotangent", model).normal(size=(n, 3))
    for subset in (None, ["roughness", "base_color"], ["clearcoat_gloss"]):
        jacobian = pb.eval_grad(material, wi, wo, wrt=subset, model=model, cosine=True, isa=isa)
        product = pb.eval_vjp(material, wi, wo, g, wrt=subset, model=model, cosine=True, isa=isa)
        assert tuple(product) == jacobian.names
        g32 = g.astype(np.float32).astype(np.float64)
        expected = np.einsum("nc,nck->nk", g32, jacobian.jacobian.astype(np.float64))
        size = np.einsum("nc,nck->nk", np.abs(g32), np.abs(jacobian.jacobian.astype(np.float64)))
        for k, name in enumerate(jacobian.names):
            assert product[name].dtype == np.float32 and product[name].shape == (n,)
            # three float32 products and two sums: a few units of float32 rounding of Σ|g J|
            assert np.all(np.abs(product[name] - expected[:, k]) <= 4 * 2.0**-24 * size[:, k] + 1e-37)


@pytest.mark.parametrize("model", MODELS)
def test_float64_vjp_is_the_contraction_of_the_reference_jacobian(model):
    n = 300
    wi, wo, material = inputs(n, ("vjp64", model))
    wi, wo = wi.astype(np.float64), wo.astype(np.float64)
    g = seeded_rng("vjp64-cotangent", model).normal(size=(n, 3))
    jacobian = pb.reference.eval_grad(material, wi, wo, model=model)
    product = pb.eval_vjp(material, wi, wo, g, model=model, precision="float64")
    expected = np.einsum("nc,nck->nk", g, jacobian.jacobian)
    for k, name in enumerate(GRADIENT_NAMES):
        assert product[name].dtype == np.float64
        np.testing.assert_allclose(product[name], expected[:, k], rtol=1e-12, atol=1e-12 * np.abs(expected).max())


@pytest.mark.parametrize("precision", ("float32", "float64"))
def test_uniform_parameters_get_the_sum_over_elements(precision):
    rng = seeded_rng("vjp-sums")
    wi, wo = random_direction_pairs(rng, 4 * 50)
    wi, wo = wi.reshape(4, 50, 3), wo.reshape(4, 50, 3)
    # roughness per element of the (50,) axis, broadcast along the first; sheen (4, 1); the rest uniform
    roughness = rng.uniform(0.2, 0.9, 50)
    sheen = rng.uniform(0.0, 1.0, (4, 1))
    material = pb.Material(roughness=roughness, sheen=sheen, base_color=(0.7, 0.4, 0.2), clearcoat=0.5)
    g = rng.normal(size=(4, 50, 3))
    product = pb.eval_vjp(material, wi, wo, g, precision=precision)
    jacobian = pb.reference.eval_grad(material, wi, wo).jacobian
    per_element = np.einsum("abc,abck->abk", g, jacobian)
    assert product["roughness"].shape == (50,) and product["sheen"].shape == (4, 1)
    assert product["metallic"].shape == () and product["base_color_r"].shape == ()
    tolerance = dict(rtol=2e-5, atol=1e-5) if precision == "float32" else dict(rtol=1e-11, atol=1e-12)
    column = {name: per_element[..., GRADIENT_NAMES.index(name)] for name in GRADIENT_NAMES}
    np.testing.assert_allclose(product["roughness"], column["roughness"].sum(axis=0), **tolerance)
    np.testing.assert_allclose(product["sheen"], column["sheen"].sum(axis=1, keepdims=True), **tolerance)
    for name in ("metallic", "base_color_r", "base_color_b", "clearcoat_gloss"):
        np.testing.assert_allclose(product[name], column[name].sum(), **tolerance)


def test_vjp_arguments_are_checked_and_named():
    wi, wo, material = inputs(10, "vjp-errors")
    with pytest.raises(ValueError, match=r"cotangent: expected shape \(\.\.\., 3\)"):
        pb.eval_vjp(material, wi, wo, np.ones((10, 2)))
    with pytest.raises(ValueError, match=r"cotangent\[3, 1\]"):
        bad = np.ones((10, 3))
        bad[3, 1] = np.nan
        pb.eval_vjp(material, wi, wo, bad)
    with pytest.raises(ValueError, match="wrt: unknown parameter"):
        pb.eval_vjp(material, wi, wo, np.ones(3), wrt="gloss")
    with pytest.raises(ValueError, match="precision"):
        pb.eval_vjp(material, wi, wo, np.ones(3), precision="half")
    with pytest.raises(NotImplementedError):
        pb.eval_grad(material, wi, wo, energy_compensation=True)
    # a single cotangent vector broadcasts; empty input gives empty products
    one = pb.eval_vjp(material, wi, wo, np.float32([1, 0, 0]), wrt="roughness")
    full = pb.eval_vjp(material, wi, wo, np.tile(np.float32([1, 0, 0]), (10, 1)), wrt="roughness")
    np.testing.assert_array_equal(one["roughness"], full["roughness"])
    empty = pb.eval_vjp(pb.Material(), np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)), wrt="roughness")
    assert empty["roughness"].shape == () and empty["roughness"] == 0.0
