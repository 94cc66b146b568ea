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
    from collections.abc import Callable

    from ._typing import Float64Array, RealArrayLike

__all__ = ["MicrofacetSurface", "LayeredPlastic", "Ward", "AshikhminShirley", "Satin", "CONDUCTORS", "conductor",
           "plastic", "layered_plastic", "dusty_dielectric", "ward", "ashikhmin_shirley", "satin"]

#: Complex indices of refraction ``(eta, k)`` at three wavelengths standing for R, G, B
#: (about 650, 550 and 450 nm).
CONDUCTORS: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    "gold": ((0.18, 0.42, 1.37), (3.42, 2.35, 1.77)),
    "copper": ((0.200438, 0.924033, 1.10221), (3.91295, 2.45285, 2.14219)),
    "aluminium": ((1.65746, 0.880369, 0.521229), (9.22387, 6.26952, 4.837)),
    "silver": ((0.15943, 0.14512, 0.13547), (3.9291, 3.1900, 2.3808)),
    "chrome": ((3.1071, 3.1812, 2.3230), (3.3314, 3.3291, 3.1350)),
}
_MAX_IOR = 1e3  # a coat's index: beyond, no dielectric
_DISTRIBUTIONS = {"beckmann": _microfacet.Beckmann, "ggx": _microfacet.GGX, "blinn_phong": _microfacet.BlinnPhong}


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
        _set_index(self)
        _set_albedos(self, ("diffuse",))
        weight = float(_validate.as_real_array("specular_weight", self.specular_weight))
        if not 0.0 <= weight <= 1.0:
            raise ValueError(f"specular_weight: {weight!r} is not in [0, 1]")
        object.__setattr__(self, "specular_weight", weight)

    def fresnel(self, cos_theta_d: RealArrayLike) -> Float64Array:
        """The unpolarised reflectance ``(..., 3)`` at ``cos θd = wi·h``."""
        return _fresnel(cos_theta_d, self.eta, self.k)

    @property
    def f0(self) -> Float64Array:
        """F at normal incidence, RGB: what the principled model's specular colour stands for."""
        return self.fresnel(1.0)

    def __call__(self, wi: RealArrayLike, wo: RealArrayLike) -> Float64Array:
        def f(l: Float64Array, v: Float64Array, h: Float64Array) -> Float64Array:
            dg = self.distribution.d(h) * self.distribution.g2(l, v)
            specular = (dg / (4.0 * l[:, 2] * v[:, 2]))[:, None] * self.fresnel(np.sum(l * h, axis=-1))
            return self.specular_weight * specular + np.asarray(self.diffuse, dtype=np.float64) / np.pi
        return _above_horizon(wi, wo, f)


def _set_index(surface: object) -> None:
    """A frozen dataclass's ``eta`` (> 0) and ``k`` (>= 0) as checked RGB arrays."""
    object.__setattr__(surface, "eta", _rgb("eta", getattr(surface, "eta"), 0.0, open_lower=True))
    object.__setattr__(surface, "k", _rgb("k", getattr(surface, "k"), 0.0))


def _set_in_range(surface: object, names: tuple[str, ...], lower: float, upper: float, what: str, *,
                  open_lower: bool = False) -> None:
    """A frozen dataclass's scalar fields ``names`` as floats in [lower, upper] ((lower, upper]
    with ``open_lower``); a ValueError saying they are not ``what`` otherwise."""
    for name in names:
        value = float(_validate.as_real_array(name, getattr(surface, name)))
        if not ((lower < value) if open_lower else (lower <= value)) or not value <= upper:
            raise ValueError(f"{name}: {value!r} is not {what}")
        object.__setattr__(surface, name, value)


def _set_albedos(surface: object, names: tuple[str, ...]) -> None:
    """A frozen dataclass's fields ``names`` as RGB arrays in [0, 1]."""
    for name in names:
        value = _rgb(name, getattr(surface, name), 0.0)
        if np.any(value > 1.0):
            raise ValueError(f"{name}: {value.tolist()} is not an albedo in [0, 1]")
        object.__setattr__(surface, name, value)


