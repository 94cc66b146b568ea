"""principled_brdf.torch (docs/interop.md): eval as a differentiable PyTorch
operation, checked by torch.autograd.gradcheck on the float64 path, against the
contraction of pb.eval_grad, and float32 against float64; pdf and sample on tensors."""

from __future__ import annotations

import importlib
import sys

import numpy as np
import pytest

import principled_brdf as pb
from conftest import seeded_rng
from interop.interior import PARAMETER_NAMES, interior_inputs

torch = pytest.importorskip("torch")
pbt = pytest.importorskip("principled_brdf.torch")


def tensors(inputs, dtype, grad=PARAMETER_NAMES):
    return {name: torch.tensor(value, dtype=dtype, requires_grad=name in grad) for name, value in inputs.items()}


def material_of(t):
    return {name: value for name, value in t.items() if name not in ("wi", "wo")}


def test_gradcheck_on_the_float64_path():
    t = tensors(interior_inputs(seeded_rng("torch gradcheck"), 12), torch.float64)
    t["specular"] = torch.tensor(0.7, dtype=torch.float64, requires_grad=True)  # one value for every element
    names = [n for n in t if n not in ("wi", "wo")]

    def f(*values):
        return pbt.eval(dict(zip(names, values)), t["wi"], t["wo"], cosine=True)

    assert torch.autograd.gradcheck(f, tuple(t[n] for n in names), eps=1e-6, atol=1e-7, rtol=1e-5)


def test_gradcheck_of_the_directions_on_the_float64_path():
    """The derivatives in wi and wo, the 3-vectors moved as given (within the length check's tolerance)."""
    t = tensors(interior_inputs(seeded_rng("torch gradcheck directions"), 12), torch.float64, grad=("roughness",))
    wi, wo = (t[n].detach().requires_grad_() for n in ("wi", "wo"))

    def f(wi, wo, roughness):
        return pbt.eval(material_of(t) | {"roughness": roughness}, wi, wo, cosine=True)

    assert torch.autograd.gradcheck(f, (wi, wo, t["roughness"]), eps=1e-6, atol=1e-7, rtol=1e-5)
    one_wo = wo[0].detach().clone().requires_grad_()  # one vector for every element: its gradient summed
    assert torch.autograd.gradcheck(lambda w: pbt.eval(material_of(t), wi.detach(), w), (one_wo,), eps=1e-6,
                                    atol=1e-7, rtol=1e-5)


@pytest.mark.parametrize("model", ["disney2014", "disney2012"])
def test_the_directions_gradients_are_eval_grads_contraction_and_float32_agrees(model):
    rng = seeded_rng("torch direction contraction", model)
    inputs = interior_inputs(rng, 257)
    cotangent = rng.normal(size=(257, 3))
    gradients = {}
    for dtype in (torch.float32, torch.float64):
        t = tensors(inputs, dtype, grad=("wi", "wo"))
        pbt.eval(material_of(t), t["wi"], t["wo"], model=model).backward(torch.from_numpy(cotangent).to(dtype))
        gradients[dtype] = np.concatenate([t["wi"].grad.numpy(), t["wo"].grad.numpy()], axis=-1)
    material = pb.Material(**{n: v.astype(np.float32) for n, v in inputs.items() if n not in ("wi", "wo")})
    g = pb.eval_grad(material, inputs["wi"].astype(np.float32), inputs["wo"].astype(np.float32), wrt=["wi", "wo"],
                     model=model)
    expected = np.einsum("nc,nck->nk", cotangent.astype(np.float32), g.jacobian)
    np.testing.assert_allclose(gradients[torch.float32], expected, rtol=1e-5, atol=1e-5 * np.abs(expected).max())
    scale = np.abs(gradients[torch.float64]).max()
    np.testing.assert_allclose(gradients[torch.float32], gradients[torch.float64], rtol=1e-3, atol=1e-4 * scale)


