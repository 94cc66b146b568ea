"""Regressions of principled_brdf.torch and principled_brdf.jax (docs/interop.md, docs/bad-input.md):
each a defect found once, refused or fixed since.

* the PyTorch backward is not differentiable: a second backward pass raises torch's
  once_differentiable error instead of a gradient that silently adds nothing;
* every parameter goes through pb.Material's checks, and a tensor or array of a dtype
  the kernels do not take is a TypeError naming it;
* a non-finite upstream gradient (cotangent) is a ValueError naming ``cotangent`` on
  every backward path;
* JAX checks what it knows when the call is traced (options, shapes, dtypes, known
  values), with the library's messages, before any host callback runs;
* JAX's backward pass computes only the cotangents of the differentiated inputs.
"""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb
from principled_brdf import _derivatives, _interop

torch = pytest.importorskip("torch")
jax = pytest.importorskip("jax")
pbt = pytest.importorskip("principled_brdf.torch")
pbj = pytest.importorskip("principled_brdf.jax")
jnp = jax.numpy

WI = np.float32([[0.0, 0.6, 0.8], [0.6, 0.0, 0.8]])
WO = np.float32([[0.0, -0.6, 0.8], [0.28, 0.0, 0.96]])


# ------------------------------------------------------------ PyTorch: double backward


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
def test_torch_double_backward_raises_torchs_error(dtype):
    """A gradient penalty differentiates the backward pass: refused, not added as zero."""
    roughness = torch.tensor([0.4, 0.7], dtype=dtype, requires_grad=True)
    wi = torch.from_numpy(WI).to(dtype)
    f = pbt.eval({"roughness": roughness}, wi, torch.from_numpy(WO).to(dtype))
    (gradient,) = torch.autograd.grad(f.sum(), roughness, create_graph=True)
    assert gradient.requires_grad
    with pytest.raises(RuntimeError, match="once_differentiable"):
        (f.sum() + (gradient ** 2).sum()).backward()


def test_torch_gradgradcheck_fails():
    roughness = torch.tensor([0.4, 0.7], dtype=torch.float64, requires_grad=True)
    wi, wo = torch.from_numpy(WI).double(), torch.from_numpy(WO).double()
    with pytest.raises(RuntimeError):
        torch.autograd.gradgradcheck(lambda r: pbt.eval({"roughness": r}, wi, wo), (roughness,))


# ------------------------------------------------------------ parameters checked as pb.Material checks them


BAD_PARAMETERS = [
    ({"roughness": "0.9"}, TypeError, "roughness: expected a real number"),
    ({"roughness": None}, TypeError, "roughness: expected a real number"),
    ({"roughness": [0.5, "a"]}, TypeError, "roughness: expected real numbers"),
    ({"roughness": -0.5}, ValueError, r"roughness: -0.5 is outside its domain \[0, inf\)"),
    ({"metallic": float("nan")}, ValueError, "metallic: nan is not a finite number"),
    ({"base_color": (0.5, 0.5)}, ValueError, "base_color: expected an RGB triple"),
    ({"base_color": np.uint8([200, 100, 50])}, TypeError, "base_color: a uint8 color"),
    ({"spec_trans": 0.5}, ValueError, "spec_trans.*does not read it"),
]


@pytest.mark.parametrize("material, error, message", BAD_PARAMETERS)
def test_torch_parameters_are_checked_as_pb_material_checks_them(material, error, message):
    with pytest.raises(error, match=f"^{message}"):
        pbt.eval(material, torch.from_numpy(WI), torch.from_numpy(WO))
    with pytest.raises(error, match=f"^{message}"):
        pbt.eval(material, torch.from_numpy(WI).double(), torch.from_numpy(WO).double())


@pytest.mark.parametrize("material, error, message", BAD_PARAMETERS)
def test_jax_parameters_are_checked_when_traced(material, error, message):
    with pytest.raises(error, match=f"^{message}"):
        pbj.eval(material, WI, WO)
    with pytest.raises(error, match=f"^{message}"):  # under jit: the values are known when it traces
        jax.jit(lambda wi: pbj.eval(material, wi, WO))(WI)


TORCH_DTYPES = [torch.bfloat16, torch.float16, torch.complex64, torch.bool, torch.int32]