def _fresnel(cos_theta_d: RealArrayLike, eta: RealArrayLike, k: RealArrayLike) -> Float64Array:
    """The unpolarised reflectance ``(..., 3)`` of the index ``eta + i k`` (RGB) at ``cos θd``
    (a dot product of unit vectors, clipped to [-1, 1] against its rounding)."""
    cos_theta_d = np.clip(np.asarray(cos_theta_d, dtype=np.float64), -1.0, 1.0)
    eta_rgb, k_rgb = np.asarray(eta, dtype=np.float64), np.asarray(k, dtype=np.float64)
    if np.any(k_rgb > 0.0):  # a channel at a time: no (..., 3) copies of the broadcast arguments
        channels = [_microfacet.fresnel_conductor(cos_theta_d, e, c) for e, c in zip(eta_rgb, k_rgb)]
    else:
        channels = [_microfacet.fresnel_dielectric(cos_theta_d, e) for e in eta_rgb]
    return np.stack(channels, axis=-1)


def _above_horizon(wi: RealArrayLike, wo: RealArrayLike,
                   f: Callable[[Float64Array, Float64Array, Float64Array], Float64Array]) -> Float64Array:
    """``f(l, v, h)`` ``(n, 3)`` at the pairs above the horizon (unit l, v and half vector h,
    ``(n, 3)`` each), NaN at the others, as a gonioreflectometer has no data there."""
    light, view = np.broadcast_arrays(np.asarray(_validate.directions("wi", wi), dtype=np.float64),
                                      np.asarray(_validate.directions("wo", wo), dtype=np.float64))
    values = np.full(light.shape, np.nan)
    above = (light[..., 2] > 0.0) & (view[..., 2] > 0.0)
    l, v = light[above], view[above]
    l = l / np.linalg.norm(l, axis=-1, keepdims=True)
    v = v / np.linalg.norm(v, axis=-1, keepdims=True)
    h = l + v
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    values[above] = f(l, v, h)
    return values


def _distribution(name: str, alpha: float) -> _microfacet.GGX | _microfacet.Beckmann:
    if not isinstance(name, str) or name not in _DISTRIBUTIONS:
        raise ValueError(f"distribution: expected one of {', '.join(_DISTRIBUTIONS)}, got {name!r}")
    return _DISTRIBUTIONS[name](alpha)


def conductor(metal: str | tuple[RealArrayLike, RealArrayLike], alpha: float, *,
              distribution: str = "beckmann") -> MicrofacetSurface:
    """A rough metal: ``metal`` a name in :data:`CONDUCTORS` or an ``(eta, k)`` pair;
    ``alpha`` the roughness of the ``distribution`` (``"beckmann"``, ``"ggx"`` or
    ``"blinn_phong"``, whose exponent is ``2/α² - 2``)."""
    return MicrofacetSurface(_distribution(distribution, alpha), *_metal_index(metal))


def _metal_index(metal: str | tuple[RealArrayLike, RealArrayLike]) -> tuple[RealArrayLike, RealArrayLike]:
    """``(eta, k)`` of a name in :data:`CONDUCTORS` or of an ``(eta, k)`` pair."""
    if isinstance(metal, str):
        if metal not in CONDUCTORS:
            raise ValueError(f"metal: expected one of {', '.join(CONDUCTORS)} or an (eta, k) pair, got {metal!r}")
        return CONDUCTORS[metal]
    eta, k = metal
    return eta, k


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


