"""docs/gradients.md: the 2015 models' derivatives in their 16 parameter slots,
the float64 reference against central differences of its own f, the SIMD
kernels against the reference on every instruction set, and the
vector-Jacobian product against the Jacobian's contraction.
"""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb
from principled_brdf import _core, _validate
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


# ---------------------------------------------------------------- in the directions
DIRECTIONS = ("wi_x", "wi_y", "wi_z", "wo_x", "wo_y", "wo_z")


def off_the_tangent_plane(rng, n, lowest=1e-3):
    """Directions over the sphere with |cos θ| >= lowest (a step in z must not cross the plane)."""
    w = sphere_directions(rng, 2 * n)
    return w[np.abs(w[:, 2]) >= lowest][:n]


@pytest.mark.parametrize("model, mode, cosine", [("disney2015", "radiance", False), ("disney2015", "importance", True),
                                                 ("disney2015_thin", "radiance", False)])
def test_reference_direction_derivatives_are_the_central_differences(model, mode, cosine):
    """∂f/∂w of each component of the 3-vectors as given, over the whole sphere: reflection and
    transmission from both sides, against central differences of the reference's f."""
    rng = seeded_rng("bsdf2015-direction-gradient", model, mode)
    n = 4000
    material = pb.Material(**smooth_materials(rng, n, model))
    wi, wo = off_the_tangent_plane(rng, n), off_the_tangent_plane(rng, n)
    gradient = pb.reference.eval_grad(material, wi, wo, wrt=["wi", "wo"], model=model, mode=mode, cosine=cosine)
    assert gradient.names == DIRECTIONS
    f = gradient.value
    np.testing.assert_array_equal(f, pb.reference.eval(material, wi, wo, model=model, mode=mode, cosine=cosine))
    assert np.mean(wi[:, 2] * wo[:, 2] < 0) > 0.4 and np.mean(np.abs(f).max(axis=1) > 0) > 0.6
    scale = np.abs(f).max(axis=1, keepdims=True) + 1e-12
    rows = np.ascontiguousarray(material.packed((n,)), dtype=np.float64)
    model_id, mode_id = _validate.model_index(model), _validate.mode_index(mode)

    def f_moved(moved_wi, moved_wo):  # the reference's f of the 3-vectors as given (pb.reference.eval checks them)
        value = _core.reference_eval(np.ascontiguousarray(moved_wi), np.ascontiguousarray(moved_wo), rows, model_id,
                                     False, False, mode_id)
        return value * np.abs(moved_wi[:, 2:3]) if cosine else value

    for k, name in enumerate(DIRECTIONS):
        analytic = gradient.jacobian[..., k]

        def central_difference(step):
            up, down = (np.concatenate([wi, wo], axis=1) for _ in range(2))
            up[:, k] += step
            down[:, k] -= step
            f_up, f_down = (f_moved(w[:, :3], w[:, 3:]) for w in (up, down))
            numeric = (f_up - f_down) / (2 * step)
            smooth = np.all((f_up > 0) == (f_down > 0), axis=1) & np.all((f_up > 0) == (f > 0), axis=1)
            error = np.abs(analytic - numeric) / (np.abs(numeric) + np.abs(analytic) + 1e-12 * scale / step)
            return numeric, smooth, error

        numeric, smooth, error = central_difference(1e-5)
        error = np.minimum(error, central_difference(1e-7)[2])  # (a kink near the critical angle: as above)
        bad = smooth[:, None] & (error > 1e-3)
        assert smooth.mean() > 0.99, name
        assert not bad.any(), (f"{name}: {bad.sum()} pairs, e.g. analytic {analytic[bad][:3]} vs numeric "
                               f"{numeric[bad][:3]}")


def near_the_critical_angle(material, wi, wo, model, band=0.02):
    """Pairs whose microfacet (the reflection's half vector, or the transmission's generalised
    one, Walter et al. 2007 eq. 16) sees the interface within |cos²θt| < band of its critical
    angle; never on the thin sheet, whose interface does not bend the light."""
    if model == "disney2015_thin":
        return np.zeros(len(wi), bool)
    r = np.sqrt(0.08 * np.asarray(material.specular, np.float64))
    eta = 2.0 / (1.0 - r) - 1.0
    inside = wo[:, 2] < 0
    mirror = np.where(inside[:, None], [1.0, 1.0, -1.0], 1.0)
    wi, wo = wi * mirror, wo * mirror
    eta_t = np.where(inside, 1.0 / eta, eta)
    through = wi[:, 2] < 0
    h = np.where(through[:, None], wo + eta_t[:, None] * wi, wo + wi)
    cos_h = np.abs(np.sum(wo * h, axis=1)) / np.linalg.norm(h, axis=1)
    return np.abs(1.0 - (1.0 - cos_h**2) / eta_t**2) < band


