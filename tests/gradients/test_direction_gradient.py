"""The derivatives of f in the directions, eval_grad's wi and wo columns (docs/gradients.md).

float64 against central differences of the float64 reference (the 3-vectors
moved as given, not renormalised), float32 kernels against float64 on the
same inputs, the cosine option, the parameter columns unchanged, the API.
"""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb
from principled_brdf import _core
from principled_brdf._gradient import GRADIENT_NAMES
from conftest import MODELS, random_direction_pairs, random_material_arrays, seeded_rng

MODEL_IDS = {"disney2014": 0, "disney2012": 1}
DIRECTIONS = ("wi_x", "wi_y", "wi_z", "wo_x", "wo_y", "wo_z")
ISAS = tuple(pb.cpu_info()["available"])
# what the directions' derivatives are checked on: random pairs (with the mirror, wi = wo and
# near them), and pairs near the horizon
PAIRS = {"random": dict(min_cos=0.02, grazing_fraction=0.0), "grazing": dict(min_cos=1e-3, grazing_fraction=0.6)}


def material_rows(rng, n):
    """Packed random materials (anisotropic ones among them), roughness >= 0.15 and
    clearcoat_gloss <= 0.9 so that a finite difference resolves the peaks."""
    material = pb.Material(**random_material_arrays(rng, n))
    rows = np.array(material.packed((n,)), dtype=np.float64)
    roughness, gloss = GRADIENT_NAMES.index("roughness"), GRADIENT_NAMES.index("clearcoat_gloss")
    rows[:, roughness] = np.maximum(rows[:, roughness], 0.15)
    rows[:, gloss] = np.minimum(rows[:, gloss], 0.9)
    return np.ascontiguousarray(rows)


def central_difference(wi, wo, rows, component, model_id, step, cosine=False):
    """The fourth-order central difference of f (times cos θl) in one direction component."""
    def f(offset):
        moved_wi, moved_wo = wi.copy(), wo.copy()
        (moved_wi if component < 3 else moved_wo)[:, component % 3] += offset
        value = _core.reference_eval(moved_wi, moved_wo, rows, model_id, False)
        return value * moved_wi[:, 2:3] if cosine else value
    return (8.0 * (f(step) - f(-step)) - (f(2 * step) - f(-2 * step))) / (12.0 * step)


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("pairs", tuple(PAIRS))
@pytest.mark.parametrize("cosine", (False, True))
def test_float64_direction_derivatives_match_central_differences(model, pairs, cosine):
    """Relative to max(|g|, 1e-6 max_k |g_k|) of the same element and channel: <= 1e-6."""
    rng = seeded_rng("direction-fd", model, pairs, cosine)
    n = 2000
    wi, wo = (np.ascontiguousarray(w, dtype=np.float64) for w in random_direction_pairs(rng, n, **PAIRS[pairs]))
    rows = material_rows(rng, n)
    jacobian = _core.reference_eval_direction_grad(wi, wo, rows, MODEL_IDS[model], cosine)
    value = _core.reference_eval(wi, wo, rows, MODEL_IDS[model], False) * (wi[:, 2:3] if cosine else 1.0)
    step = 1e-5 if pairs == "random" else 2e-6
    rounding = 4.0 * np.finfo(np.float64).eps * np.abs(value) / step  # what rounding puts into the quotient
    scale_all = 1e-6 * np.abs(jacobian).max(axis=-1)
    # FH = (1 - cos θd)^5 with 1 - cos θd ~ |wi - wo|² / 4: a difference quotient resolves it only
    # for pairs much further apart than the step (wi = wo itself is in the float32 comparison)
    # and the lobes' peaks in the half vector are alpha |H| wide (alpha down to 0.011 here): a
    # pair whose H = wi + wo nearly vanishes (back to back at the horizon) needs a smaller step
    apart = (np.linalg.norm(wi - wo, axis=-1)[:, None] >= 100 * step) & (np.linalg.norm(wi + wo, axis=-1)[:, None] >= 0.05)
    checked = 0
    for component, name in enumerate(DIRECTIONS):
        numeric = central_difference(wi, wo, rows, component, MODEL_IDS[model], step, cosine)
        analytic = jacobian[..., component]
        scale = np.maximum(np.abs(analytic), scale_all)
        resolvable = (rounding <= 1e-8 * scale) & (scale > 0) & apart
        error = np.abs(numeric - analytic) / np.where(resolvable, scale, 1.0)
        assert np.all(error[resolvable] <= 1e-6), (name, float(error[resolvable].max()))
        checked += int(resolvable.sum())
    # (near the horizon f and its derivatives are small against rounding more often)
    assert checked >= (0.75 if pairs == "random" else 0.6) * n * 3 * len(DIRECTIONS), checked / (n * 3 * len(DIRECTIONS))


