"""principled_brdf.jax (docs/interop.md): eval as a jax.custom_vjp operation over
host callbacks, checked by jax.test_util.check_grads on the float64 path, under
jit and vmap, and against the contraction of pb.eval_grad."""

from __future__ import annotations

import importlib
import sys

import numpy as np
import pytest

import principled_brdf as pb
from conftest import seeded_rng
from interop.interior import PARAMETER_NAMES, interior_inputs

jax = pytest.importorskip("jax")
pbj = pytest.importorskip("principled_brdf.jax")
jnp = jax.numpy
enable_x64 = jax.enable_x64
from jax.test_util import check_grads  # noqa: E402


def split(inputs):
    return inputs["wi"], inputs["wo"], {n: inputs[n] for n in PARAMETER_NAMES}


def test_check_grads_on_the_float64_path():
    wi, wo, material = split(interior_inputs(seeded_rng("jax check_grads"), 10))
    names = list(material)
    with enable_x64(True):
        def f(*values):
            return pbj.eval(dict(zip(names, values)) | {"specular": 0.6}, wi, wo, cosine=True)
        check_grads(f, tuple(jnp.asarray(material[n]) for n in names), order=1, modes=["rev"], eps=1e-6)
        # one value for every element
        check_grads(lambda s: pbj.eval({"specular": s, "clearcoat": 0.5}, wi, wo), (0.6,), order=1, modes=["rev"])


def test_jit_and_vmap_give_the_eager_values_and_gradients():
    rng = seeded_rng("jax jit vmap")
    wi, wo, _ = split(interior_inputs(rng, 40))
    wi, wo = wi.astype(np.float32), wo.astype(np.float32)
    roughness = rng.uniform(0.2, 0.9, (5, 40)).astype(np.float32)

    def loss(r, metallic):
        return jnp.sum(pbj.eval({"roughness": r, "metallic": metallic, "base_color": (0.8, 0.5, 0.2)}, wi, wo) ** 2)

    eager_values = np.stack([pbj.eval({"roughness": r}, wi, wo) for r in roughness])
    mapped = jax.jit(jax.vmap(lambda r: pbj.eval({"roughness": r}, wi, wo)))(roughness)
    np.testing.assert_array_equal(mapped, eager_values)
    np.testing.assert_array_equal(eager_values[2], pb.eval(pb.Material(roughness=roughness[2]), wi, wo))

    grad = jax.grad(loss, argnums=(0, 1))
    eager = [grad(r, np.float32(0.3)) for r in roughness]
    mapped_r, mapped_m = jax.jit(jax.vmap(grad, in_axes=(0, None)))(roughness, np.float32(0.3))
    np.testing.assert_array_equal(mapped_r, np.stack([e[0] for e in eager]))
    np.testing.assert_array_equal(mapped_m, np.stack([e[1] for e in eager]))
    metallic = np.float32([0.0, 0.5, 1.0])
    per_metallic = jax.vmap(grad, in_axes=(None, 0))(roughness[0], metallic)[1]
    np.testing.assert_array_equal(per_metallic, [grad(roughness[0], m)[1] for m in metallic])


def test_the_gradient_is_eval_grads_contraction():
    rng = seeded_rng("jax contraction")
    wi, wo, material = split(interior_inputs(rng, 300))
    wi, wo = wi.astype(np.float32), wo.astype(np.float32)
    material = {n: v.astype(np.float32) for n, v in material.items()}
    cotangent = rng.normal(size=(300, 3)).astype(np.float32)
    value, vjp = jax.vjp(lambda m: pbj.eval(m, wi, wo), material)
    (gradients,) = vjp(jnp.asarray(cotangent))
    g = pb.eval_grad(pb.Material(**material), wi, wo, wrt=list(material))
    np.testing.assert_array_equal(value, g.value)
    per_element = np.einsum("nc,nck->nk", cotangent.astype(np.float64), g.jacobian.astype(np.float64))
    for name in material:
        columns = [k for k, n in enumerate(g.names) if n in (name, f"{name}_r", f"{name}_g", f"{name}_b")]
        expected = per_element[:, columns].reshape(material[name].shape)
        np.testing.assert_allclose(gradients[name], expected, rtol=0, atol=2e-6 * np.abs(expected).max(),
                                   err_msg=name)


