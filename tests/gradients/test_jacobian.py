"""The Jacobian of f in the material's parameters (docs/gradients.md).

float64 against central differences of the float64 reference, the clamps'
derivatives, the linearity of f in sheen, clearcoat and the diffuse color,
and the API (names, wrt, cosine, shapes, the horizon).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import principled_brdf as pb
from principled_brdf import _core
from principled_brdf._gradient import GRADIENT_NAMES
from conftest import MODELS, random_direction_pairs, random_material_arrays, seeded_rng

MODEL_IDS = {"disney2014": 0, "disney2012": 1}
BOUNDED_SLOTS = [GRADIENT_NAMES.index(n) for n in
                 ("metallic", "subsurface", "specular_tint", "anisotropic", "sheen_tint", "clearcoat_gloss")]


def interior_rows(rng, n):
    """Packed materials away from the domain edges and from the alpha clamp."""
    material = pb.Material(**random_material_arrays(rng, n, edge_fraction=0.0))
    rows = np.array(material.packed((n,)), dtype=np.float64)
    rows = np.maximum(rows, 0.05)
    rows[:, BOUNDED_SLOTS] = np.minimum(rows[:, BOUNDED_SLOTS], 0.95)
    roughness = GRADIENT_NAMES.index("roughness")
    rows[:, roughness] = np.maximum(rows[:, roughness], 0.2)  # alpha = r² / aspect >= 0.04 > 0.001
    return np.ascontiguousarray(rows)


def central_difference(wi, wo, rows, slot, model_id, step):
    """The fourth-order central difference (8 f(p+h) - 8 f(p-h) - f(p+2h) + f(p-2h)) / 12h."""
    def f(offset):
        shifted = rows.copy()
        shifted[:, slot] += offset
        return _core.reference_eval(wi, wo, shifted, model_id, False)
    return (8.0 * (f(step) - f(-step)) - (f(2 * step) - f(-2 * step))) / (12.0 * step)


@pytest.mark.parametrize("model", MODELS)
def test_float64_jacobian_matches_central_differences(model):
    rng = seeded_rng("gradient-fd", model)
    n = 3000
    wi, wo = (np.ascontiguousarray(w, dtype=np.float64) for w in random_direction_pairs(rng, n, min_cos=0.02))
    rows = interior_rows(rng, n)
    value, jacobian = _core.reference_eval_grad(wi, wo, rows, MODEL_IDS[model])
    assert np.array_equal(value, _core.reference_eval(wi, wo, rows, MODEL_IDS[model], False))
    step = 1e-4
    # what rounding alone puts into the difference quotient: ~ eps |f| / h
    rounding = 4.0 * np.finfo(np.float64).eps * np.abs(value) / step
    checked = 0
    for slot, name in enumerate(GRADIENT_NAMES):
        numeric = central_difference(wi, wo, rows, slot, MODEL_IDS[model], step)
        analytic = jacobian[..., slot]
        scale = np.maximum(np.abs(analytic), 1e-6 * np.abs(jacobian).max(axis=-1))
        resolvable = (rounding <= 1e-8 * scale) & (scale > 0)
        error = np.abs(numeric - analytic) / np.where(resolvable, scale, 1.0)
        assert np.all(error[resolvable] <= 1e-6), (name, float(error[resolvable].max()))
        checked += int(resolvable.sum())
    assert checked >= 0.8 * n * 3 * len(GRADIENT_NAMES)


def test_gradient_at_the_alpha_clamp_is_the_active_branch():
    """roughness 0.02: alpha = max(0.001, r²/aspect) is clamped in x and y, so S does
    not move with anisotropic, and with roughness only through the diffuse lobe."""
    rng = seeded_rng("gradient-clamp")
    wi, wo = random_direction_pairs(rng, 500, min_cos=0.05)
    m = pb.Material(roughness=0.02, anisotropic=0.3, subsurface=0.4)
    g = pb.reference.eval_grad(m, wi, wo, wrt=["roughness", "anisotropic"])
    assert np.all(g.jacobian[..., 1] == 0.0)
    step = 1e-6
    numeric = (pb.reference.eval_lobes(pb.Material(roughness=0.02 + step, anisotropic=0.3, subsurface=0.4), wi, wo).diffuse
               - pb.reference.eval_lobes(pb.Material(roughness=0.02 - step, anisotropic=0.3, subsurface=0.4), wi, wo).diffuse
               ) / (2 * step)
    np.testing.assert_allclose(g.jacobian[..., 0], numeric, rtol=1e-6, atol=1e-9 * np.abs(numeric).max())


def test_black_base_color_tint_has_no_derivative():
    """lum(base_color) = 0 gives Ctint = 1 (a constant): with metallic 0 only the diffuse
    color (1 - metallic) base / π moves with base_color."""
    rng = seeded_rng("gradient-black")
    wi, wo = random_direction_pairs(rng, 400, min_cos=0.05)
    m = pb.Material(base_color=(0.0, 0.0, 0.0), specular_tint=1.0, sheen=1.0, sheen_tint=1.0)
    g = pb.reference.eval_grad(m, wi, wo, wrt="base_color")
    unit = pb.reference.eval_lobes(pb.Material(base_color=(1.0, 1.0, 1.0), specular_tint=1.0, sheen=1.0, sheen_tint=1.0),
                                   wi, wo).diffuse  # D (1 - metallic) / π per channel
    for c in range(3):
        expected = np.zeros_like(g.jacobian[..., 0])
        expected[..., c] = unit[..., c]
        np.testing.assert_allclose(g.jacobian[..., c], expected, rtol=1e-13, atol=0.0)


materials = st.fixed_dictionaries({
    "base_color": st.tuples(*[st.floats(0.0, 1.0)] * 3),
    "subsurface": st.floats(0.0, 1.0), "specular": st.floats(0.0, 2.0), "specular_tint": st.floats(0.0, 1.0),
    "roughness": st.floats(0.0, 1.0), "anisotropic": st.floats(0.0, 1.0), "sheen": st.floats(0.0, 2.0),
    "sheen_tint": st.floats(0.0, 1.0), "clearcoat": st.floats(0.0, 2.0), "clearcoat_gloss": st.floats(0.0, 1.0),
})


@settings(max_examples=60, deadline=None, derandomize=True)
@given(params=materials, model=st.sampled_from(MODELS))
def test_linear_parameters_reproduce_their_lobes(params, model):
    """f is linear in sheen and clearcoat, and (metallic 0) homogeneous of degree 1 in
    base_color through the diffuse lobe (Ctint is of degree 0): each Jacobian column
    times its parameter gives that lobe."""
    rng = seeded_rng("gradient-linear")
    wi, wo = random_direction_pairs(rng, 64, min_cos=0.05)
    m = pb.Material(**params)
    g = pb.reference.eval_grad(m, wi, wo, model=model)
    lobes = pb.reference.eval_lobes(m, wi, wo, model=model)
    column = {name: g.jacobian[..., k] for k, name in enumerate(g.names)}
    np.testing.assert_allclose(column["sheen"] * params["sheen"], lobes.sheen, rtol=1e-12, atol=1e-300)
    np.testing.assert_allclose(column["clearcoat"] * params["clearcoat"], lobes.clearcoat, rtol=1e-12, atol=1e-300)
    euler = sum(column[f"base_color_{c}"] * params["base_color"][i] for i, c in enumerate("rgb"))
    scale = np.abs(g.value).max(axis=-1, keepdims=True)
    np.testing.assert_allclose(euler, lobes.diffuse, rtol=1e-10, atol=1e-12 * scale.max())


def test_names_wrt_cosine_shapes_and_horizon():
    rng = seeded_rng("gradient-api")
    wi, wo = random_direction_pairs(rng, 24)
    wi = wi.reshape(4, 6, 3)
    wo = wo.reshape(4, 6, 3)
    m = pb.Material(roughness=np.linspace(0.2, 0.8, 6), clearcoat=0.5)
    g = pb.reference.eval_grad(m, wi, wo)
    assert g.names == GRADIENT_NAMES and len(g.names) == 13
    assert g.value.shape == (4, 6, 3) and g.jacobian.shape == (4, 6, 3, 13)
    np.testing.assert_array_equal(g.value, pb.reference.eval(m, wi, wo))
    sub = pb.reference.eval_grad(m, wi, wo, wrt=["roughness", "base_color"])
    assert sub.names == ("base_color_r", "base_color_g", "base_color_b", "roughness")
    np.testing.assert_array_equal(sub.jacobian, g.jacobian[..., [0, 1, 2, 7]])
    lit = pb.reference.eval_grad(m, wi, wo, cosine=True)
    np.testing.assert_allclose(lit.jacobian, g.jacobian * wi[..., 2:3, None], rtol=1e-15)
    below = wi * np.array([1.0, 1.0, -1.0])
    zero = pb.reference.eval_grad(m, below, wo)
    assert not np.any(zero.value) and not np.any(zero.jacobian)
    with pytest.raises(ValueError, match="wrt: unknown parameter 'shininess'"):
        pb.reference.eval_grad(m, wi, wo, wrt="shininess")
    with pytest.raises(TypeError, match="wrt"):
        pb.reference.eval_grad(m, wi, wo, wrt=3)


# ---------------------------------------------------------------- the SIMD kernels (float32)

ISAS = tuple(pb.cpu_info()["available"])
DIRECTION_MIX = {"cos>=0.05": dict(min_cos=0.05, grazing_fraction=0.0), "cos>=1e-4": dict(min_cos=1e-4, grazing_fraction=0.5)}


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("directions", tuple(DIRECTION_MIX))
def test_float32_jacobian_against_float64(isa, model, directions):
    """Relative to max(|g64|, 1e-3 max_k |g64_k|) of the same element and channel, on the
    same float32 inputs: p99.99 <= 1e-4, max <= 1e-2."""
    rng = seeded_rng("gradient-simd", model, directions)
    n = 250_000
    material = pb.Material(**random_material_arrays(rng, n))
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, n, **DIRECTION_MIX[directions]))
    g32 = pb.eval_grad(material, wi, wo, model=model, isa=isa)
    g64 = pb.reference.eval_grad(material, wi.astype(np.float64), wo.astype(np.float64), model=model)
    scale = np.maximum(np.abs(g64.jacobian), 1e-3 * np.abs(g64.jacobian).max(axis=-1, keepdims=True))
    error = np.abs(g32.jacobian - g64.jacobian) / np.where(scale > 0, scale, 1.0)
    assert np.all(np.isfinite(g32.jacobian))
    assert np.percentile(error, 99.99) <= 1e-4, np.percentile(error, 99.99)
    assert error.max() <= 1e-2, error.max()
    np.testing.assert_array_equal(g32.value, pb.eval(material, wi, wo, model=model, isa=isa))


@pytest.mark.parametrize("isa", ISAS)
def test_simd_gradient_bits_do_not_depend_on_threads_tails_layout_or_uniformity(isa):
    rng = seeded_rng("gradient-bits")
    n = 1003  # not a multiple of any lane count
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, n))
    uniform = pb.Material(roughness=0.4, anisotropic=0.5, sheen=0.3, clearcoat=0.7, subsurface=0.2, metallic=0.3)
    per_element = pb.Material(**{name: np.broadcast_to(getattr(uniform, name), (n, 3) if name == "base_color" else (n,))
                                 for name in pb.PARAMETERS})
    reference = pb.eval_grad(uniform, wi, wo, isa=isa, threads=1)
    for other in (pb.eval_grad(uniform, wi, wo, isa=isa, threads=2), pb.eval_grad(per_element, wi, wo, isa=isa)):
        np.testing.assert_array_equal(other.jacobian, reference.jacobian)
        np.testing.assert_array_equal(other.value, reference.value)
    soa = pb.eval_grad(uniform, np.ascontiguousarray(wi.T), np.ascontiguousarray(wo.T), layout="soa", isa=isa)
    assert soa.jacobian.shape == (3, 13, n)
    np.testing.assert_array_equal(np.moveaxis(soa.jacobian, -1, 0), reference.jacobian)
    for start, stop in ((0, 7), (5, 22), (999, 1003)):
        part = pb.eval_grad(uniform, wi[start:stop], wo[start:stop], isa=isa)
        np.testing.assert_array_equal(part.jacobian, reference.jacobian[start:stop])


def test_simd_gradient_out_wrt_cosine_and_bad_input():
    rng = seeded_rng("gradient-api-simd")
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, 40))
    m = pb.Material(roughness=0.3, clearcoat=0.5)
    full = pb.eval_grad(m, wi, wo)
    assert full.names == GRADIENT_NAMES and full.jacobian.shape == (40, 3, 13) and full.jacobian.dtype == np.float32
    value, jacobian = np.empty((40, 3), np.float32), np.empty((40, 3, 2), np.float32)
    result = pb.eval_grad(m, wi, wo, wrt=["clearcoat_gloss", "roughness"], out=(value, jacobian))
    assert result.value is value and result.jacobian is jacobian
    assert result.names == ("roughness", "clearcoat_gloss")
    np.testing.assert_array_equal(jacobian, full.jacobian[..., [7, 12]])
    lit = pb.eval_grad(m, wi, wo, cosine=True)
    np.testing.assert_array_equal(lit.value, pb.eval(m, wi, wo, cosine=True))
    # the cosine weighs the pair's scalars before they are combined: equal up to float32 rounding
    scaled = full.jacobian * wi[:, 2, None, None]
    np.testing.assert_allclose(lit.jacobian, scaled, rtol=1e-5, atol=1e-6 * np.abs(scaled).max())
    bad = wi.copy()
    bad[17] *= 2.0
    with pytest.raises(ValueError, match=r"wi\[17\]"):
        pb.eval_grad(m, bad, wo)
    with pytest.raises(ValueError, match=r"out\[1\]: expected shape"):
        pb.eval_grad(m, wi, wo, out=(value, np.empty((40, 3, 12), np.float32)))
    with pytest.raises(TypeError, match="out: expected a tuple"):
        pb.eval_grad(m, wi, wo, out=value)
