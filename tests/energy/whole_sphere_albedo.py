"""The directional albedo of a BSDF over the whole sphere by deterministic quadrature,
E(wo) = ∫ f(wi, wo) |cos θi| dωi, for the furnace tests of the 2015 models.

Both halves are integrated over the microfacet normal h, on the hemisphere of wo's
side, where a GGX lobe is a smooth bell about the normal whatever wo:

- reflection, wi = 2 (wo·h) h - wo: dωi = 4 |wo·h| dωh (Walter et al. 2007 eq. 14);
- transmission, wi = the refraction of wo at h (none under total internal
  reflection): dωi = (η_o (wo·h) + η_i (wi·h))² / (η_i² |wi·h|) dωh, η_o the index
  on wo's side, η_i on wi's (Walter et al. 2007 eq. 16-17).

θh = (π/2) t² with Gauss-Legendre panels in t that crowd towards the normal, φh
uniform (periodic: spectral). The integrand jumps where wi crosses the horizon and
at the critical angle; panels are fine enough there for about 1e-4 (checked against
Monte Carlo in test_whole_sphere_albedo_quadrature.py).
"""

from __future__ import annotations

import numpy as np

_EDGES = (0.0, 0.02, 0.05, 0.1, 0.2, 0.35, 0.55, 0.75, 1.0)
_PER_PANEL = 48
_AZIMUTHS = 512


def _half_vectors():
    x, w = np.polynomial.legendre.leggauss(_PER_PANEL)
    t = np.concatenate([a + (b - a) * (x + 1) / 2 for a, b in zip(_EDGES[:-1], _EDGES[1:])])
    wt = np.concatenate([(b - a) / 2 * w for a, b in zip(_EDGES[:-1], _EDGES[1:])])
    theta = 0.5 * np.pi * t**2
    phi = (np.arange(_AZIMUTHS) + 0.5) * (2.0 * np.pi / _AZIMUTHS)
    h = np.stack([np.outer(np.sin(theta), np.cos(phi)), np.outer(np.sin(theta), np.sin(phi)),
                  np.outer(np.cos(theta), np.ones_like(phi))], axis=-1).reshape(-1, 3)
    weights = np.outer(np.sin(theta) * np.pi * t * wt, np.full(phi.shape, 2.0 * np.pi / _AZIMUTHS)).reshape(-1)
    return h, weights


_H, _WEIGHTS = _half_vectors()


def albedo(f, wo, eta):
    """(reflected, transmitted) parts of E(wo), each (3,): ``f(wi, wo)`` the BSDF (RGB, 1/sr) of
    unit directions (n, 3), ``wo`` a unit direction (either side), ``eta`` the interior's index
    over the exterior's (wo below the surface: inside)."""
    wo = np.asarray(wo, dtype=np.float64)
    side = 1.0 if wo[2] >= 0.0 else -1.0
    h = _H * np.array([1.0, 1.0, side])
    cos_o = h @ wo
    keep = cos_o > 0.0
    h, weights, cos_o = h[keep], _WEIGHTS[keep], cos_o[keep]

    reflected_wi = 2.0 * cos_o[:, None] * h - wo
    above = reflected_wi[:, 2] * side > 0.0
    values = np.nan_to_num(f(reflected_wi[above], np.broadcast_to(wo, reflected_wi[above].shape)))
    jacobian = 4.0 * cos_o[above]
    reflected = (values * (np.abs(reflected_wi[above, 2]) * jacobian * weights[above])[:, None]).sum(axis=0)

    eta_o, eta_i = (1.0, eta) if side > 0 else (eta, 1.0)
    ratio = eta_o / eta_i
    sin2_t = ratio**2 * (1.0 - cos_o**2)
    refracts = sin2_t < 1.0
    cos_t = np.sqrt(np.maximum(1.0 - sin2_t, 0.0))
    transmitted_wi = (ratio * cos_o - cos_t)[:, None] * h - ratio * wo  # cos(wi, h) = -cos_t
    crossed = refracts & (transmitted_wi[:, 2] * side < 0.0)
    wi = transmitted_wi[crossed]
    wi /= np.linalg.norm(wi, axis=-1, keepdims=True)
    cos_i = np.sum(wi * h[crossed], axis=-1)
    jacobian = (eta_o * cos_o[crossed] + eta_i * cos_i) ** 2 / (eta_i**2 * np.abs(cos_i))
    values = np.nan_to_num(f(wi, np.broadcast_to(wo, wi.shape)))
    transmitted = (values * (np.abs(wi[:, 2]) * jacobian * weights[crossed])[:, None]).sum(axis=0)
    return reflected, transmitted
