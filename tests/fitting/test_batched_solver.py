"""The batched solver of pb.fit (docs/fitting.md): the normal equations the
kernels reduce per problem, against numpy's from the float64 reference
Jacobian; recovery of the model's own parameters, agreement with the scipy
method, bounds, bad texels, and bits that do not depend on the batch or the
thread count."""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb
from principled_brdf import _core, fitting
from principled_brdf._gradient import GRADIENT_NAMES
from principled_brdf.fitting import LOSSES
from conftest import random_direction_pairs, seeded_rng

TRUTH = dict(base_color=(0.7, 0.3, 0.1), metallic=0.2, subsurface=0.3, specular=0.6, specular_tint=0.3, roughness=0.35,
             anisotropic=0.2, sheen=0.4, sheen_tint=0.6, clearcoat=0.3, clearcoat_gloss=0.7)
LOSS_CODES = {"linear": 0, "log": 1}


def pairs(n, key="batched"):
    return random_direction_pairs(seeded_rng(key), n, min_cos=0.05)


def numpy_normal_equations(rows, wi, wo, target, scale, columns, loss, cosine, gain=None, model="disney2014"):
    """JᵀJ (upper triangle by rows), Jᵀr and Σ r² of r = (u(g f) - t) s, u(x) = x or log(1 + x),
    from pb.reference.eval_grad (float64), transcribed here."""
    normal, gradient, cost = [], [], []
    for b, row in enumerate(rows):
        material = pb.Material(**{name: row[info.first_slot:info.first_slot + info.slots] if info.slots == 3
                                  else row[info.first_slot] for name, info in pb.PARAMETERS.items()
                                  if info.first_slot < len(row)})  # (the fitted models' parameters)
        g = pb.reference.eval_grad(material, wi, wo, cosine=cosine, model=model)
        gb = 1.0 if gain is None else gain[b]
        f, jacobian = gb * g.value, gb * g.jacobian[..., columns]
        if loss == "log":
            r, slope = (np.log1p(f) - target[b]) * scale[b], scale[b] / (1.0 + f)
        else:
            r, slope = (f - target[b]) * scale[b], scale[b]
        d = slope[..., None] * jacobian
        a = np.einsum("nck,ncl->kl", d, d)
        normal.append(a[np.triu_indices(len(columns))])
        gradient.append(np.einsum("nck,nc->k", d, r))
        cost.append(np.sum(r * r))
    return np.array(normal), np.array(gradient), np.array(cost)


