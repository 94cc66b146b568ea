"""pb.fit holds what the data cannot determine (docs/fitting.md): pairs whose
half vectors lie in one plane through the normal (a MERL table's) do not
determine anisotropy, so the default fit keeps it at its start and says so."""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb

pytest.importorskip("scipy")


def test_merl_pairs_at_an_azimuth():
    wi0, wo0 = pb.measured.merl_pairs()
    wi, wo = pb.measured.merl_pairs(phi_h=0.7)
    h0, h = wi0 + wo0, wi + wo
    phi = np.arctan2(h[:, 1], h[:, 0])
    off = np.hypot(h[:, 0], h[:, 1]) > 1e-6
    np.testing.assert_allclose(np.mod(phi[off] - 0.7 + np.pi / 2, np.pi) - np.pi / 2, 0.0, atol=1e-9)
    # the same (θh, θd, φd): the same dot products
    np.testing.assert_allclose(np.sum(wi * wo, axis=1), np.sum(wi0 * wo0, axis=1), atol=1e-12)
    np.testing.assert_allclose(wi[:, 2], wi0[:, 2], atol=1e-12)
    with pytest.raises(ValueError, match=r"phi_h: expected one angle"):
        pb.measured.merl_pairs(phi_h=[0.0, 1.0])
    with pytest.raises(ValueError, match=r"phi_h: nan"):
        pb.measured.merl_pairs(phi_h=np.nan)


def pairs_in_a_plane(n, rng):
    """Random pairs whose half vectors lie in the x-z plane."""
    theta_h = rng.uniform(0, 1.2, n)
    phi_h = np.where(rng.random(n) < 0.5, 0.0, np.pi)
    theta_d = rng.uniform(0, 1.2, n)
    phi_d = rng.uniform(0, 2 * np.pi, n)
    wi, wo = pb.frames.half_diff_to_wiwo(theta_h, phi_h, theta_d, phi_d)
    keep = (wi[:, 2] > 0.05) & (wo[:, 2] > 0.05)
    return wi[keep], wo[keep]


def test_the_default_fit_holds_anisotropy_the_pairs_cannot_determine():
    rng = np.random.default_rng(5)
    truth = pb.Material(base_color=(0.9, 0.6, 0.3), metallic=1.0, roughness=0.3)
    wi, wo = pairs_in_a_plane(400, rng)
    result = pb.fit(wi, wo, pb.reference.eval(truth, wi, wo), fit=None, max_iterations=60)
    assert "anisotropic" not in result.names
    assert float(result.material.anisotropic) == 0.0
    assert "anisotropic held" in result.summary()
    # asked for, it is fitted; pairs spread in azimuth determine it and the default fits it
    asked = pb.fit(wi, wo, pb.reference.eval(truth, wi, wo), fit=["roughness", "anisotropic"], max_iterations=20)
    assert "anisotropic" in asked.names and not asked.notes
    spread_wi, spread_wo = wi @ np.array([[0.6, 0.8, 0], [-0.8, 0.6, 0], [0, 0, 1.0]]).T, wo
    spread_wi = np.concatenate([wi, spread_wi])
    spread_wo = np.concatenate([wo, wo @ np.array([[0.6, 0.8, 0], [-0.8, 0.6, 0], [0, 0, 1.0]]).T])
    spread = pb.fit(spread_wi, spread_wo, pb.reference.eval(truth, spread_wi, spread_wo), max_iterations=5)
    assert "anisotropic" in spread.names and not any("anisotropic held" in note for note in spread.notes)


def test_parameters_without_effect_go_back_to_their_start():
    """A metal's diffuse, subsurface and sheen lobes are weighted by 1 - metallic = 0: whatever
    those parameters reached on the way, the fit sets them back to the start and says so; f
    stays the same to float32's resolution, and the cost and residuals are those of the
    material returned."""
    rng = np.random.default_rng(8)
    truth = pb.Material(base_color=(0.95, 0.64, 0.54), metallic=1.0, roughness=0.35)
    wi, wo = pairs_in_a_plane(3000, rng)
    start = dict(subsurface=0.7, sheen=0.6, sheen_tint=0.2, specular_tint=0.4)  # far from the start put back
    measured = pb.reference.eval(truth, wi, wo)
    result = pb.fit(wi, wo, measured, init=start, loss="linear", cosine=False)
    assert float(result.material.metallic) == pytest.approx(1.0, abs=1e-6)
    for name, value in start.items():  # the start, exactly: the fit moved them, then put them back
        assert float(getattr(result.material, name)) == pytest.approx(value, abs=1e-12), name
    assert any("set back to the start" in note for note in result.notes)
    # f, residuals and cost as the fitted material gives them (the linear loss: f - m)
    f = pb.eval(result.material, wi.astype(np.float32), wo.astype(np.float32)).astype(np.float64)
    np.testing.assert_array_equal(result.residuals, f - measured)
    np.testing.assert_allclose(f, measured, rtol=1e-4, atol=1e-6 * measured.max())
    assert float(result.cost) == pytest.approx(0.5 * np.sum((f - measured) ** 2), rel=1e-12)