@pytest.mark.parametrize("model", ["disney2014", "disney2012"])
def test_the_gradient_is_eval_grads_contraction(model):
    rng = seeded_rng("torch contraction", model)
    inputs = interior_inputs(rng, 257)
    t = tensors(inputs, torch.float32)
    t["specular_tint"] = torch.tensor(0.4, requires_grad=True)
    f = pbt.eval(material_of(t), t["wi"], t["wo"], model=model)
    cotangent = rng.normal(size=(257, 3)).astype(np.float32)
    f.backward(torch.from_numpy(cotangent))

    material = pb.Material(**{n: v.detach().numpy() for n, v in material_of(t).items()})
    names = list(material_of(t))
    g = pb.eval_grad(material, inputs["wi"].astype(np.float32), inputs["wo"].astype(np.float32), wrt=names,
                     model=model)
    np.testing.assert_array_equal(f.detach().numpy(), g.value)
    per_element = np.einsum("nc,nck->nk", cotangent.astype(np.float64), g.jacobian.astype(np.float64))
    expected = {"base_color": per_element[:, 0:3]}
    for k, name in enumerate(g.names):
        if not name.startswith("base_color"):
            expected[name] = per_element[:, k]
    expected["specular_tint"] = expected["specular_tint"].sum()
    for name, value in expected.items():
        scale = np.abs(value).max()
        np.testing.assert_allclose(t[name].grad.numpy(), value, rtol=0, atol=2e-6 * scale, err_msg=name)


def test_float32_gradients_follow_float64():
    inputs = interior_inputs(seeded_rng("torch f32 vs f64"), 500)
    grads = {}
    for dtype in (torch.float32, torch.float64):
        t = tensors(inputs, dtype)
        pbt.eval(material_of(t), t["wi"], t["wo"]).sum().backward()
        grads[dtype] = {n: t[n].grad.double().numpy() for n in PARAMETER_NAMES}
    for name in PARAMETER_NAMES:
        exact, single = grads[torch.float64][name], grads[torch.float32][name]
        np.testing.assert_allclose(single, exact, rtol=2e-3, atol=2e-4 * np.abs(exact).max(), err_msg=name)


def test_broadcast_parameters_get_summed_gradients():
    rng = seeded_rng("torch broadcast")
    inputs = interior_inputs(rng, 24)
    wi, wo = (torch.from_numpy(inputs[k].reshape(4, 6, 3).astype(np.float32)) for k in ("wi", "wo"))
    roughness = torch.tensor(rng.uniform(0.3, 0.8, (4, 1)), dtype=torch.float32, requires_grad=True)
    color = torch.tensor([0.5, 0.4, 0.3], requires_grad=True)
    f = pbt.eval({"roughness": roughness, "base_color": color}, wi, wo)
    assert f.shape == (4, 6, 3) and f.dtype == torch.float32
    f.sum().backward()
    g = pb.eval_grad(pb.Material(roughness=roughness.detach().numpy(), base_color=(0.5, 0.4, 0.3)), wi.numpy(),
                     wo.numpy(), wrt=["roughness", "base_color"])
    per_element = g.jacobian.astype(np.float64).sum(axis=-2)  # cotangent of ones
    np.testing.assert_allclose(roughness.grad.numpy(), per_element[..., 3].sum(axis=1, keepdims=True), rtol=1e-5)
    np.testing.assert_allclose(color.grad.numpy(), per_element[..., :3].sum(axis=(0, 1)), rtol=1e-5)


def test_inputs_are_read_without_a_copy():
    wi = torch.tensor([[0.0, 0.6, 0.8]] * 5)
    assert np.shares_memory(pbt._numpy("wi", wi), wi.numpy())
    f = pbt.eval(pb.Material(roughness=0.3), wi, wi)
    np.testing.assert_array_equal(f.numpy(), pb.eval(pb.Material(roughness=0.3), wi.numpy(), wi.numpy()))


