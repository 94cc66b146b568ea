"""The independent numpy transcription of the 2015 BSDF (numpy_model_2015.py)
holds the properties the equations promise (docs/model-2015.md): the diffuse
split reproduces the 2012 diffuse, generalized reciprocity across the
interface, plain reciprocity of the thin sheet, no transmission without
spec_trans, the energy bound and the smooth-interface limit."""

from __future__ import annotations

import numpy as np
import pytest

import numpy_model
import numpy_model_2015 as m15

RNG = np.random.default_rng(2015)


def sphere(n, rng=RNG):
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def random_params(n, rng=RNG, **fixed):
    unit = lambda: rng.random(n)  # noqa: E731
    p = {"base_color": rng.random((n, 3)), "metallic": unit(), "specular": 2.0 * unit(), "specular_tint": unit(),
         "roughness": 0.05 + 0.95 * unit(), "anisotropic": unit(), "sheen": unit(), "sheen_tint": unit(),
         "clearcoat": unit(), "clearcoat_gloss": unit(), "spec_trans": unit(), "flatness": unit(),
         "diff_trans": 2.0 * unit()}
    p.update({k: np.broadcast_to(np.asarray(v, float), np.shape(p[k])) for k, v in fixed.items()})
    return p


def test_the_diffuse_split_is_the_2012_diffuse():
    """f_L + f_R = Fd of Burley 2012 (flatness 0, no transmission, no metal)."""
    n = 4000
    wi, wo = sphere(n), sphere(n)
    wi[:, 2], wo[:, 2] = np.abs(wi[:, 2]), np.abs(wo[:, 2])
    p = random_params(n, metallic=0.0, spec_trans=0.0, flatness=0.0)
    ours = m15.eval_lobes(p, wi, wo).diffuse
    theirs = numpy_model.eval_lobes({k: p[k] for k in numpy_model.DEFAULTS if k in p} | {"subsurface": 0.0},
                                    wi, wo).diffuse
    np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=1e-300)


def index_of_side(w, eta):
    return np.where(w[:, 2] > 0, 1.0, eta)


def test_generalized_reciprocity():
    """f(wi, wo) / n(wo)² = f(wo, wi) / n(wi)² (radiance), over the whole sphere."""
    n = 20000
    wi, wo = sphere(n), sphere(n)
    p = random_params(n)
    eta = m15.eta_of_specular(p["specular"])
    forward = m15.eval(p, wi, wo) / index_of_side(wo, eta)[:, None] ** 2
    backward = m15.eval(p, wo, wi) / index_of_side(wi, eta)[:, None] ** 2
    assert np.isfinite(forward).all() and (forward >= 0).all()
    np.testing.assert_allclose(forward, backward, rtol=1e-6, atol=1e-300)  # 1 - F cancels near total reflection
    transmitted = (wi[:, 2] * wo[:, 2] < 0) & (forward.sum(axis=1) > 0)
    assert transmitted.sum() > n // 10


def test_the_thin_sheet_is_reciprocal_and_two_sided():
    n = 20000
    wi, wo = sphere(n), sphere(n)
    p = random_params(n)
    f = m15.eval(p, wi, wo, model="disney2015_thin")
    np.testing.assert_allclose(f, m15.eval(p, wo, wi, model="disney2015_thin"), rtol=1e-10, atol=1e-300)
    mirror = np.array([1.0, 1.0, -1.0])
    np.testing.assert_allclose(f, m15.eval(p, wi * mirror, wo * mirror, model="disney2015_thin"), rtol=1e-14)


def test_the_thin_diffuse_splits_reflected_and_transmitted_as_one_minus_dt_to_dt():
    n = 2000
    wo = sphere(n)
    wo[:, 2] = np.abs(wo[:, 2])
    wi = sphere(n)
    wi[:, 2] = np.abs(wi[:, 2])
    p = random_params(n, sheen=0.0, flatness=0.0, roughness=0.5)
    lobes = m15.eval_lobes(p, wi, wo, model="disney2015_thin")
    below = m15.eval_lobes(p, wi * [1, 1, -1], wo, model="disney2015_thin")
    dt = p["diff_trans"] / 2.0
    # the transmitted diffuse is Lambertian, c/π (1-m)(1-st) dt; the reflected one's Lambert part at FL = FV = 0
    w_d = (1 - p["metallic"]) * (1 - p["spec_trans"])
    np.testing.assert_allclose(below.diffuse_transmission, (w_d * dt / np.pi)[:, None] * p["base_color"], rtol=1e-13)
    normal = wi.copy()
    normal[:] = [0, 0, 1]
    at_normal = m15.eval_lobes(p, normal, normal, model="disney2015_thin").diffuse
    # at the normal FL = FV = 0, cos θd = 1: Lambert part 1, retro-reflection 0
    np.testing.assert_allclose(at_normal, (w_d * (1 - dt) / np.pi)[:, None] * p["base_color"], rtol=1e-13)
    assert (lobes.diffuse_transmission == 0).all()


@pytest.mark.parametrize("model", ["disney2015", "disney2015_thin"])
def test_no_spec_trans_no_transmission(model):
    n = 5000
    wi, wo = sphere(n), sphere(n)
    p = random_params(n, spec_trans=0.0)
    lobes = m15.eval_lobes(p, wi, wo, model=model)
    assert (lobes.transmission == 0).all()
    if model == "disney2015":
        assert (m15.eval(p, wi, wo)[wo[:, 2] < 0] == 0).all()  # inside, only the interface exists