def test_check_grads_of_the_directions_on_the_float64_path():
    """The derivatives in wi and wo, the 3-vectors moved as given (within the length check's tolerance)."""
    wi, wo, material = split(interior_inputs(seeded_rng("jax check_grads directions"), 10))
    with enable_x64(True):
        check_grads(lambda a, b: pbj.eval(material, a, b, cosine=True), (jnp.asarray(wi), jnp.asarray(wo)), order=1,
                    modes=["rev"], eps=1e-6)
        check_grads(lambda b: pbj.eval(material, wi, b), (jnp.asarray(wo[0]),), order=1, modes=["rev"], eps=1e-6)


def test_the_directions_gradients_are_eval_grads_contraction_under_jit_and_vmap():
    rng = seeded_rng("jax direction contraction")
    wi, wo, material = split(interior_inputs(rng, 64))
    wi, wo = wi.astype(np.float32), wo.astype(np.float32)
    material = {n: v.astype(np.float32) for n, v in material.items()}
    cotangent = rng.normal(size=(64, 3)).astype(np.float32)
    _, vjp = jax.vjp(lambda a, b: pbj.eval(material, a, b), wi, wo)
    by_wi, by_wo = vjp(jnp.asarray(cotangent))
    g = pb.eval_grad(pb.Material(**material), wi, wo, wrt=["wi", "wo"])
    expected = np.einsum("nc,nck->nk", cotangent, g.jacobian)
    scale = np.abs(expected).max()
    np.testing.assert_allclose(np.concatenate([by_wi, by_wo], -1), expected, rtol=1e-5, atol=1e-6 * scale)
    loss = jax.jit(jax.vmap(jax.grad(lambda a, b: jnp.sum(pbj.eval(material, a, b))), in_axes=(0, None)))
    rows = loss(jnp.stack([wi, wi[::-1]]), wo)
    np.testing.assert_array_equal(rows[0], jax.grad(lambda a: jnp.sum(pbj.eval(material, a, wo)))(wi))


def test_bad_calls_are_named():
    wi = np.float32([0.0, 0.6, 0.8])
    with pytest.raises(ValueError, match="material: unknown parameter 'gloss'"):
        pbj.eval({"gloss": 1.0}, wi, wi)
    with pytest.raises(TypeError, match="unexpected option 'layout'"):
        pbj.eval({}, wi, wi, layout="soa")
    with pytest.raises(TypeError, match="material: expected a mapping"):
        pbj.eval(pb.Material(), wi, wi)


def test_without_jax_the_error_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "jax", None)
    monkeypatch.delitem(sys.modules, "principled_brdf.jax")
    with pytest.raises(ImportError, match=r"pip install 'principled-brdf\[jax\]'"):
        importlib.import_module("principled_brdf.jax")


def test_check_grads_of_the_2015_directions_through_glass():
    """model="disney2015", half of the pairs through the interface: check_grads in wi and wo (float64)."""
    rng = seeded_rng("jax 2015 directions")
    wi, wo, material = split(interior_inputs(rng, 10))
    wi = wi * np.where(np.arange(10) % 2 == 0, -1.0, 1.0)[:, None]
    material["spec_trans"] = rng.uniform(0.3, 0.9, 10)
    with enable_x64(True):
        check_grads(lambda a, b: pbj.eval(material, a, b, model="disney2015", cosine=True),
                    (jnp.asarray(wi), jnp.asarray(wo)), order=1, modes=["rev"], eps=1e-6)