@pytest.mark.parametrize("dtype", TORCH_DTYPES)
def test_torch_tensors_of_other_dtypes_are_named_type_errors(dtype):
    wi, wo = torch.from_numpy(WI), torch.from_numpy(WO)
    message = rf"expected a real floating-point tensor \(float32 or float64\), got {dtype}"
    with pytest.raises(TypeError, match=f"^roughness: {message}"):
        pbt.eval({"roughness": torch.ones(2).to(dtype)}, wi, wo)
    with pytest.raises(TypeError, match=f"^wi: {message}"):
        pbt.eval({}, wi.to(dtype), wo)
    with pytest.raises(TypeError, match=f"^wo: {message}"):
        pbt.pdf({}, wi, wo.to(dtype))


@pytest.mark.parametrize("dtype", [jnp.bfloat16, jnp.float16, jnp.complex64, jnp.bool_, jnp.int32])
def test_jax_arrays_of_other_dtypes_are_named_type_errors(dtype):
    message = r"expected a real floating-point array \(float32 or float64\)"
    with pytest.raises(TypeError, match=f"^roughness: {message}"):
        pbj.eval({"roughness": jnp.ones(2, dtype)}, WI, WO)
    with pytest.raises(TypeError, match=f"^wi: {message}"):
        jax.jit(lambda wi: pbj.eval({}, wi, WO))(jnp.asarray(WI).astype(dtype))


def test_torch_sample_takes_pb_samples_keywords_in_either_precision():
    material = {"roughness": torch.tensor([0.3, 0.6]), "metallic": 0.5}
    single = pbt.sample(material, torch.from_numpy(WO), seed=5, n=4)
    double = pbt.sample(material, torch.from_numpy(WO).double(), seed=5, n=4)
    assert single.wi.shape == double.wi.shape == (4, 2, 3) and double.wi.dtype == torch.float64
    # the same uniforms: pb.sample's counter-based generator, keyed by seed and element
    np.testing.assert_allclose(double.wi.numpy(), single.wi.numpy(), atol=1e-4)
    np.testing.assert_array_equal(double.lobe.numpy(), single.lobe.numpy())
    u = torch.rand(2, 3, dtype=torch.float64)
    for wo in (torch.from_numpy(WO), torch.from_numpy(WO).double()):
        with pytest.raises(ValueError, match="^n: not with u"):
            pbt.sample(material, wo, u=u, n=3)
        with pytest.raises(ValueError, match="^n: expected a count >= 0"):
            pbt.sample(material, wo, n=-1)
        with pytest.raises(TypeError, match="threads"):
            pbt.sample(material, wo, threads=1)


# ------------------------------------------------------------ non-finite cotangents


def torch_inputs(dtype, differentiate):
    wi, wo = torch.from_numpy(WI).to(dtype), torch.from_numpy(WO).to(dtype)
    roughness = torch.tensor([0.4, 0.7], dtype=dtype)
    inputs = {"wi": wi, "wo": wo, "roughness": roughness}
    for name in differentiate:
        inputs[name].requires_grad_()
    return inputs


@pytest.mark.parametrize("dtype", [torch.float32, torch.float64])
@pytest.mark.parametrize("differentiate", [("roughness",), ("wi",), ("wo",), ("wi", "roughness")])
@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_torch_non_finite_cotangents_are_refused_on_every_backward_path(dtype, differentiate, bad):
    t = torch_inputs(dtype, differentiate)
    f = pbt.eval({"roughness": t["roughness"]}, t["wi"], t["wo"])
    cotangent = torch.ones_like(f)
    cotangent[1, 2] = bad
    with pytest.raises(ValueError, match=r"^cotangent\[1, 2\]: (nan|inf) is not a finite number"):
        torch.autograd.grad(f, [t[name] for name in differentiate], cotangent)


@pytest.mark.parametrize("x64", [False, True])
@pytest.mark.parametrize("argnums", [(0,), (1,), (2,), (0, 2)])
def test_jax_non_finite_cotangents_are_refused_on_every_backward_path(x64, argnums):
    with jax.enable_x64(x64):
        dtype = jnp.float64 if x64 else jnp.float32
        inputs = (jnp.asarray(WI, dtype), jnp.asarray(WO, dtype), jnp.asarray([0.4, 0.7], dtype))
        f = lambda wi, wo, r: pbj.eval({"roughness": r}, wi, wo)  # noqa: E731
        _, vjp = jax.vjp(lambda *diff: f(*[diff[argnums.index(k)] if k in argnums else inputs[k]
                                           for k in range(3)]), *[inputs[k] for k in argnums])
        cotangent = jnp.ones((2, 3), dtype).at[0, 1].set(jnp.nan)
        with pytest.raises(ValueError, match=r"^cotangent\[0, 1\]: nan is not a finite number"):
            vjp(cotangent)  # a known cotangent: refused when the backward pass is traced
        with pytest.raises(Exception, match=r"cotangent\[0, 1\]: nan is not a finite number"):
            jax.block_until_ready(jax.jit(vjp)(cotangent))  # a traced one: by the callback, named


