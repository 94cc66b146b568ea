"""docs/gradients.md: the 2015 models' derivatives in their 16 parameter slots,
the float64 reference against central differences of its own f, the SIMD
kernels against the reference on every instruction set, and the
vector-Jacobian product against the Jacobian's contraction.
"""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb
from conftest import seeded_rng

ISAS = pb.cpu_info()["available"]
NAMES = pb.GRADIENT_NAMES + ("spec_trans", "flatness", "diff_trans")
MODELS = ("disney2015", "disney2015_thin")
UNREAD = {"disney2015": ("subsurface", "diff_trans"), "disney2015_thin": ("subsurface",)}  # (they stay at 0)


def sphere_directions(rng, n):
    w = rng.normal(size=(n, 3))
    return w / np.linalg.norm(w, axis=1, keepdims=True)


def smooth_materials(rng, n, model):
    """Parameters inside their domains, away from the model's clamps (alpha >= 0.001, η >= 1.001)
    and the domains' edges, where a one-sided derivative is the active branch's."""
    return {
        "base_color": rng.uniform(0.1, 1.0, (n, 3)), "metallic": rng.uniform(0.05, 0.95, n),
        "specular": rng.uniform(0.1, 2.0, n), "specular_tint": rng.uniform(0.05, 0.95, n),
        "roughness": rng.uniform(0.25, 1.0, n), "anisotropic": rng.uniform(0.05, 0.9, n),
        "sheen": rng.uniform(0.05, 1.0, n), "sheen_tint": rng.uniform(0.05, 0.95, n),
        "clearcoat": rng.uniform(0.05, 1.0, n), "clearcoat_gloss": rng.uniform(0.05, 0.95, n),
        "spec_trans": rng.uniform(0.05, 0.95, n), "flatness": rng.uniform(0.05, 0.95, n),
    } | ({"diff_trans": rng.uniform(0.05, 1.9, n)} if model == "disney2015_thin" else {})


def slot_values(params, n):
    """The materials as (n, 16) slot rows, in NAMES' order."""
    rows = np.zeros((n, 16))
    rows[:, :3] = params["base_color"]
    for k, name in enumerate(NAMES[3:], start=3):
        rows[:, k] = params.get(name, 0.0)
    return rows


def material_of(rows):
    values = {name: rows[:, k] for k, name in enumerate(NAMES) if k >= 3}
    return pb.Material(base_color=rows[:, :3], **values)


@pytest.mark.parametrize("model, mode", [("disney2015", "radiance"), ("disney2015", "importance"),
                                         ("disney2015_thin", "radiance")])
def test_reference_derivatives_are_the_central_differences(model, mode):
    rng = seeded_rng("bsdf2015-gradient", model, mode)
    n = 4000
    params = smooth_materials(rng, n, model)
    wi, wo = sphere_directions(rng, n), sphere_directions(rng, n)
    material = pb.Material(**params)
    gradient = pb.reference.eval_grad(material, wi, wo, model=model, mode=mode)
    assert gradient.names == NAMES
    unread = UNREAD[model]
    for name in unread:
        assert np.all(gradient.jacobian[..., NAMES.index(name)] == 0), name
    rows = slot_values(params, n)
    f = gradient.value
    scale = np.abs(f).max(axis=1, keepdims=True) + 1e-12
    for k, name in enumerate(NAMES):
        if name in unread:
            continue
        analytic = gradient.jacobian[..., k]

        def central_difference(relative_step):
            step = relative_step * np.maximum(np.abs(rows[:, k]), 0.1)
            up, down = rows.copy(), rows.copy()
            up[:, k] += step
            down[:, k] -= step
            f_up = pb.reference.eval(material_of(up), wi, wo, model=model, mode=mode)
            f_down = pb.reference.eval(material_of(down), wi, wo, model=model, mode=mode)
            numeric = (f_up - f_down) / (2 * step[:, None])
            # a pair whose side, total internal reflection or validity changes within the step has a kink there
            smooth = np.all((f_up > 0) == (f_down > 0), axis=1) & np.all((f_up > 0) == (f > 0), axis=1)
            # (the differences carry the rounding of f, some ulp of each of its terms, over the step)
            error = np.abs(analytic - numeric) / (np.abs(numeric) + np.abs(analytic) + 1e-12 * scale / step[:, None])
            return numeric, smooth, error

        numeric, smooth, error = central_difference(1e-5)
        # near a kink (the transmittance's square root at the critical angle) the difference's curvature
        # term needs a shorter step: a pair passes where either step agrees
        error = np.minimum(error, central_difference(1e-7)[2])
        bad = smooth[:, None] & (error > 1e-3)
        assert smooth.mean() > 0.99, name
        assert not bad.any(), (f"{name}: {bad.sum()} pairs, e.g. analytic {analytic[bad][:3]} vs numeric "
                               f"{numeric[bad][:3]}")