def test_float64_cosine_is_the_product_rule():
    """∂(f cos θl)/∂w = cos θl ∂f/∂w + f ∂wi_z/∂w."""
    rng = seeded_rng("direction-cosine")
    wi, wo = random_direction_pairs(rng, 500, min_cos=0.01)
    m = pb.Material(**random_material_arrays(rng, 500))
    plain = pb.reference.eval_grad(m, wi, wo, wrt=["wi", "wo"])
    lit = pb.reference.eval_grad(m, wi, wo, wrt=["wi", "wo"], cosine=True)
    expected = plain.jacobian * wi[:, 2, None, None]
    expected[..., 2] += plain.value
    np.testing.assert_allclose(lit.jacobian, expected, rtol=1e-12, atol=1e-14 * np.abs(expected).max())
    np.testing.assert_array_equal(lit.value, pb.reference.eval(m, wi, wo, cosine=True))


DIRECTION_MIX = {"cos>=0.05": dict(min_cos=0.05, grazing_fraction=0.0), "cos>=1e-4": dict(min_cos=1e-4, grazing_fraction=0.5)}


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("directions", tuple(DIRECTION_MIX))
def test_float32_direction_derivatives_against_float64(isa, model, directions):
    """Relative to max(|g64|, 1e-3 max_k |g64_k|) of the same element and channel (k over
    the six direction columns), on the same float32 inputs: p99.99 <= 1e-4, max <= 1e-2
    (the kernels sum in double: docs/gradients.md, "Derivatives in the directions")."""
    rng = seeded_rng("direction-simd", model, directions)
    n = 60_000
    material = pb.Material(**{k: np.asarray(v, np.float32) for k, v in random_material_arrays(rng, n).items()})
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, n, **DIRECTION_MIX[directions]))
    cosine = directions == "cos>=1e-4"  # the cosine option on one of the two mixes
    g32 = pb.eval_grad(material, wi, wo, wrt=["wi", "wo"], model=model, cosine=cosine, isa=isa)
    g64 = pb.reference.eval_grad(material, wi.astype(np.float64), wo.astype(np.float64), wrt=["wi", "wo"], model=model,
                                 cosine=cosine)
    assert g32.names == DIRECTIONS and g32.jacobian.dtype == np.float32
    scale = np.maximum(np.abs(g64.jacobian), 1e-3 * np.abs(g64.jacobian).max(axis=-1, keepdims=True))
    # channels whose f is below float32's normal range (a metal's zero channel) have no digits to compare
    scale = np.maximum(scale, 1e-3 * float(np.finfo(np.float32).tiny))
    error = np.abs(g32.jacobian - g64.jacobian) / np.where(scale > 0, scale, 1.0)
    assert np.all(np.isfinite(g32.jacobian))
    assert np.percentile(error, 99.99) <= 1e-4, np.percentile(error, 99.99)
    assert error.max() <= 1e-2, error.max()
    # in float32's normal range each entry is the double sum rounded once
    normal = scale >= np.finfo(np.float32).tiny
    assert error[normal].max() <= 1e-7, error[normal].max()
    np.testing.assert_array_equal(g32.value, pb.eval(material, wi, wo, model=model, cosine=cosine, isa=isa))