def test_pdf_and_sample_on_tensors():
    inputs = interior_inputs(seeded_rng("torch pdf sample"), 64)
    wi, wo = (torch.from_numpy(inputs[k].astype(np.float32)) for k in ("wi", "wo"))
    material = {"roughness": torch.from_numpy(inputs["roughness"].astype(np.float32)), "metallic": 0.5}
    numpy_material = pb.Material(roughness=inputs["roughness"], metallic=0.5)
    np.testing.assert_array_equal(pbt.pdf(material, wi, wo).numpy(), pb.pdf(numpy_material, wi.numpy(), wo.numpy()))
    drawn = pbt.sample(material, wo, seed=5)
    expected = pb.sample(numpy_material, wo.numpy(), seed=5)
    for tensor, array in zip(drawn, expected):
        np.testing.assert_array_equal(tensor.numpy(), array)
    u = torch.rand(64, 3, dtype=torch.float64)
    exact = pbt.sample({"roughness": torch.from_numpy(inputs["roughness"])}, wo.double(), u=u)
    assert exact.wi.dtype == torch.float64


def test_bad_calls_are_named():
    wi = torch.tensor([0.0, 0.6, 0.8])
    with pytest.raises(ValueError, match="material: unknown parameter 'gloss'"):
        pbt.eval({"gloss": 1.0}, wi, wi)
    with pytest.raises(TypeError, match="unexpected option 'threads'"):
        pbt.eval({}, wi, wi, threads=2)
    with pytest.raises(TypeError, match="roughness: expected a real floating-point tensor"):
        pbt.eval({"roughness": torch.tensor(1)}, wi, wi)
    with pytest.raises(ValueError, match="roughness"):  # the library's domain check
        pbt.eval({"roughness": torch.tensor(-1.0)}, wi, wi)
    with pytest.raises(TypeError, match="material: expected a principled_brdf.Material or a mapping"):
        pbt.eval("gold", wi, wi)


def test_without_torch_the_error_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "torch", None)
    monkeypatch.delitem(sys.modules, "principled_brdf.torch")
    with pytest.raises(ImportError, match=r"pip install 'principled-brdf\[torch\]'"):
        importlib.import_module("principled_brdf.torch")


def test_the_2015_directions_gradients_through_glass():
    """model="disney2015": light through the interface from both sides, gradcheck of wi and wo on
    the float64 path (importance mode), and the float32 gradient against eval_grad's contraction."""
    rng = seeded_rng("torch 2015 directions")
    inputs = interior_inputs(rng, 64)
    inputs["wi"] = inputs["wi"] * np.where(np.arange(64) % 2 == 0, -1.0, 1.0)[:, None]  # half of them through
    inputs["spec_trans"] = rng.uniform(0.3, 0.9, 64)
    t = tensors(inputs, torch.float64, grad=("wi", "wo"))
    options = dict(model="disney2015", mode="importance", cosine=True)
    first = {name: value[:12] for name, value in material_of(t).items()}
    assert torch.autograd.gradcheck(lambda wi, wo: pbt.eval(first, wi, wo, **options),
                                    (t["wi"][:12].detach().requires_grad_(), t["wo"][:12].detach().requires_grad_()),
                                    eps=1e-6, atol=1e-7, rtol=1e-5)
    t32 = tensors(inputs, torch.float32, grad=("wi", "wo"))
    cotangent = rng.normal(size=(64, 3)).astype(np.float32)
    pbt.eval(material_of(t32), t32["wi"], t32["wo"], **options).backward(torch.from_numpy(cotangent))
    material = pb.Material(**{n: v.astype(np.float32) for n, v in inputs.items() if n not in ("wi", "wo")})
    g = pb.eval_grad(material, inputs["wi"].astype(np.float32), inputs["wo"].astype(np.float32), wrt=["wi", "wo"],
                     **options)
    expected = np.einsum("nc,nck->nk", cotangent, g.jacobian)
    gradients = np.concatenate([t32["wi"].grad.numpy(), t32["wo"].grad.numpy()], axis=-1)
    np.testing.assert_allclose(gradients, expected, rtol=1e-5, atol=1e-5 * np.abs(expected).max())
    assert np.abs(gradients[::2]).max() > 0  # (the transmitted pairs have derivatives)