@pytest.fixture(scope="module", params=MODELS)
def float32_case(request):
    model = request.param
    rng = seeded_rng("bsdf2015-gradient", "simd", model)
    n = 100_000
    params = smooth_materials(rng, n, model)
    material = pb.Material(**{k: np.asarray(v, np.float32) for k, v in params.items()})
    wi, wo = (sphere_directions(rng, n).astype(np.float32) for _ in range(2))
    reference = pb.reference.eval_grad(material, wi.astype(np.float64), wo.astype(np.float64), model=model)
    return model, material, wi, wo, reference


@pytest.mark.parametrize("isa", ISAS)
def test_simd_jacobian_matches_the_reference(float32_case, isa):
    model, material, wi, wo, reference = float32_case
    simd = pb.eval_grad(material, wi, wo, model=model, isa=isa)
    assert simd.names == NAMES
    np.testing.assert_array_equal(simd.value, pb.eval(material, wi, wo, model=model, isa=isa))
    assert np.all(np.isfinite(simd.jacobian))
    # each column against its own scale: |simd - ref| / max(|ref|, 1e-4 max |ref| of the column)
    floor = 1e-4 * np.abs(reference.jacobian).max(axis=(0, 1))
    errors = np.abs(simd.jacobian - reference.jacobian) / np.maximum(np.abs(reference.jacobian), floor)
    for k, name in enumerate(NAMES):
        if name in UNREAD[model]:  # not read: 0
            assert np.all(simd.jacobian[..., k] == 0), f"{isa} {name}"
            continue
        column = errors[..., k]
        assert np.percentile(column, 99.9) <= 1e-3, f"{isa} {name}: p99.9 {np.percentile(column, 99.9):.3g}"
    some = pb.eval_grad(material, wi, wo, wrt=["roughness", "spec_trans"], model=model, isa=isa)
    np.testing.assert_array_equal(some.jacobian, simd.jacobian[..., [NAMES.index("roughness"), NAMES.index("spec_trans")]])


@pytest.mark.parametrize("isa", ISAS)
def test_the_vector_jacobian_product_is_the_contraction(float32_case, isa):
    model, material, wi, wo, _ = float32_case
    rng = seeded_rng("bsdf2015-vjp", isa)
    cotangent = rng.normal(size=wi.shape).astype(np.float32)
    jacobian = pb.eval_grad(material, wi, wo, model=model, isa=isa).jacobian.astype(np.float64)
    products = pb.eval_vjp(material, wi, wo, cotangent, model=model, isa=isa)
    expected = np.einsum("nc,nck->nk", cotangent.astype(np.float64), jacobian)
    for k, name in enumerate(NAMES):
        if name in UNREAD[model]:  # (uniform: one sum, 0)
            continue
        np.testing.assert_allclose(products[name], expected[:, k], rtol=1e-5, atol=1e-6 * np.abs(expected[:, k]).max())
