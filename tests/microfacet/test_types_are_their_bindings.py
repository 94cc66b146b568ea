"""The distribution types of principled_brdf.microfacet: every method returns, bit for bit, what its
binding in ``_core.microfacet`` returns for the same rows (the methods add checks, broadcasting and
packing, never arithmetic); the types are immutable, compare by value, pickle, and name what they lack."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest

import principled_brdf as pb
from principled_brdf import _core
from principled_brdf import microfacet as mf

core = _core.microfacet
N = 257


def unit(rng, n):
    v = rng.normal(size=(n, 3))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    v[:4] = [[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [0.6, 0.8, 0.0]]
    return v


@pytest.fixture(scope="module")
def rows():
    rng = np.random.default_rng(2024)
    u1, u2 = rng.random(N), rng.random(N)
    u2[:3] = [0.0, 1.0, 1e-300]
    return dict(h=unit(rng, N), w=unit(rng, N), wi=unit(rng, N), wo=unit(rng, N), u1=u1, u2=u2,
                ax=rng.uniform(0.01, 1.0, N), ay=rng.uniform(0.01, 1.0, N), gamma=rng.uniform(0.1, 5.0, N))


def same(got, expected):
    assert got.dtype == np.float64 and got.shape == expected.shape
    assert np.array_equal(got, expected, equal_nan=True) and np.array_equal(np.signbit(got), np.signbit(expected))


# (type, constructor keywords, binding prefix, the shape argument of the bindings or None)
FAMILIES = [
    (mf.GGX, {}, "ggx", None),
    (mf.Beckmann, {}, "beckmann", None),
    (mf.BlinnPhong, {}, "blinn_phong", np.zeros(1)),
    (mf.StudentT, {"gamma": 2.7}, "student_t", np.array([2.7])),
    (mf.ExponentialPower, {"p": 0.6}, "exponential_power", np.array([0.6])),
]


@pytest.mark.parametrize("cls, keywords, prefix, shape", FAMILIES, ids=[f[2] for f in FAMILIES])
@pytest.mark.parametrize("isotropic", [True, False], ids=["isotropic", "anisotropic"])
def test_methods_are_their_bindings(rows, cls, keywords, prefix, shape, isotropic):
    ax, ay = rows["ax"], rows["ax"] if isotropic else rows["ay"]
    dist = cls(ax, None if isotropic else ay, **keywords)
    extra = () if shape is None else (shape,)
    h, w, wi, wo, u1, u2 = (rows[k] for k in ("h", "w", "wi", "wo", "u1", "u2"))

    def binding(name):
        return getattr(core, f"{prefix}_{name}")

    same(dist.d(h), binding("d")(h, ax, ay, *extra))
    same(dist.pdf(h), binding("pdf")(h, ax, ay, *extra))
    same(dist.sample(u1, u2), binding("sample")(u1, u2, ax, ay, *extra))
    same(dist.lambda_(w), binding("lambda")(w, ax, ay, *extra))
    same(dist.g1(w), binding("g1")(w, ax, ay, *extra))
    same(dist.g2(wi, wo), binding("g2_height_correlated")(wi, wo, ax, ay, *extra))
    same(dist.g2(wi, wo, correlated=True), binding("g2_height_correlated")(wi, wo, ax, ay, *extra))
    same(dist.g2(wi, wo, correlated=False), binding("g2_separable")(wi, wo, ax, ay, *extra))
    same(dist.pdf_visible(h, wo), binding("pdf_visible")(h, wo, ax, ay, *extra))
    if cls in (mf.GGX, mf.Beckmann):
        same(dist.sample_visible(wo, u1, u2), binding("sample_visible")(wo, u1, u2, ax, ay))
    else:
        assert not hasattr(dist, "sample_visible")
    # scalar parameters are one shared row of the binding
    scalar = cls(0.3, None if isotropic else 0.1, **keywords)
    a_y = np.array([0.3 if isotropic else 0.1])
    same(scalar.d(h), binding("d")(h, np.array([0.3]), a_y, *extra))
    same(scalar.g2(wi, wo, correlated=False), binding("g2_separable")(wi, wo, np.array([0.3]), a_y, *extra))


def test_ggx_visibility_is_its_binding(rows):
    ax, ay, wi, wo = rows["ax"], rows["ay"], rows["wi"], rows["wo"]
    ggx = mf.GGX(ax, ay)
    for form, approximation in enumerate((None, "karis", "hammon")):
        same(ggx.g2_over_4cos(wi, wo, approximation=approximation), core.ggx_g2_over_4cos(wi, wo, ax, ay, form))
    same(ggx.g2_over_4cos(wi, wo), core.ggx_g2_over_4cos(wi, wo, ax, ay, 0))


def test_beckmann_walter_is_its_binding(rows):
    ax, ay, h, w, wi, wo, u1, u2 = (rows[k] for k in ("ax", "ay", "h", "w", "wi", "wo", "u1", "u2"))
    walter = mf.Beckmann(ax, ay, approximation="walter")
    no_shape = np.zeros(1)
    same(walter.lambda_(w), core.beckmann_walter_lambda(w, ax, ay, no_shape))
    same(walter.g1(w), core.beckmann_walter_g1(w, ax, ay, no_shape))
    same(walter.g2(wi, wo), core.beckmann_walter_g2_height_correlated(wi, wo, ax, ay, no_shape))
    same(walter.g2(wi, wo, correlated=False), core.beckmann_walter_g2_separable(wi, wo, ax, ay, no_shape))
    # D, its sampler and the visible normals stay exact
    same(walter.d(h), core.beckmann_d(h, ax, ay))
    same(walter.pdf(h), core.beckmann_pdf(h, ax, ay))
    same(walter.sample(u1, u2), core.beckmann_sample(u1, u2, ax, ay))
    same(walter.pdf_visible(h, wo), core.beckmann_pdf_visible(h, wo, ax, ay))
    same(walter.sample_visible(wo, u1, u2), core.beckmann_sample_visible(wo, u1, u2, ax, ay))


@pytest.mark.parametrize("closed_forms", [True, False])
def test_gtr_methods_are_their_bindings(rows, closed_forms):
    alpha, gamma, h, u1, u2 = rows["ax"], rows["gamma"], rows["h"], rows["u1"], rows["u2"]
    gtr = mf.GTR(alpha, gamma, closed_forms=closed_forms)
    # d reads cos θh from the normalised half vector
    cos_theta_h = np.clip(h[:, 2] / np.sqrt(np.sum(h * h, axis=-1)), -1.0, 1.0)
    same(gtr.d(h), core.gtr_d(cos_theta_h, alpha, gamma, closed_forms))
    same(gtr.pdf(h), core.gtr_pdf(h, alpha, gamma, closed_forms))
    same(gtr.sample(u1, u2), core.gtr_sample(u1, u2, alpha, gamma, closed_forms))
    if closed_forms:
        same(mf.GTR(0.2, 1.5).d(h), core.gtr_d(cos_theta_h, np.array([0.2]), np.array([1.5]), True))


def test_hyp2f1_is_its_binding(rows):
    z = -5.0 * rows["u1"]
    same(mf.hyp2f1(0.5, 2.3, 1.5, z), core.hyp2f1(np.array([0.5]), np.array([2.3]), np.array([1.5]), z))


# --------------------------------------------------------------------------
# the types themselves

EVERY = [mf.GGX(0.3), mf.GGX(0.3, 0.1), mf.Beckmann(0.3, approximation="walter"), mf.BlinnPhong(0.5, 0.2),
         mf.StudentT(0.3, gamma=2.5), mf.ExponentialPower(0.3, 0.1, p=0.5), mf.GTR(0.2, 1.5),
         mf.GTR(0.2, 1.0, closed_forms=False), mf.GGX(np.array([0.1, 0.2]), 0.3)]


def test_repr_shows_the_parameters():
    assert [repr(d) for d in EVERY[:-1]] == [
        "GGX(alpha_x=0.3)", "GGX(alpha_x=0.3, alpha_y=0.1)", "Beckmann(alpha_x=0.3, approximation='walter')",
        "BlinnPhong(alpha_x=0.5, alpha_y=0.2)", "StudentT(alpha_x=0.3, gamma=2.5)",
        "ExponentialPower(alpha_x=0.3, alpha_y=0.1, p=0.5)", "GTR(alpha=0.2, gamma=1.5)",
        "GTR(alpha=0.2, gamma=1.0, closed_forms=False)"]
    assert repr(EVERY[-1]) == "GGX(alpha_x=array([0.1, 0.2]), alpha_y=0.3)"
    assert repr(mf.Beckmann(0.3)) == "Beckmann(alpha_x=0.3)"


@pytest.mark.parametrize("dist", EVERY, ids=repr)
def test_immutable_equal_by_value_and_picklable(dist):
    name = next(iter(dist._parameters()))
    with pytest.raises(AttributeError, match="immutable"):
        setattr(dist, name, 0.5)
    with pytest.raises(AttributeError, match="immutable"):
        delattr(dist, name)
    with pytest.raises(AttributeError):
        dist.__dict__  # noqa: B018  (slots: no instance dictionary)
    value = getattr(dist, name)
    assert isinstance(value, np.ndarray) and value.dtype == np.float64 and not value.flags.writeable
    rebuilt = eval(repr(dist), {"array": np.array, **{n: getattr(mf, n) for n in mf.__all__}})
    assert rebuilt == dist and hash(rebuilt) == hash(dist)
    for twin in (pickle.loads(pickle.dumps(dist)), copy.deepcopy(dist), copy.copy(dist)):
        assert twin == dist and type(twin) is type(dist)
    assert dist != mf.GGX(0.25) and dist != "GGX(alpha_x=0.3)"


def test_equality_is_of_the_parameters_in_effect():
    assert mf.GGX(0.3) == mf.GGX(0.3, 0.3) and hash(mf.GGX(0.3)) == hash(mf.GGX(0.3, 0.3))
    assert mf.Beckmann(0.3) == mf.Beckmann(0.3, approximation=None) != mf.Beckmann(0.3, approximation="walter")
    assert mf.GTR(0.2, 1.5) == mf.GTR(0.2, 1.5, closed_forms=True) != mf.GTR(0.2, 1.5, closed_forms=False)
    assert mf.StudentT(0.3, gamma=2) == mf.StudentT(0.3, 0.3, gamma=2.0) != mf.StudentT(0.3, gamma=3.0)
    assert mf.GGX(0.3) != mf.Beckmann(0.3) and mf.GGX([0.3]) != mf.GGX(0.3)  # the shapes differ


def test_parameters_are_copied_and_read_only():
    alpha = np.array([0.1, 0.2])
    ggx = mf.GGX(alpha)
    alpha[0] = 0.9
    assert ggx.alpha_x[0] == 0.1 and ggx.alpha_y is ggx.alpha_x
    with pytest.raises(ValueError):
        ggx.alpha_x[0] = 0.5
    assert float(mf.GGX(0.3, 0.1).alpha_y) == 0.1 and mf.GTR(0.2, 1.5).closed_forms is True
    assert mf.Beckmann(0.3).approximation is None and float(mf.StudentT(0.3, gamma=3).gamma) == 3.0
    assert float(mf.ExponentialPower(0.3, p=2).p) == 2.0 and float(mf.GTR(0.2, 1.5).alpha) == 0.2


@pytest.mark.parametrize("cls, keywords, absent", [
    (mf.GTR, {"alpha": 0.2, "gamma": 1.5}, ["lambda_", "g1", "g2", "pdf_visible", "sample_visible", "g2_over_4cos"]),
    (mf.BlinnPhong, {"alpha_x": 0.3}, ["sample_visible", "g2_over_4cos"]),
    (mf.StudentT, {"alpha_x": 0.3, "gamma": 2.0}, ["sample_visible", "g2_over_4cos"]),
    (mf.ExponentialPower, {"alpha_x": 0.3, "p": 1.0}, ["sample_visible", "g2_over_4cos"]),
    (mf.Beckmann, {"alpha_x": 0.3}, ["g2_over_4cos"]),
    (mf.GGX, {"alpha_x": 0.3}, []),
])
def test_absent_methods_raise_attribute_error_with_the_reason(cls, keywords, absent):
    dist = cls(**keywords)
    methods = ["d", "pdf", "sample", "lambda_", "g1", "g2", "pdf_visible", "sample_visible", "g2_over_4cos"]
    for method in methods:
        assert hasattr(dist, method) == (method not in absent), method
        assert hasattr(cls, method) == (method not in absent), method
    for method in absent:
        with pytest.raises(AttributeError, match=f"{cls.__name__} has no {method}\\(\\): .*"):
            getattr(dist, method)
    with pytest.raises(AttributeError, match="has no attribute 'nonsense'"):
        dist.nonsense  # noqa: B018
    with pytest.raises(AttributeError, match="shape-invariant"):
        mf.GTR(0.2, 1.5).lambda_  # noqa: B018


@pytest.mark.parametrize("call, error, pattern", [
    (lambda: mf.GGX(0.3).g2([0, 0, 1], [0, 0, 1], correlated="yes"), TypeError, "correlated"),
    (lambda: mf.GTR(0.3, 1.0, closed_forms=1), TypeError, "closed_forms"),
    (lambda: mf.Beckmann(0.3, approximation="hammon"), ValueError, "approximation"),
    (lambda: mf.StudentT(0.3), TypeError, "gamma"),
    (lambda: mf.ExponentialPower(0.3), TypeError, "p"),
    (lambda: mf.GTR(0.3, [1.0, 2.0]).d(np.zeros((3, 3)) + [0, 0, 1]), ValueError, "broadcast"),
])
def test_option_checks(call, error, pattern):
    with pytest.raises(error, match=pattern):
        call()


def test_parameters_broadcast_with_the_directions():
    h = mf.GGX(0.3).sample(np.full((2, 1), 0.3), np.array([0.1, 0.5, 0.9]))
    assert h.shape == (2, 3, 3)
    alphas = np.array([[0.1], [0.2], [0.4], [0.8]])
    assert mf.StudentT(alphas, gamma=np.array([2.0, 3.0, 4.0])).d(h[0]).shape == (4, 3)
    assert mf.GTR(alphas, 1.5).pdf(h[0]).shape == (4, 3)
    assert pb.microfacet.GGX(alphas).g2(h[0], h[1]).shape == (4, 3)
