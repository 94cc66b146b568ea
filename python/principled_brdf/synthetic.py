"""Measurements from other models: microfacet BRDFs that are not the principled one (docs/fitting.md).

A fit is only checked when the answer is known. These are the materials a
measurement campaign meets, written with :mod:`principled_brdf.microfacet`'s
distributions, Smith terms and exact Fresnel factors in float64, as callables
``f(wi, wo) -> (..., 3)`` in 1/sr that :func:`principled_brdf.measured.save_merl`
writes as a MERL table and :mod:`principled_brdf.plot` draws:

    f(wi, wo) = s · D(h) G2(wi, wo) F(wi·h) / (4 cos θl cos θv) + ρd / π

(Walter et al. 2007 eq. 20 for the specular term, height-correlated Smith G2),
with F the conductor's (complex index ``eta + i k``) or the dielectric's
(``k = 0``) unpolarised reflectance, ``s`` the share of the surface the
microfacets cover and ``ρd`` a Lambertian albedo (a plastic's body, or dust).
Like a gonioreflectometer, they have no data where a direction lies at or below
the horizon: NaN there (``save_merl`` writes it as the format's "no data").

    >>> import principled_brdf as pb
    >>> gold = pb.synthetic.conductor("gold", alpha=0.2)            # Beckmann by default
    >>> gold.f0.round(3)                                            # F at normal incidence, RGB
    array([0.945, 0.777, 0.373])
    >>> pb.measured.save_merl(path, gold)                           # doctest: +SKIP
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from . import _validate
from . import microfacet as _microfacet

if TYPE_CHECKING:
    from ._typing import Float64Array, RealArrayLike

__all__ = ["MicrofacetSurface", "CONDUCTORS", "conductor", "plastic", "dusty_dielectric"]

#: Complex indices of refraction ``(eta, k)`` at three wavelengths standing for R, G, B
#: (about 650, 550 and 450 nm).
CONDUCTORS: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    "gold": ((0.18, 0.42, 1.37), (3.42, 2.35, 1.77)),
    "copper": ((0.200438, 0.924033, 1.10221), (3.91295, 2.45285, 2.14219)),
    "aluminium": ((1.65746, 0.880369, 0.521229), (9.22387, 6.26952, 4.837)),
}
_DISTRIBUTIONS = {"beckmann": _microfacet.Beckmann, "ggx": _microfacet.GGX}


def _rgb(name: str, value: RealArrayLike, lower: float, *, open_lower: bool = False) -> Float64Array:
    """One value or an RGB triple, each finite and >= lower (> lower when open_lower)."""
    array = np.array(np.broadcast_to(_validate.as_real_array(name, value), (3,)), dtype=np.float64)
    _validate.require_finite(name, array)
    bad = array <= lower if open_lower else array < lower
    if bad.any():
        relation = ">" if open_lower else ">="
        raise ValueError(f"{name}[{int(np.argmax(bad))}]: {float(array[bad][0])!r} is not {relation} {lower:g}")
    array.setflags(write=False)
    return array


@dataclass(frozen=True, eq=False)
class MicrofacetSurface:
    """``f = specular_weight · D G2 F / (4 cos θl cos θv) + diffuse / π``, RGB in 1/sr, float64.

    ``distribution``: a :class:`~principled_brdf.microfacet.GGX` or
    :class:`~principled_brdf.microfacet.Beckmann` (any distribution with ``d``
    and ``g2``); ``eta``, ``k``: the index of refraction ``eta + i k`` of the
    surface, one value or RGB (``k = 0``: a dielectric, exact Fresnel);
    ``diffuse``: a Lambertian albedo, one value or RGB, in [0, 1];
    ``specular_weight``: in [0, 1], the share of the specular layer (below 1
    for a surface partly covered by dust). Calling it gives f ``(..., 3)`` at
    unit directions ``(..., 3)``, NaN where either is at or below the horizon.
    """

    distribution: _microfacet.GGX | _microfacet.Beckmann
    eta: RealArrayLike
    k: RealArrayLike = 0.0
    diffuse: RealArrayLike = 0.0
    specular_weight: float = 1.0

    def __post_init__(self) -> None:
        if not (hasattr(self.distribution, "d") and hasattr(self.distribution, "g2")):
            raise TypeError("distribution: expected a pb.microfacet distribution with d and g2 (GGX, Beckmann), "
                            f"got {type(self.distribution).__name__}")
        object.__setattr__(self, "eta", _rgb("eta", self.eta, 0.0, open_lower=True))
        object.__setattr__(self, "k", _rgb("k", self.k, 0.0))
        diffuse = _rgb("diffuse", self.diffuse, 0.0)
        if np.any(diffuse > 1.0):
            raise ValueError(f"diffuse: {diffuse.tolist()} is not an albedo in [0, 1]")
        object.__setattr__(self, "diffuse", diffuse)
        weight = float(_validate.as_real_array("specular_weight", self.specular_weight))
        if not 0.0 <= weight <= 1.0:
            raise ValueError(f"specular_weight: {weight!r} is not in [0, 1]")
        object.__setattr__(self, "specular_weight", weight)

    def fresnel(self, cos_theta_d: RealArrayLike) -> Float64Array:
        """The unpolarised reflectance ``(..., 3)`` at ``cos θd = wi·h``."""
        cos_theta_d = np.asarray(cos_theta_d, dtype=np.float64)
        eta_rgb, k_rgb = np.asarray(self.eta, dtype=np.float64), np.asarray(self.k, dtype=np.float64)
        if np.any(k_rgb > 0.0):  # a channel at a time: no (..., 3) copies of the broadcast arguments
            channels = [_microfacet.fresnel_conductor(cos_theta_d, eta, k) for eta, k in zip(eta_rgb, k_rgb)]
        else:
            channels = [_microfacet.fresnel_dielectric(cos_theta_d, eta) for eta in eta_rgb]
        return np.stack(channels, axis=-1)

    @property
    def f0(self) -> Float64Array:
        """F at normal incidence, RGB: what the principled model's specular colour stands for."""
        return self.fresnel(1.0)

    def __call__(self, wi: RealArrayLike, wo: RealArrayLike) -> Float64Array:
        light, view = np.broadcast_arrays(np.asarray(_validate.directions("wi", wi), dtype=np.float64),
                                          np.asarray(_validate.directions("wo", wo), dtype=np.float64))
        f = np.full(light.shape, np.nan)
        above = (light[..., 2] > 0.0) & (view[..., 2] > 0.0)
        l, v = light[above], view[above]
        l = l / np.linalg.norm(l, axis=-1, keepdims=True)
        v = v / np.linalg.norm(v, axis=-1, keepdims=True)
        h = l + v
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        dg = self.distribution.d(h) * self.distribution.g2(l, v)
        specular = (dg / (4.0 * l[:, 2] * v[:, 2]))[:, None] * self.fresnel(np.sum(l * h, axis=-1))
        f[above] = self.specular_weight * specular + np.asarray(self.diffuse, dtype=np.float64) / np.pi
        return f