@dataclass(frozen=True, eq=False)
class LayeredPlastic:
    """A diffuse body under a rough dielectric coat of index ``ior``, float64, RGB in 1/sr:

        f = D G2 F(wi·h) / (4 cos θl cos θv)
            + (1 - F(cos θl)) (1 - F(cos θv)) f_body / (η² (1 - ρ F̄i))

    The coat reflects by the microfacet term (exact dielectric Fresnel); light that crosses it
    at the macroscopic normal's Fresnel transmittance meets the body, ``f_body`` Lambert's
    ``ρ/π`` (``sigma = 0``) or Oren & Nayar's (1994, the qualitative model) of slope
    deviation ``sigma`` radians, taken at the outer directions; it leaves the coat with the
    radiance divided by ``η²``, and the share reflected back down by the inside of the coat,
    ``F̄i = 1 - (1 - F̄e) / η²`` (``F̄e`` the cosine-weighted mean of F from outside), returns
    to the body: with ``ρ = 1`` all the light that enters leaves. NaN at or below the horizon.
    """

    distribution: _microfacet.GGX | _microfacet.Beckmann | _microfacet.BlinnPhong
    ior: float
    albedo: RealArrayLike
    sigma: float = 0.0

    def __post_init__(self) -> None:
        _set_in_range(self, ("ior",), 1.0, _MAX_IOR, f"an index of refraction in (1, {_MAX_IOR:g}]", open_lower=True)
        _set_albedos(self, ("albedo",))
        _set_in_range(self, ("sigma",), 0.0, np.pi / 2, "a slope deviation in [0, π/2] radians")

    @property
    def internal_reflectance(self) -> float:
        """``F̄i``: the share of the body's diffuse light that the inside of the coat sends back."""
        x, w = np.polynomial.legendre.leggauss(64)  # F̄e = ∫ F(μ) dμ² over μ² in [0, 1]
        external = float(0.5 * w @ _microfacet.fresnel_dielectric(np.sqrt(0.5 * (x + 1.0)), self.ior))
        return 1.0 - (1.0 - external) / self.ior**2

    def _body(self, l: Float64Array, v: Float64Array) -> Float64Array:
        """f_body / ρ (n,): Lambert's 1/π, or Oren & Nayar's qualitative model."""
        if self.sigma == 0.0:
            return np.full(len(l), 1.0 / np.pi)
        s2 = self.sigma**2
        a, b = 1.0 - 0.5 * s2 / (s2 + 0.33), 0.45 * s2 / (s2 + 0.09)
        theta_l, theta_v = np.arccos(np.clip(l[:, 2], -1.0, 1.0)), np.arccos(np.clip(v[:, 2], -1.0, 1.0))
        azimuths = np.hypot(l[:, 0], l[:, 1]) * np.hypot(v[:, 0], v[:, 1])
        cos_dphi = np.where(azimuths > 0.0, (l[:, 0] * v[:, 0] + l[:, 1] * v[:, 1]) / np.maximum(azimuths, 1e-300), 0.0)
        alpha, beta = np.maximum(theta_l, theta_v), np.minimum(theta_l, theta_v)
        return (a + b * np.maximum(cos_dphi, 0.0) * np.sin(alpha) * np.tan(beta)) / np.pi

    def __call__(self, wi: RealArrayLike, wo: RealArrayLike) -> Float64Array:
        eta = np.full(3, self.ior)
        albedo = np.asarray(self.albedo, dtype=np.float64)
        body_scale = albedo / (self.ior**2 * (1.0 - albedo * self.internal_reflectance))

        def f(l: Float64Array, v: Float64Array, h: Float64Array) -> Float64Array:
            dg = self.distribution.d(h) * self.distribution.g2(l, v)
            coat = (dg / (4.0 * l[:, 2] * v[:, 2]))[:, None] * _fresnel(np.sum(l * h, axis=-1), eta, 0.0)
            transmitted = (1.0 - _fresnel(l[:, 2], eta, 0.0)) * (1.0 - _fresnel(v[:, 2], eta, 0.0))
            return coat + transmitted * self._body(l, v)[:, None] * body_scale
        return _above_horizon(wi, wo, f)


@dataclass(frozen=True, eq=False)
class Ward:
    """Ward's (1992) anisotropic BRDF with a conductor's exact Fresnel for its specular albedo
    (``eta + i k``, RGB), float64, in 1/sr:

        f = F(wi·h) exp(-((h·x / αx)² + (h·y / αy)²) / (h·n)²) / (4π αx αy sqrt(cos θl cos θv))

    ``x`` the tangent (the direction of brushing has the smaller α). NaN at or below the horizon."""

    eta: RealArrayLike
    k: RealArrayLike
    alpha_x: float
    alpha_y: float

    def __post_init__(self) -> None:
        _set_index(self)
        _set_in_range(self, ("alpha_x", "alpha_y"), 0.0, 1.0, "in (0, 1]", open_lower=True)

    def __call__(self, wi: RealArrayLike, wo: RealArrayLike) -> Float64Array:
        def f(l: Float64Array, v: Float64Array, h: Float64Array) -> Float64Array:
            slope = ((h[:, 0] / self.alpha_x) ** 2 + (h[:, 1] / self.alpha_y) ** 2) / h[:, 2] ** 2
            lobe = np.exp(-slope) / (4.0 * np.pi * self.alpha_x * self.alpha_y * np.sqrt(l[:, 2] * v[:, 2]))
            return lobe[:, None] * _fresnel(np.sum(l * h, axis=-1), self.eta, self.k)
        return _above_horizon(wi, wo, f)