@pytest.mark.parametrize("isa", tuple(pb.cpu_info()["available"]))
@pytest.mark.parametrize("loss", ("linear", "log"))
@pytest.mark.parametrize("cosine", (False, True))
def test_the_kernels_normal_equations_are_numpys(isa, loss, cosine):
    rng = seeded_rng("normal-equations", loss, cosine)
    n, count = 203, 3  # a tail on every lane count
    wi, wo = pairs(n, "normal-equations")
    rows = np.array([pb.Material(**TRUTH).packed(()).reshape(-1)[:len(GRADIENT_NAMES)]] * count, dtype=np.float64)
    rows[:, GRADIENT_NAMES.index("roughness")] = (0.2, 0.5, 0.8)
    rows = rows.astype(np.float32).astype(np.float64)
    target = rng.uniform(0.0, 0.5, (count, n, 3))
    scale = rng.uniform(0.5, 1.0, (count, n, 3))
    scale[1, 5] = 0.0  # a missing sample
    gain = np.float32([0.5, 4.0, 1.0]).astype(np.float64)  # the scaled log loss's 1/s
    wi32, wo32 = wi.astype(np.float32), wo.astype(np.float32)
    for columns in (list(range(len(GRADIENT_NAMES))), [GRADIENT_NAMES.index("roughness")], [0, 1, 2, 8, 12]):
        normal, gradient, cost = _core.normal_equations(
            wi=wi32, wo=wo32, slots=rows.astype(np.float32), target=target.astype(np.float32),
            scale=scale.astype(np.float32), problems=np.array([2, 0, 1], np.int64), columns=columns,
            loss=LOSS_CODES[loss], cosine=cosine, model=0, isa=isa, gain=gain.astype(np.float32))
        order = [2, 0, 1]
        expected = numpy_normal_equations(rows[order], wi32.astype(np.float64), wo32.astype(np.float64),
                                          target.astype(np.float32)[order].astype(np.float64),
                                          scale.astype(np.float32)[order].astype(np.float64), columns, loss, cosine,
                                          gain[order])
        # float32 Jacobians, summed per lane in float32: relative to the entries' natural size
        diagonal = np.stack([expected[0][:, k * len(columns) - k * (k - 1) // 2] for k in range(len(columns))], 1)
        size = np.sqrt(np.einsum("bk,bl->bkl", diagonal, diagonal))[:, *np.triu_indices(len(columns))]
        assert np.all(np.abs(normal - expected[0]) <= 1e-4 * size + 1e-12)
        gradient_size = np.sqrt(diagonal * expected[2][:, None])
        assert np.all(np.abs(gradient - expected[1]) <= 1e-4 * gradient_size + 1e-12)
        np.testing.assert_allclose(cost, expected[2], rtol=1e-5)


@pytest.mark.parametrize("isa", tuple(pb.cpu_info()["available"]))
@pytest.mark.parametrize("model", ("disney2015", "disney2015_thin"))
def test_the_kernels_normal_equations_of_the_2015_models_are_numpys(isa, model):
    # every slot of the table (spec_trans, flatness, diff_trans too), the light on the whole sphere
    rng = seeded_rng("normal-equations-2015", model)
    n, count = 203, 2
    wi, wo = pairs(n, "normal-equations-2015")
    wi[::3, 2] *= -1.0  # a third of the light below the surface: the transmission
    own = dict(TRUTH, subsurface=0.0, spec_trans=0.4, flatness=0.3, diff_trans=0.6 if model.endswith("thin") else 0.0)
    rows = np.array([pb.Material(**own).packed(()).reshape(-1)] * count)
    rows[1, GRADIENT_NAMES.index("roughness")] = 0.7
    rows = rows.astype(np.float32).astype(np.float64)
    target = rng.uniform(0.0, 0.5, (count, n, 3)).astype(np.float32).astype(np.float64)
    scale = rng.uniform(0.5, 1.0, (count, n, 3)).astype(np.float32).astype(np.float64)
    gain = np.float32([0.5, 2.0]).astype(np.float64)
    wi32, wo32 = wi.astype(np.float32), wo.astype(np.float32)
    model_code = pb._validate.model_index(model)
    for columns in (list(range(16)), [0, 7, 13, 14, 15]):
        for loss in ("linear", "log"):
            normal, gradient, cost = _core.normal_equations(
                wi=wi32, wo=wo32, slots=rows.astype(np.float32), target=target.astype(np.float32),
                scale=scale.astype(np.float32), problems=np.array([1, 0], np.int64), columns=columns,
                loss=LOSS_CODES[loss], cosine=True, model=model_code, isa=isa, gain=gain.astype(np.float32))
            order = [1, 0]
            expected = numpy_normal_equations(rows[order], wi32.astype(np.float64), wo32.astype(np.float64),
                                              target[order], scale[order], columns, loss, True, gain[order], model)
            diagonal = np.stack([expected[0][:, k * len(columns) - k * (k - 1) // 2] for k in range(len(columns))], 1)
            size = np.sqrt(np.einsum("bk,bl->bkl", diagonal, diagonal))[:, *np.triu_indices(len(columns))]
            assert np.all(np.abs(normal - expected[0]) <= 1e-4 * size + 1e-12), (columns, loss)
            gradient_size = np.sqrt(diagonal * expected[2][:, None])
            assert np.all(np.abs(gradient - expected[1]) <= 1e-4 * gradient_size + 1e-12), (columns, loss)
            np.testing.assert_allclose(cost, expected[2], rtol=1e-5)


def test_the_float64_paths_normal_equations_are_numpys():
    from principled_brdf import _solver

    rng = seeded_rng("normal-equations-64")
    n, count = 50, 2
    wi, wo = pairs(n, "normal-equations-64")
    rows = np.array([pb.Material(**TRUTH).packed(()).reshape(-1)[:len(GRADIENT_NAMES)]] * count, dtype=np.float64)
    rows[1, GRADIENT_NAMES.index("roughness")] = 0.7
    target, scale = rng.uniform(0.0, 0.5, (count, n, 3)), rng.uniform(0.5, 1.0, (count, n, 3))
    columns = [0, 1, 2, 7, 12]
    for loss in ("linear", "log"):
        gain = np.array([1.0, 0.25])
        equations = _solver.float64_equations(fitting._material_of, wi, wo, target, scale, gain, rows,
                                              columns, np.arange(count), LOSS_CODES[loss], True, "disney2014")
        got = equations.evaluate(np.arange(count), rows[:, columns])
        expected = numpy_normal_equations(rows, wi, wo, target, scale, columns, loss, True, gain)
        for a, b in zip(got, expected):
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12 * np.abs(b).max())


def texels(count=6, n=400, key="texels", roughest=(0.15, 0.8)):
    """Measurements of the model itself (float64) for `count` materials of varied roughness,
    metallic and colour."""
    rng = seeded_rng(key)
    wi, wo = pairs(n, key)
    roughness = rng.uniform(*roughest, count)
    metallic = rng.uniform(0.0, 1.0, count)
    base_color = rng.uniform(0.1, 0.9, (count, 3))
    truth = pb.Material(roughness=roughness[:, None], metallic=metallic[:, None], base_color=base_color[:, None])
    return wi, wo, pb.reference.eval(truth, wi, wo), np.column_stack([base_color, metallic, roughness])


FITTED = ["base_color", "metallic", "roughness"]
FITTED_SLOTS = [0, 1, 2, GRADIENT_NAMES.index("metallic"), GRADIENT_NAMES.index("roughness")]


@pytest.mark.parametrize("precision", ("float32", "float64"))
@pytest.mark.parametrize("loss", LOSSES)
def test_the_default_recovers_the_models_parameters(precision, loss):
    # the relative loss, which weighs the darkest samples most, finds a glossy peak from nearby
    # only (docs/fitting.md); scipy's method ends in the same other minimum from the default start
    wi, wo, measured, truth = texels(roughest=(0.3, 0.8) if loss == "relative" else (0.15, 0.8))
    result = pb.fit(wi, wo, measured, fit=FITTED, loss=loss, precision=precision)
    assert result.success.all(), result.message
    tolerance = 2e-3 if precision == "float32" else 1e-6
    np.testing.assert_allclose(result.slots[:, FITTED_SLOTS], truth, atol=tolerance)
    # the cost at the float32 kernels' rounding: relative to the data's own size (linear's is in 1/sr²)
    size = 0.5 * np.sum((measured * wi[:, 2, None]) ** 2, axis=(1, 2)) if loss == "linear" else 1.0
    assert np.all(result.cost < (1e-7 if precision == "float32" else 1e-12) * size)
    assert np.all(result.iterations >= 2) and np.all(result.iterations <= 200)


def test_every_parameter_from_the_default_start_matches_f():
    wi, wo = pairs(3000, "every-parameter")
    measured = pb.reference.eval(pb.Material(**TRUTH), wi, wo)
    result = pb.fit(wi, wo, measured)
    assert result.success
    np.testing.assert_allclose(pb.reference.eval(result.material, wi, wo), measured, rtol=2e-3,
                               atol=1e-6 * measured.max())


@pytest.mark.parametrize("loss", LOSSES)
def test_with_noise_the_batched_and_scipy_methods_agree(loss):
    wi, wo, measured, truth = texels(count=4, key="noisy")
    noisy = measured * seeded_rng("noise", loss).lognormal(0.0, 0.05, measured.shape)
    batched = pb.fit(wi, wo, noisy, fit=FITTED, loss=loss)
    scipy = pb.fit(wi, wo, noisy, fit=FITTED, loss=loss, method="scipy")
    assert batched.success.all() and scipy.success.all()
    np.testing.assert_allclose(batched.slots[:, FITTED_SLOTS], scipy.slots[:, FITTED_SLOTS], atol=5e-3)
    # the same minimum: neither cost is more than a hair below the other
    np.testing.assert_allclose(batched.cost, scipy.cost, rtol=1e-3)
    if loss != "linear":  # (linear weighs the noise of the brightest samples most: metallic may end on a bound)
        np.testing.assert_allclose(batched.slots[:, FITTED_SLOTS], truth, atol=0.05)


def test_bounds_are_respected():
    wi, wo, measured, truth = texels(count=4, key="bounded")
    bounds = {"roughness": (0.3, 0.5), "metallic": (0.0, 0.5)}
    result = pb.fit(wi, wo, measured, fit=FITTED, bounds=bounds)
    roughness, metallic = result.slots[:, FITTED_SLOTS[4]], result.slots[:, FITTED_SLOTS[3]]
    assert np.all((roughness >= 0.3) & (roughness <= 0.5)) and np.all((metallic >= 0.0) & (metallic <= 0.5))
    # a truth outside the bounds ends on the bound it lies beyond
    assert np.all(roughness[truth[:, 4] > 0.55] == 0.5) and np.all(roughness[truth[:, 4] < 0.25] == 0.3)
    np.testing.assert_array_less(-1e-12, result.slots[:, :3])
    # within the bounds, the truth is found
    inside = (truth[:, 4] > 0.3) & (truth[:, 4] < 0.5) & (truth[:, 3] < 0.5)
    np.testing.assert_allclose(result.slots[inside][:, FITTED_SLOTS], truth[inside], atol=2e-3)


@pytest.mark.parametrize("loss", LOSSES)
def test_a_nan_texel_and_a_black_texel_do_not_abort_the_batch(loss):
    wi, wo, measured, truth = texels(count=4, key="bad-texels")
    measured[1] = np.nan
    measured[2] = 0.0
    measured[3, ::5] = np.nan
    result = pb.fit(wi, wo, measured, fit=FITTED, loss=loss)
    assert not result.success[1] and result.message[1].startswith("no data") and result.iterations[1] == 0
    assert np.isnan(result.residuals[1]).all() and result.cost[1] == 0.0
    assert result.success[[0, 2, 3]].all()
    assert np.isfinite(result.slots).all() and np.isfinite(result.residuals[[0, 2]]).all()
    np.testing.assert_allclose(result.slots[[0, 3]][:, FITTED_SLOTS], truth[[0, 3]], atol=2e-3)
    # black: as dark as the model gets (no base colour, metallic: only the Fresnel edge is left),
    # the minimum scipy's method finds
    black = pb.fit(wi, wo, measured[2], fit=FITTED, loss=loss, method="scipy")
    np.testing.assert_allclose(result.slots[2], black.slots, atol=1e-6)
    assert result.cost[2] <= black.cost * (1.0 + 1e-6)


def test_a_problems_bits_do_not_depend_on_its_batch_or_the_threads():
    wi, wo, measured, _ = texels(count=6, key="bits")
    noisy = measured * seeded_rng("bits-noise").lognormal(0.0, 0.05, measured.shape)
    together = pb.fit(wi, wo, noisy, fit=FITTED)
    for threads in (1, 2):
        np.testing.assert_array_equal(pb.fit(wi, wo, noisy, fit=FITTED, threads=threads).slots, together.slots)
    for rows in ([3], [5, 0], [4, 1, 2]):
        part = pb.fit(wi, wo, noisy[rows], fit=FITTED)
        np.testing.assert_array_equal(part.slots, together.slots[rows])
        np.testing.assert_array_equal(part.iterations, together.iterations[rows])
        np.testing.assert_array_equal(part.cost, together.cost[rows])
    alone = pb.fit(wi, wo, noisy[2], fit=FITTED)
    np.testing.assert_array_equal(alone.slots, together.slots[2])


def test_method_and_threads_are_checked():
    wi, wo, measured, _ = texels(count=1, n=20, key="arguments")
    with pytest.raises(ValueError, match="method: expected one of batched, scipy"):
        pb.fit(wi, wo, measured[0], method="lm")
    with pytest.raises(ValueError, match="threads"):
        pb.fit(wi, wo, measured[0], threads=0)
    one = pb.fit(wi, wo, measured[0], fit="roughness", max_iterations=1)
    assert one.iterations == 1 and not one.success and "max_iterations" in one.message


def test_the_batched_method_leaves_blas_alone(monkeypatch):
    """No BLAS call of the batched method needs a thread limit: it never sets one."""
    threadpoolctl = pytest.importorskip("threadpoolctl")

    def refuse(*args, **kwargs):
        raise AssertionError("the batched fit limited BLAS threads")

    monkeypatch.setattr(threadpoolctl, "threadpool_limits", refuse)
    wi, wo, measured, truth = texels(count=2, n=100, key="blas")
    result = pb.fit(wi, wo, measured, fit=FITTED)
    assert result.success.all()


def test_a_texture_solved_in_parts_is_the_texture_solved_at_once(monkeypatch):
    """fit takes a large batch a few million samples at a time: the parts give the same bits."""
    wi, wo, measured, _ = texels(count=5, n=100, key="parts")
    whole = pb.fit(wi, wo, measured, fit=FITTED)
    monkeypatch.setattr(fitting, "_batch_problems", lambda pairs: 2)
    parts = pb.fit(wi, wo, measured, fit=FITTED)
    np.testing.assert_array_equal(parts.slots, whole.slots)
    np.testing.assert_array_equal(parts.cost, whole.cost)
    assert parts.message == whole.message and parts.notes == whole.notes
    # directions per problem for one of wi, wo
    per_problem = pb.fit(wi, np.broadcast_to(wo, (5,) + wo.shape), measured, fit=FITTED)
    np.testing.assert_array_equal(per_problem.slots, whole.slots)