def _distribution(name: str, alpha: float) -> _microfacet.GGX | _microfacet.Beckmann:
    if not isinstance(name, str) or name not in _DISTRIBUTIONS:
        raise ValueError(f"distribution: expected one of {', '.join(_DISTRIBUTIONS)}, got {name!r}")
    return _DISTRIBUTIONS[name](alpha)


def conductor(metal: str | tuple[RealArrayLike, RealArrayLike], alpha: float, *,
              distribution: str = "beckmann") -> MicrofacetSurface:
    """A rough metal: ``metal`` a name in :data:`CONDUCTORS` or an ``(eta, k)`` pair;
    ``alpha`` the roughness of the ``distribution`` (``"beckmann"`` or ``"ggx"``)."""
    if isinstance(metal, str):
        if metal not in CONDUCTORS:
            raise ValueError(f"metal: expected one of {', '.join(CONDUCTORS)} or an (eta, k) pair, got {metal!r}")
        return MicrofacetSurface(_distribution(distribution, alpha), *CONDUCTORS[metal])
    eta, k = metal
    return MicrofacetSurface(_distribution(distribution, alpha), eta, k)


def plastic(diffuse: RealArrayLike, alpha: float, *, ior: float = 1.5,
            distribution: str = "ggx") -> MicrofacetSurface:
    """A Lambertian body of albedo ``diffuse`` under a rough dielectric interface of index ``ior``."""
    return MicrofacetSurface(_distribution(distribution, alpha), ior, diffuse=diffuse)


def dusty_dielectric(alpha: float, *, ior: float = 1.5, dust_cover: float = 0.2,
                     dust_albedo: RealArrayLike = (0.5, 0.45, 0.4),
                     distribution: str = "beckmann") -> MicrofacetSurface:
    """A rough dielectric (black beneath) of which ``dust_cover`` is covered by
    Lambertian dust of albedo ``dust_albedo``: a glossy peak over a dim diffuse floor."""
    cover = float(_validate.as_real_array("dust_cover", dust_cover))
    if not 0.0 <= cover <= 1.0:
        raise ValueError(f"dust_cover: {cover!r} is not in [0, 1]")
    albedo = _rgb("dust_albedo", dust_albedo, 0.0)
    return MicrofacetSurface(_distribution(distribution, alpha), ior, diffuse=cover * albedo,
                             specular_weight=1.0 - cover)