# ------------------------------------------------------------ JAX: checks when the call is traced


def test_jax_options_are_checked_before_any_callback():
    with pytest.raises(ValueError, match=r"^model: expected one of"):
        pbj.eval({}, WI, WO, model="bogus")
    with pytest.raises(ValueError, match=r"^model: expected one of"):
        jax.jit(lambda wi: pbj.eval({}, wi, WO, model="bogus"))(WI)
    with pytest.raises(ValueError, match=r"^mode: expected one of"):
        pbj.eval({}, WI, WO, mode="light")
    with pytest.raises(TypeError, match=r"^cosine: expected True or False"):
        pbj.eval({}, WI, WO, cosine=1)


def test_jax_a_traced_cosine_is_a_named_type_error():
    with pytest.raises(TypeError, match=r"^cosine: must be a static Python value, not a traced array"):
        jax.jit(lambda c: pbj.eval({}, WI, WO, cosine=c))(True)
    static = jax.jit(lambda wi, c: pbj.eval({}, wi, WO, cosine=c), static_argnames="c")
    np.testing.assert_array_equal(static(WI, True), pb.eval(pb.Material(), WI, WO, cosine=True))


def test_jax_shapes_are_checked_with_the_librarys_messages():
    wi3 = np.tile(WI[:1], (3, 1))
    with pytest.raises(ValueError, match=r"^leading shapes do not broadcast: wi \(3,\), wo \(2,\)"):
        pbj.eval({}, wi3, WO)
    with pytest.raises(ValueError, match=r"^leading shapes do not broadcast: .*roughness \(4,\)"):
        jax.jit(lambda r: pbj.eval({"roughness": r}, WI, WO))(jnp.ones(4) * 0.5)
    with pytest.raises(ValueError, match=r"^wo: expected shape \(\.\.\., 3\)"):
        pbj.eval({}, WI, WO[:, :2])
    with pytest.raises(ValueError, match=r"^base_color: expected an RGB triple"):
        jax.jit(lambda c: pbj.eval({"base_color": c}, WI, WO))(jnp.ones((2, 2)) * 0.5)


def test_jax_known_directions_are_checked_before_any_callback():
    bad = WI.copy()
    bad[1, 0] = np.nan
    with pytest.raises(ValueError, match=r"^wi\[1, 0\]: nan is not a finite number"):
        pbj.eval({}, bad, WO)
    with pytest.raises(ValueError, match=r"^wo\[0\]: length 2 is not 1"):
        jax.jit(lambda r: pbj.eval({"roughness": r}, WI, 2 * WO))(jnp.float32(0.5))


def test_jax_a_value_known_only_at_run_time_is_named_by_the_callback():
    with pytest.raises(Exception, match=r"roughness(\[\d+\])?: nan is not a finite number"):
        jax.block_until_ready(jax.jit(lambda r: pbj.eval({"roughness": r}, WI, WO))(jnp.float32(jnp.nan)))


# ------------------------------------------------------------ JAX: only the cotangents asked for


def count_calls(monkeypatch, module, name):
    calls = []
    original = getattr(module, name)

    def counted(*args, **kwargs):
        calls.append(name)
        return original(*args, **kwargs)

    monkeypatch.setattr(module, name, counted)
    return calls


def test_jax_backward_computes_only_the_cotangents_asked_for(monkeypatch):
    by_directions = count_calls(monkeypatch, _interop, "direction_vjp")
    by_parameters = count_calls(monkeypatch, _derivatives, "eval_vjp")
    loss = lambda r, wi: jnp.sum(pbj.eval({"roughness": r, "metallic": 0.5}, wi, WO))  # noqa: E731
    r = jnp.float32([0.4, 0.7])
    by_r = jax.jit(jax.grad(loss))(r, WI)
    assert (len(by_directions), len(by_parameters)) == (0, 1)
    by_wi = jax.jit(jax.grad(loss, argnums=1))(r, WI)
    assert (len(by_directions), len(by_parameters)) == (1, 1)
    both = jax.grad(loss, argnums=(0, 1))(r, WI)
    assert (len(by_directions), len(by_parameters)) == (2, 2)
    np.testing.assert_array_equal(both[0], by_r)
    np.testing.assert_array_equal(both[1], by_wi)