@pytest.fixture(scope="module", params=MODELS)
def float32_direction_case(request):
    model = request.param
    rng = seeded_rng("bsdf2015-direction-gradient", "simd", model)
    n = 60_000
    material = pb.Material(**{k: np.asarray(v, np.float32) for k, v in smooth_materials(rng, n, model).items()})
    wi, wo = (sphere_directions(rng, n).astype(np.float32) for _ in range(2))
    reference = pb.reference.eval_grad(material, wi.astype(np.float64), wo.astype(np.float64), wrt=["wi", "wo"],
                                       model=model, mode="importance")
    return model, material, wi, wo, reference


@pytest.mark.parametrize("isa", ISAS)
def test_simd_direction_derivatives_match_the_reference(float32_direction_case, isa):
    """Relative to max(|g64|, 1e-3 max_k |g64_k|) of the same element and channel (k over the six
    columns), on the same float32 inputs (docs/gradients.md, "Derivatives in the directions")."""
    model, material, wi, wo, reference = float32_direction_case
    simd = pb.eval_grad(material, wi, wo, wrt=["wi", "wo"], model=model, mode="importance", isa=isa)
    assert simd.names == DIRECTIONS and simd.jacobian.dtype == np.float32
    np.testing.assert_array_equal(simd.value, pb.eval(material, wi, wo, model=model, mode="importance", isa=isa))
    assert np.all(np.isfinite(simd.jacobian))
    scale = np.maximum(np.abs(reference.jacobian), 1e-3 * np.abs(reference.jacobian).max(axis=-1, keepdims=True))
    error = np.abs(simd.jacobian - reference.jacobian) / np.where(scale > 0, scale, 1.0)
    assert np.percentile(error, 99.99) <= 1e-4, np.percentile(error, 99.99)
    assert error.max() <= 1e-2, error.max()
    # each entry is the double sum rounded once, near the critical angle too, where the square
    # root of cos²θt (Fresnel's factor) would amplify float32's roundings by 1 / (2 cos²θt)
    normal = scale >= np.finfo(np.float32).tiny
    assert np.all(error[normal] <= 1e-7), error[normal].max()
    near = near_the_critical_angle(material, wi, wo, model)
    assert model == "disney2015_thin" or near.sum() >= 500, near.sum()
    # with the parameters' columns: the same columns as alone, after them
    both = pb.eval_grad(material[:999], wi[:999], wo[:999], wrt=["wo", "spec_trans", "wi"], model=model,
                        mode="importance", isa=isa)
    assert both.names == ("spec_trans",) + DIRECTIONS
    np.testing.assert_array_equal(both.jacobian[..., 1:], simd.jacobian[:999])


@pytest.mark.parametrize("isa", ISAS)
def test_the_direction_vector_jacobian_product_is_the_contraction(float32_direction_case, isa):
    from principled_brdf import _derivatives

    model, material, wi, wo, _ = float32_direction_case
    g = seeded_rng("bsdf2015-direction-vjp", isa).normal(size=wi.shape).astype(np.float32)
    for cosine in (False, True):
        jacobian = pb.eval_grad(material, wi, wo, wrt=["wi", "wo"], model=model, cosine=cosine, isa=isa).jacobian
        by_wi, by_wo = _derivatives.direction_vjp(material, wi, wo, g, model=model, cosine=cosine, isa=isa)
        expected = np.einsum("nc,nck->nk", g.astype(np.float64), jacobian.astype(np.float64))
        bound = 4 * np.finfo(np.float32).eps * np.einsum("nc,nck->nk", np.abs(g), np.abs(jacobian))
        assert np.all(np.abs(np.concatenate([by_wi, by_wo], -1) - expected) <= bound)


def test_transport_mode_reaches_the_direction_derivatives():
    """Importance = radiance η_t² for the solid's transmission alone, and so their derivatives."""
    rng = seeded_rng("bsdf2015-direction-mode")
    n = 2000
    material = pb.Material(**smooth_materials(rng, n, "disney2015"))
    wi, wo = off_the_tangent_plane(rng, n), off_the_tangent_plane(rng, n)
    radiance, importance = (pb.reference.eval_grad(material, wi, wo, wrt="wo", model="disney2015", mode=mode)
                            for mode in ("radiance", "importance"))
    reflected = wi[:, 2] * wo[:, 2] > 0
    np.testing.assert_array_equal(radiance.jacobian[reflected], importance.jacobian[reflected])
    through = ~reflected & (np.abs(radiance.jacobian).max(axis=(1, 2)) > 0)
    assert through.sum() > 0.1 * n
    assert np.all(np.abs(importance.jacobian[through] - radiance.jacobian[through]).max(axis=(1, 2)) > 0)