@pytest.mark.parametrize("isa", ISAS)
def test_simd_direction_bits_do_not_depend_on_threads_tails_layout_or_uniformity(isa):
    rng = seeded_rng("direction-bits")
    n = 1003  # not a multiple of any lane count
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, n))
    uniform = pb.Material(roughness=0.4, anisotropic=0.5, sheen=0.3, clearcoat=0.7, subsurface=0.2, metallic=0.3)
    per_element = pb.Material(**{name: np.broadcast_to(getattr(uniform, name), (n, 3) if name == "base_color" else (n,))
                                 for name in pb.PARAMETERS})
    wrt = ["wi", "wo"]
    reference = pb.eval_grad(uniform, wi, wo, wrt=wrt, isa=isa, threads=1)
    for other in (pb.eval_grad(uniform, wi, wo, wrt=wrt, isa=isa, threads=2),
                  pb.eval_grad(per_element, wi, wo, wrt=wrt, isa=isa)):
        np.testing.assert_array_equal(other.jacobian, reference.jacobian)
    soa = pb.eval_grad(uniform, np.ascontiguousarray(wi.T), np.ascontiguousarray(wo.T), wrt=wrt, layout="soa", isa=isa)
    assert soa.jacobian.shape == (3, 6, n)
    np.testing.assert_array_equal(np.moveaxis(soa.jacobian, -1, 0), reference.jacobian)
    for start, stop in ((0, 7), (5, 22), (999, 1003)):
        part = pb.eval_grad(uniform, wi[start:stop], wo[start:stop], wrt=wrt, isa=isa)
        np.testing.assert_array_equal(part.jacobian, reference.jacobian[start:stop])
    one_wo = pb.eval_grad(uniform, wi, wo[3], wrt="wo", isa=isa)  # one shared vector
    np.testing.assert_array_equal(one_wo.jacobian, pb.eval_grad(uniform, wi, np.broadcast_to(wo[3], wi.shape), wrt="wo",
                                                                isa=isa).jacobian)


@pytest.mark.parametrize("path", ("simd", "reference"))
def test_parameter_columns_are_unchanged_and_directions_come_last(path):
    rng = seeded_rng("direction-columns", path)
    wi, wo = random_direction_pairs(rng, 300)
    if path == "simd":
        wi, wo = wi.astype(np.float32), wo.astype(np.float32)
    m = pb.Material(**random_material_arrays(rng, 300))
    eval_grad = pb.eval_grad if path == "simd" else pb.reference.eval_grad
    alone = eval_grad(m, wi, wo)
    parameters = [name for name in pb.PARAMETERS if name not in ("spec_trans", "flatness", "diff_trans")]
    both = eval_grad(m, wi, wo, wrt=["wo", *parameters, "wi"])
    assert both.names == GRADIENT_NAMES + DIRECTIONS
    np.testing.assert_array_equal(both.jacobian[..., :13], alone.jacobian)
    np.testing.assert_array_equal(both.value, alone.value)
    directions = eval_grad(m, wi, wo, wrt=["wi", "wo"])
    np.testing.assert_array_equal(both.jacobian[..., 13:], directions.jacobian)
    np.testing.assert_array_equal(directions.value, alone.value)
    some = eval_grad(m, wi, wo, wrt=["wo_z", "roughness", "wi_x"])
    assert some.names == ("roughness", "wi_x", "wo_z")
    np.testing.assert_array_equal(some.jacobian, both.jacobian[..., [7, 13, 18]])
    soa = eval_grad(m, np.moveaxis(wi, -1, 0), np.moveaxis(wo, -1, 0), wrt=["roughness", "wi"], layout="soa")
    assert soa.jacobian.shape == (3, 4, 300)
    np.testing.assert_array_equal(np.moveaxis(soa.jacobian, -1, 0), both.jacobian[..., [7, 13, 14, 15]])