@dataclass(frozen=True, eq=False)
class AshikhminShirley:
    """Ashikhmin & Shirley's (2000) anisotropic Phong specular lobe with a conductor's exact
    Fresnel (``eta + i k``, RGB) in place of Schlick's, float64, in 1/sr:

        f = sqrt((nu + 1)(nv + 1)) / (8π) (h·n)^e F(wi·h) / ((wi·h) max(cos θl, cos θv)),
        e = (nu (h·x)² + nv (h·y)²) / (1 - (h·n)²)

    NaN at or below the horizon."""

    eta: RealArrayLike
    k: RealArrayLike
    nu: float
    nv: float

    def __post_init__(self) -> None:
        _set_index(self)
        _set_in_range(self, ("nu", "nv"), 0.0, 1e6, "an exponent in [0, 1e6]")

    def __call__(self, wi: RealArrayLike, wo: RealArrayLike) -> Float64Array:
        def f(l: Float64Array, v: Float64Array, h: Float64Array) -> Float64Array:
            sin2 = h[:, 0] ** 2 + h[:, 1] ** 2
            # at h = n the exponent's azimuthal mean is undefined and (h·n)^e = 1 whatever e
            e = np.where(sin2 > 0.0, (self.nu * h[:, 0] ** 2 + self.nv * h[:, 1] ** 2) / np.maximum(sin2, 1e-300),
                         self.nu)
            cos_d = np.sum(l * h, axis=-1)
            lobe = (np.sqrt((self.nu + 1.0) * (self.nv + 1.0)) / (8.0 * np.pi) * h[:, 2] ** e
                    / (cos_d * np.maximum(l[:, 2], v[:, 2])))
            return lobe[:, None] * _fresnel(cos_d, self.eta, self.k)
        return _above_horizon(wi, wo, f)


@dataclass(frozen=True, eq=False)
class Satin:
    """A cloth: a Lambertian body under a sheen of grazing microfibres, float64, RGB in 1/sr:

        f = ρd / π + s D(h) / (4 (cos θl + cos θv - cos θl cos θv))

    with Estevez & Kulla's (2017) "Charlie" distribution ``D = (2 + 1/α) sin^(1/α) θh / (2π)``
    and Neubelt & Pettineo's (2013) visibility: bright where the light and the view graze the
    surface, as a satin's sheen is. ``diffuse`` ρd and ``sheen`` s RGB in [0, 1]; ``alpha`` in
    (0, 1]. NaN at or below the horizon."""

    diffuse: RealArrayLike
    sheen: RealArrayLike
    alpha: float

    def __post_init__(self) -> None:
        _set_albedos(self, ("diffuse", "sheen"))
        _set_in_range(self, ("alpha",), 0.0, 1.0, "in (0, 1]", open_lower=True)

    def __call__(self, wi: RealArrayLike, wo: RealArrayLike) -> Float64Array:
        def f(l: Float64Array, v: Float64Array, h: Float64Array) -> Float64Array:
            sin_h = np.sqrt(np.maximum(1.0 - h[:, 2] ** 2, 0.0))
            d = (2.0 + 1.0 / self.alpha) * sin_h ** (1.0 / self.alpha) / (2.0 * np.pi)
            visibility = 1.0 / (4.0 * (l[:, 2] + v[:, 2] - l[:, 2] * v[:, 2]))
            return (np.asarray(self.diffuse, dtype=np.float64) / np.pi
                    + (d * visibility)[:, None] * np.asarray(self.sheen, dtype=np.float64))
        return _above_horizon(wi, wo, f)


def layered_plastic(diffuse: RealArrayLike, alpha: float, *, ior: float = 1.5, distribution: str = "ggx",
                    sigma: float = 0.0) -> LayeredPlastic:
    """A plastic: a body of albedo ``diffuse`` (Lambert, or Oren-Nayar of slope deviation
    ``sigma`` radians) under a rough coat of index ``ior`` and roughness ``alpha``."""
    return LayeredPlastic(_distribution(distribution, alpha), ior, diffuse, sigma)


def ward(metal: str | tuple[RealArrayLike, RealArrayLike], alpha_x: float, alpha_y: float) -> Ward:
    """A brushed metal by Ward's model: ``metal`` a name in :data:`CONDUCTORS` or ``(eta, k)``."""
    return Ward(*_metal_index(metal), alpha_x, alpha_y)


def ashikhmin_shirley(metal: str | tuple[RealArrayLike, RealArrayLike], nu: float, nv: float) -> AshikhminShirley:
    """A brushed metal by Ashikhmin & Shirley's lobe: ``metal`` a name in :data:`CONDUCTORS` or ``(eta, k)``."""
    return AshikhminShirley(*_metal_index(metal), nu, nv)


def satin(diffuse: RealArrayLike, sheen: RealArrayLike, alpha: float) -> Satin:
    """A satin: a Lambertian body of albedo ``diffuse`` under a sheen of colour ``sheen``."""
    return Satin(diffuse, sheen, alpha)
