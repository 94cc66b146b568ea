"""pb.fit: least squares with the analytic Jacobian (docs/fitting.md)."""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb
from conftest import random_direction_pairs, seeded_rng

TRUTH = dict(base_color=(0.7, 0.3, 0.1), metallic=0.2, subsurface=0.3, specular=0.6, specular_tint=0.3, roughness=0.35,
             anisotropic=0.2, sheen=0.4, sheen_tint=0.6, clearcoat=0.3, clearcoat_gloss=0.7)


def pairs(n, key="fit"):
    return random_direction_pairs(seeded_rng(key), n, min_cos=0.05)


@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_fit_reproduces_measurements_of_the_model(precision):
    """Every parameter fitted from the default start: f is matched to the precision's
    rounding (the color parameters are not all identifiable from f: Cspec0 spans only
    base_color and grey, so the fitted f is checked, and the identifiable ones below)."""
    wi, wo = pairs(6000)
    truth = pb.Material(**TRUTH)
    measured = pb.reference.eval(truth, wi, wo)
    result = pb.fit(wi, wo, measured, precision=precision)
    assert result.success
    fitted = pb.reference.eval(result.material, wi, wo)
    tolerance = 1e-4 if precision == "float32" else 1e-8
    np.testing.assert_allclose(fitted, measured, rtol=tolerance, atol=tolerance * measured.max() * 1e-3)
    for name in ("roughness", "anisotropic", "clearcoat", "clearcoat_gloss", "subsurface"):
        assert getattr(result.material, name) == pytest.approx(TRUTH[name], abs=10 * tolerance), name


def test_fit_a_subset_from_a_far_start_with_missing_samples_and_weights():
    wi, wo = pairs(4000, "fit-subset")
    truth = pb.Material(**TRUTH)
    measured = pb.reference.eval(truth, wi, wo)
    measured[::7] = np.nan  # missing cells
    start = dict(TRUTH, roughness=0.8, clearcoat_gloss=0.1, base_color=(0.3, 0.3, 0.3))
    result = pb.fit(wi, wo, measured, init=start, fit=["roughness", "clearcoat_gloss", "base_color"],
                    weights=np.linspace(0.5, 2.0, len(wi)))
    assert result.success and result.names == ("base_color_r", "base_color_g", "base_color_b", "roughness",
                                               "clearcoat_gloss")
    np.testing.assert_allclose(result.slots[[0, 1, 2, 7, 12]], [0.7, 0.3, 0.1, 0.35, 0.7], atol=1e-4)
    assert result.material.metallic == TRUTH["metallic"]  # held at init
    assert np.isnan(result.residuals[::7]).all() and np.isfinite(result.residuals[1::7]).all()
    assert "converged" in result.summary() and "roughness=0.35" in str(result)


def test_log_and_relative_losses_fit_a_glossy_measurement():
    """Specular peaks span decades of f: the log loss finds the peak from far away (the
    relative one, which weighs the darkest samples most, from nearby: from 0.5 it
    settles in a local minimum near 0.38)."""
    wi, wo = pairs(4000, "fit-log")
    truth = pb.Material(base_color=(0.5, 0.2, 0.1), roughness=0.08, specular=0.5)
    measured = pb.reference.eval(truth, wi, wo)
    result = pb.fit(wi, wo, measured, init=dict(roughness=0.5), fit=["roughness", "base_color"], loss="log")
    np.testing.assert_allclose(result.slots[[0, 1, 2, 7]], [0.5, 0.2, 0.1, 0.08], atol=1e-4)
    relative = pb.fit(wi, wo, measured, init=dict(base_color=(0.5, 0.2, 0.1), roughness=0.15), fit=["roughness"],
                      loss="relative")
    assert relative.material.roughness == pytest.approx(0.08, abs=1e-4)


def test_many_materials_in_one_call():
    wi, wo = pairs(1500, "fit-batch")
    roughness = np.array([0.2, 0.5, 0.8])
    texels = pb.Material(base_color=np.array([[0.8, 0.2, 0.2], [0.2, 0.8, 0.2], [0.2, 0.2, 0.8]]), roughness=roughness)
    measured = np.stack([pb.reference.eval(texels.replace(base_color=texels.base_color[i], roughness=roughness[i]), wi, wo)
                         for i in range(3)])
    result = pb.fit(wi, wo, measured, fit=["base_color", "roughness"])
    assert result.slots.shape == (3, 13) and result.cost.shape == (3,) and result.residuals.shape == (3, 1500, 3)
    assert result.material.roughness.shape == (3,) and result.success.all()
    np.testing.assert_allclose(result.material.roughness, roughness, atol=1e-4)
    np.testing.assert_allclose(result.material.base_color, texels.base_color, atol=1e-4)
    assert "problem 2" in result.summary()


@pytest.mark.parametrize("call, error, match", [
    (lambda wi, wo, m: pb.fit(wi, wo, m[:, :2]), ValueError, r"measured: expected \(N, 3\)"),
    (lambda wi, wo, m: pb.fit(wi, wo, -m), ValueError, "measured: values must be finite and >= 0"),
    (lambda wi, wo, m: pb.fit(wi, wo, m, loss="l1"), ValueError, "loss: expected one of scaled_log, log, relative, linear"),
    (lambda wi, wo, m: pb.fit(wi, wo, m, fit=["shininess"]), ValueError, "fit: unknown parameter 'shininess'"),
    (lambda wi, wo, m: pb.fit(wi, wo, m, bounds={"roughness": (0.5, 0.1)}), ValueError, r"bounds\['roughness'\]"),
    (lambda wi, wo, m: pb.fit(wi[:5], wo, m), ValueError, "wi, wo: expected"),
    (lambda wi, wo, m: pb.fit(wi, wo, m, init=3), TypeError, "init: expected a uniform"),
    (lambda wi, wo, m: pb.fit(wi, wo, m, precision="half"), ValueError, "precision"),
])
def test_bad_arguments(call, error, match):
    wi, wo = pairs(50, "fit-bad")
    with pytest.raises(error, match=match):
        call(wi, wo, pb.reference.eval(pb.Material(), wi, wo))