@pytest.mark.parametrize("path", ("simd", "reference"))
def test_below_the_surface_the_derivatives_are_zero(path):
    rng = seeded_rng("direction-horizon", path)
    wi, wo = random_direction_pairs(rng, 64)
    eval_grad = pb.eval_grad if path == "simd" else pb.reference.eval_grad
    m = pb.Material(clearcoat=1.0, sheen=0.5, subsurface=0.5)
    for below_wi, below_wo in ((wi * [1, 1, -1], wo), (wi, wo * [1, 1, -1]), (wi * [1, 1, -1], wo * [1, 1, -1])):
        g = eval_grad(m, below_wi, below_wo, wrt=["wi", "wo"], cosine=True)
        assert not np.any(g.value) and not np.any(g.jacobian)
    horizon = wi[np.linalg.norm(wi[:, :2], axis=-1) > 0.1]  # (the pairs include the normal itself)
    horizon[:, 2] = 0.0
    horizon[:, :2] /= np.linalg.norm(horizon[:, :2], axis=-1, keepdims=True)
    assert not np.any(eval_grad(m, horizon, wo[:len(horizon)], wrt="wi").jacobian)


def test_direction_wrt_out_and_bad_input():
    rng = seeded_rng("direction-api")
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, 40))
    m = pb.Material(roughness=0.3, clearcoat=0.5)
    full = pb.eval_grad(m, wi, wo, wrt=["base_color", "wi", "wo"])
    value, jacobian = np.empty((40, 3), np.float32), np.empty((40, 3, 9), np.float32)
    result = pb.eval_grad(m, wi, wo, wrt=["base_color", "wi", "wo"], out=(value, jacobian))
    assert result.value is value and result.jacobian is jacobian
    np.testing.assert_array_equal(jacobian, full.jacobian)
    with pytest.raises(ValueError, match=r"out\[1\]: expected shape"):
        pb.eval_grad(m, wi, wo, wrt="wi", out=(value, jacobian))
    bad = wi.copy()
    bad[17] *= 2.0
    for wrt in ("wi", ["roughness", "wo"]):
        with pytest.raises(ValueError, match=r"wi\[17\]"):
            pb.eval_grad(m, bad, wo, wrt=wrt)
    with pytest.raises(ValueError, match=r"wi\[17\]"):
        pb.reference.eval_grad(m, bad, wo, wrt="wo")
    for eval_grad in (pb.eval_grad, pb.reference.eval_grad):
        with pytest.raises(ValueError, match="wrt: unknown parameter 'wx'.*wi or wo"):
            eval_grad(m, wi, wo, wrt=["wi", "wx"])
        with pytest.raises(TypeError, match="wrt"):
            eval_grad(m, wi, wo, wrt=["wi", 3])
        with pytest.raises(NotImplementedError, match="energy_compensation"):
            eval_grad(m, wi, wo, wrt="wi", energy_compensation=True)


@pytest.mark.parametrize("isa", ISAS)
def test_the_directions_vjp_kernel_is_the_jacobians_contraction(isa):
    """batch_eval_direction_vjp (the interop's backward pass): Σ_c g_c ∂f_c/∂w per element,
    within a few float32 roundings of the contraction of eval_grad's direction columns."""
    from principled_brdf import _derivatives

    rng = seeded_rng("direction-vjp", isa)
    n = 1003
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, n))
    m = pb.Material(**random_material_arrays(rng, n))
    g = rng.normal(size=(n, 3)).astype(np.float32)
    for cosine in (False, True):
        by_wi, by_wo = _derivatives.direction_vjp(m, wi, wo, g, cosine=cosine, isa=isa)
        jacobian = pb.eval_grad(m, wi, wo, wrt=["wi", "wo"], cosine=cosine, isa=isa).jacobian.astype(np.float64)
        expected = np.einsum("nc,nck->nk", g.astype(np.float64), jacobian)
        bound = 4 * np.finfo(np.float32).eps * np.einsum("nc,nck->nk", np.abs(g), np.abs(jacobian))
        assert np.all(np.abs(np.concatenate([by_wi, by_wo], -1) - expected) <= bound)
    one_g = _derivatives.direction_vjp(m, wi, wo, g[0], isa=isa)  # one cotangent for every element
    np.testing.assert_array_equal(one_g[1], _derivatives.direction_vjp(m, wi, wo, np.broadcast_to(g[0], g.shape), isa=isa)[1])