def sphere_quadrature(views, f_of, n_cos=800, n_phi=400):
    """∫ f(wi, wo) |cos θl| dωi over the whole sphere, per hemisphere by the midpoint rule in
    (t, φ) with cos θ = 1 - t², which is dense near the poles, where refraction concentrates."""
    t = (np.arange(n_cos) + 0.5) / n_cos
    phi = (np.arange(n_phi) + 0.5) / n_phi * 2 * np.pi
    t_, f_ = np.meshgrid(t, phi, indexing="ij")
    c = 1.0 - t_ * t_
    s = np.sqrt(1 - c * c)
    upper = np.stack([s * np.cos(f_), s * np.sin(f_), c], axis=-1).reshape(-1, 3)
    weight = ((2.0 * t_) * (1.0 / n_cos) * (2 * np.pi / n_phi)).reshape(-1, 1)  # d cos θ = 2t dt
    totals = []
    for wo in views:
        reflect = transmit = 0.0
        for side, directions in ((1, upper), (-1, upper * [1, 1, -1])):
            value = f_of(directions, np.broadcast_to(wo, directions.shape)) * np.abs(directions[:, 2:3])
            part = (value * weight).sum(axis=0)
            if side == np.sign(wo[2]):
                reflect = part
            else:
                transmit = part
        totals.append((reflect, transmit))
    return totals


@pytest.mark.parametrize("roughness, specular", [(0.3, 0.1), (0.5, 0.5), (1.0, 1.5)])
def test_a_white_dielectric_does_not_create_energy(roughness, specular):
    """Importance mode, c = 1, st = 1, m = 0: reflectance + transmittance <= 1 + 2e-3 from
    either side (rough enough for the grid to resolve the refracted lobe)."""
    p = {"base_color": (1.0, 1.0, 1.0), "spec_trans": 1.0, "roughness": roughness, "specular": specular}
    views = [np.array([np.sin(t), 0.0, side * np.cos(t)]) for t in np.radians([0, 45, 75]) for side in (1, -1)]
    for reflect, transmit in sphere_quadrature(views, lambda a, b: m15.eval(p, a, b, mode="importance")):
        total = reflect + transmit
        assert (total <= 1 + 2e-3).all(), total
        assert (total >= 0.2).all(), total  # single scattering loses some, not all


@pytest.mark.parametrize("theta", [0.0, 30.0, 60.0])
@pytest.mark.parametrize("side", [1, -1])
def test_a_smooth_interface_splits_by_fresnel(theta, side):
    """r -> 0: reflectance F_D(cos θv; η) and transmittance its complement (importance mode),
    by Monte Carlo over the visible normals of the nearly smooth interface."""
    specular = 0.5
    eta = m15.eta_of_specular(specular)
    eta_view = eta if side > 0 else 1.0 / eta  # far side over the viewer's
    t = np.radians(theta)
    wo = np.array([np.sin(t), 0.0, side * np.cos(t)])
    cos_v = abs(wo[2])
    expected_reflect = m15.fresnel_dielectric(np.array([cos_v]), eta_view)[0]
    # nearly smooth: the lobes concentrate at the mirror and the refracted directions;
    # integrate over a small cap around each with a fine polar grid
    p = {"base_color": (1.0, 1.0, 1.0), "spec_trans": 1.0, "roughness": 0.02, "specular": specular}
    mirror = wo * [-1, -1, 1]
    s2 = (1 - cos_v**2) / eta_view**2
    refracted = None
    if s2 < 1:
        refracted = np.array([-wo[0] / eta_view, -wo[1] / eta_view, -np.sign(wo[2]) * np.sqrt(1 - s2)])
    reflect = cap_integral(p, mirror, wo)
    transmit = cap_integral(p, refracted, wo) if refracted is not None else 0.0
    assert abs(reflect - expected_reflect) <= 3e-3, (reflect, expected_reflect)
    assert abs(transmit - (1 - expected_reflect)) <= 3e-3, (transmit, 1 - expected_reflect)


def cap_integral(p, axis, wo, radius=0.15, n_r=400, n_phi=256):
    """∫ f |cos θl| dωi over a cap of the given angular radius around ``axis``."""
    axis = axis / np.linalg.norm(axis)
    helper = np.array([1.0, 0, 0]) if abs(axis[0]) < 0.9 else np.array([0, 1.0, 0])
    e1 = np.cross(axis, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    # rings in cos of the angle from the axis, denser near it
    u = ((np.arange(n_r) + 0.5) / n_r) ** 2
    angle = u * radius
    d_angle = 2 * ((np.arange(n_r) + 0.5) / n_r) / n_r * radius
    phi = (np.arange(n_phi) + 0.5) / n_phi * 2 * np.pi
    a, f_ = np.meshgrid(angle, phi, indexing="ij")
    da = np.broadcast_to(d_angle[:, None], a.shape)
    directions = (np.cos(a)[..., None] * axis + np.sin(a)[..., None] * (np.cos(f_)[..., None] * e1
                                                                          + np.sin(f_)[..., None] * e2))
    directions = directions.reshape(-1, 3)
    area = (np.sin(a) * da * (2 * np.pi / n_phi)).reshape(-1)
    value = m15.eval(p, directions, np.broadcast_to(wo, directions.shape), mode="importance")
    return float(np.sum(value[:, 0] * np.abs(directions[:, 2]) * area))


def test_the_thin_sheet_with_white_color_does_not_create_energy():
    p = {"base_color": (1.0, 1.0, 1.0), "spec_trans": 1.0, "roughness": 0.5}
    views = [np.array([np.sin(t), 0.0, np.cos(t)]) for t in np.radians([0, 45, 75])]
    for reflect, transmit in sphere_quadrature(views, lambda a, b: m15.eval(p, a, b, model="disney2015_thin")):
        assert (reflect + transmit <= 1 + 2e-3).all(), reflect + transmit
