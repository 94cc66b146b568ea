"""The whole-sphere albedo quadrature (whole_sphere_albedo.py) that the white furnace of
the 2015 models is measured with: it agrees with pb.albedo's Monte Carlo estimate within
its standard error, with itself at twice the nodes within 2e-4, and splits the light
into the reflected and the transmitted as pb.albedo does.
"""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb
import whole_sphere_albedo

CASES = [  # roughness, index, cos θo (negative: from inside), mode
    (0.3, 1.5, 0.5, "importance"),
    (1.0, 1.5, 0.1, "importance"),
    (1.0, 1.5, -0.9, "importance"),
    (0.6, 4.0, -0.3, "importance"),
    (0.8, 1.05, 0.1, "importance"),
    (0.3, 2.4, -0.9, "radiance"),
]


def _white_glass(roughness, eta):
    return pb.Material(base_color=(1.0, 1.0, 1.0), spec_trans=1.0, roughness=roughness, ior=eta)


@pytest.mark.parametrize("roughness, eta, mu, mode", CASES)
def test_the_quadrature_agrees_with_monte_carlo(roughness, eta, mu, mode):
    material = _white_glass(roughness, eta)
    wo = np.array([np.sqrt(1.0 - mu * mu), 0.0, mu])
    reflected, transmitted = whole_sphere_albedo.albedo(
        lambda wi, v: pb.reference.eval(material, wi, v, model="disney2015", mode=mode), wo, eta)
    estimate = pb.albedo(material, mu, samples=1 << 21, model="disney2015", mode=mode)
    tolerance = 5.0 * float(np.max(estimate.total_error)) + 2e-4
    np.testing.assert_allclose(reflected + transmitted, estimate.total, atol=tolerance)
    np.testing.assert_allclose(reflected, estimate.reflectance, atol=tolerance)
    np.testing.assert_allclose(transmitted, estimate.transmittance, atol=tolerance)


def test_the_quadrature_has_converged(monkeypatch):
    """Twice the nodes in both angles move it by less than 2e-4 (rough glass from inside,
    where the critical angle cuts through the lobe)."""
    material = _white_glass(1.0, 1.5)
    f = lambda wi, v: pb.reference.eval(material, wi, v, model="disney2015", mode="importance")  # noqa: E731
    wo = np.array([np.sqrt(1.0 - 0.81), 0.0, -0.9])
    coarse = sum(whole_sphere_albedo.albedo(f, wo, 1.5))
    monkeypatch.setattr(whole_sphere_albedo, "_PER_PANEL", 2 * whole_sphere_albedo._PER_PANEL)
    monkeypatch.setattr(whole_sphere_albedo, "_AZIMUTHS", 2 * whole_sphere_albedo._AZIMUTHS)
    h, weights = whole_sphere_albedo._half_vectors()
    monkeypatch.setattr(whole_sphere_albedo, "_H", h)
    monkeypatch.setattr(whole_sphere_albedo, "_WEIGHTS", weights)
    fine = sum(whole_sphere_albedo.albedo(f, wo, 1.5))
    np.testing.assert_allclose(coarse, fine, atol=2e-4)
