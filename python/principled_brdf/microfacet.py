"""Microfacet toolkit (README "Microfacet toolkit"), float64: GTR, anisotropic GGX with Smith masking, Beckmann.

Every function takes numbers or arrays, broadcasts them numpy-style (a
direction contributes its leading shape ``(...)`` of ``(..., 3)``) and returns
a new float64 array: ``(...)`` for values, ``(..., 3)`` for sampled half
vectors. Directions are unit 3-vectors in the local frame ``n = z``, ``x``
tangent (``alpha_x``), ``y`` bitangent (``alpha_y``); they are checked to be of
length 1 within 1e-3 and normalised before use. ``alpha_y`` defaults to
``alpha_x`` (isotropic).

Domains (README "Bad input": anything else raises ``ValueError``/``TypeError`` naming the
argument and its first offending element): ``cos_theta_h`` in [-1, 1];
uniforms ``u1``, ``u2`` in [0, 1]; GTR ``alpha`` in (0, 1] and ``gamma`` in
(0, 1e6]; GGX and Beckmann ``alpha_x``, ``alpha_y`` > 0. Roughness is clamped
to at least ``MIN_ALPHA`` (and GGX/Beckmann to at most ``MAX_ALPHA``), which
keeps every result finite and free of NaN; the only infinity is Λ at exactly
grazing angles (its true value) or within ~1e-298 of them (where its true value
exceeds the double range).

Each distribution ``D`` is zero for ``h·n <= 0`` and normalised,
``∫ D(h) (h·n) dω_h = 1``; the ``*_pdf`` functions return that density of
``h`` in solid angle, ``D(h) (h·n)``, which is what the matching ``*_sample``
function draws from.
"""

from __future__ import annotations

import typing

import numpy as np

from . import _core
from . import _validate

if typing.TYPE_CHECKING:  # (typing.TYPE_CHECKING: this module shows its public names only)
    from collections.abc import Callable

    from ._typing import Float64Array, RealArrayLike

__all__ = [
    "MIN_ALPHA",
    "MAX_ALPHA",
    "MAX_GAMMA",
    "gtr_d",
    "gtr_pdf",
    "gtr_sample",
    "ggx_d",
    "ggx_pdf",
    "ggx_sample",
    "ggx_sample_visible",
    "ggx_pdf_visible",
    "ggx_lambda",
    "ggx_g1",
    "ggx_g2_separable",
    "ggx_g2_height_correlated",
    "beckmann_d",
    "beckmann_pdf",
    "beckmann_sample",
    "beckmann_lambda",
    "beckmann_g1",
]

MIN_ALPHA = 1e-10  # roughness below this is clamped to it (microfacet.hpp kMinAlpha)
MAX_ALPHA = 1e10  # GGX / Beckmann roughness above this is clamped to it (kMaxAlpha)
MAX_GAMMA = 1e6  # upper end of the GTR gamma domain (kMaxGamma)

_core_mf = _core.microfacet

# --------------------------------------------------------------------------
# validation and packing


def _positive(name: str, value: RealArrayLike, upper: float = np.inf) -> Float64Array:
    """Finite values in (0, upper]."""
    array = _validate.as_real_array(name, value)
    _validate.require_in_domain(name, array, 0.0, upper)
    bad = array <= 0.0
    if bad.any():
        i = _validate.first_true(bad)
        domain = "(0, inf)" if np.isinf(upper) else f"(0, {upper:g}]"
        value = float(array.ravel()[i])
        raise ValueError(f"{_validate.element_name(name, i, array.shape)}: {value!r} is outside its domain {domain}")
    return array


def _in_range(name: str, value: RealArrayLike, lower: float, upper: float) -> Float64Array:
    array = _validate.as_real_array(name, value)
    _validate.require_in_domain(name, array, lower, upper)
    return array


def _uniform(name: str, value: RealArrayLike) -> Float64Array:
    return _in_range(name, value, 0.0, 1.0)


def _alphas(alpha_x: RealArrayLike, alpha_y: RealArrayLike | None) -> tuple[Float64Array, Float64Array]:
    ax = _positive("alpha_x", alpha_x)
    ay = ax if alpha_y is None else _positive("alpha_y", alpha_y)
    return ax, ay


class _Vector:
    """Marks a ``(..., 3)`` argument for :func:`_run`."""

    def __init__(self, array: Float64Array) -> None:
        self.array = array


def _run(core_function: Callable[..., Float64Array], *args: bool, returns_vector: bool = False,
         **arguments: Float64Array | _Vector) -> Float64Array:
    """Broadcasts ``arguments`` (numpy arrays or :class:`_Vector`), packs them as rows
    (one shared row when an argument has a single element) and calls the binding."""
    leading = {
        name: (value.array.shape[:-1] if isinstance(value, _Vector) else value.shape)
        for name, value in arguments.items()
    }
    shape = _validate.broadcast_leading(**leading)
    trailing = (3,) if returns_vector else ()
    if int(np.prod(shape, dtype=np.int64)) == 0:
        return np.zeros(shape + trailing)
    packed = []
    for value in arguments.values():
        if isinstance(value, _Vector):
            array = value.array
            if array.size == 3:
                packed.append(np.ascontiguousarray(array.reshape(1, 3)))
            else:
                packed.append(np.ascontiguousarray(np.broadcast_to(array, shape + (3,))).reshape(-1, 3))
        elif value.size == 1:
            packed.append(np.ascontiguousarray(value.reshape(1)))
        else:
            packed.append(np.ascontiguousarray(np.broadcast_to(value, shape)).reshape(-1))
    out = core_function(*packed, *args)
    return out.reshape(shape + trailing)


# --------------------------------------------------------------------------
# GTR (Burley 2012 appendix B)


def gtr_d(cos_theta_h: RealArrayLike, alpha: RealArrayLike, gamma: RealArrayLike, *,
          closed_forms: bool = True) -> Float64Array:
    """Generalized-Trowbridge-Reitz distribution D(θh), appendix B eq. (1)::

        D = (γ-1)(α²-1) / (π (1 - (α²)^(1-γ))) / (1 + (α²-1) cos²θh)^γ

    for any γ > 0, 0 for ``cos_theta_h <= 0``. The limits are built in: γ = 1
    gives eq. (4) ``(α²-1) / (π ln α² (1 + (α²-1) cos²θh))``, α = 1 gives 1/π.
    With ``closed_forms`` (default) γ = 1, 3/2 and 2 use eq. (4), (6)
    ``(α²+α) / (2π (1 + (α²-1) cos²θh)^(3/2))`` and (8)
    ``α² / (π (1 + (α²-1) cos²θh)²)``; otherwise the general form serves every γ.
    """
    c = _in_range("cos_theta_h", cos_theta_h, -1.0, 1.0)
    a = _positive("alpha", alpha, 1.0)
    g = _positive("gamma", gamma, MAX_GAMMA)
    return _run(_core_mf.gtr_d, bool(closed_forms), cos_theta_h=c, alpha=a, gamma=g)


def gtr_pdf(h: RealArrayLike, alpha: RealArrayLike, gamma: RealArrayLike, *,
            closed_forms: bool = True) -> Float64Array:
    """Density in solid angle of the half vectors drawn by :func:`gtr_sample`: ``D(h) (h·n)``.

    ``cos²θh`` and ``sin²θh`` are taken from the components of ``h``, so narrow
    peaks stay accurate where ``1 - cos²θh`` would cancel.
    """
    hv = _validate.directions("h", h)
    a = _positive("alpha", alpha, 1.0)
    g = _positive("gamma", gamma, MAX_GAMMA)
    return _run(_core_mf.gtr_pdf, bool(closed_forms), h=_Vector(hv), alpha=a, gamma=g)


def gtr_sample(u1: RealArrayLike, u2: RealArrayLike, alpha: RealArrayLike, gamma: RealArrayLike, *,
               closed_forms: bool = True) -> Float64Array:
    """Half vectors ``(..., 3)`` with density :func:`gtr_pdf`, appendix B eq. (2)-(3)::

        φ = 2π u1,  cos θh = sqrt((1 - [(α²)^(1-γ)(1-u2) + u2]^(1/(1-γ))) / (1 - α²))

    (eq. (5), (7), (9) at γ = 1, 3/2, 2), evaluated with expm1/log1p so that it
    is accurate near γ = 1 and α = 1; ``u2 = 1`` gives the horizon.
    """
    v1 = _uniform("u1", u1)
    v2 = _uniform("u2", u2)
    a = _positive("alpha", alpha, 1.0)
    g = _positive("gamma", gamma, MAX_GAMMA)
    return _run(_core_mf.gtr_sample, bool(closed_forms), returns_vector=True, u1=v1, u2=v2, alpha=a, gamma=g)


# --------------------------------------------------------------------------
# anisotropic GGX and Smith masking


def ggx_d(h: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Anisotropic GGX (GTR2), appendix B eq. (13)::

        D = 1 / (π αx αy ((h·x/αx)² + (h·y/αy)² + (h·n)²)²),  0 for h·n <= 0.
    """
    hv = _validate.directions("h", h)
    ax, ay = _alphas(alpha_x, alpha_y)
    return _run(_core_mf.ggx_d, h=_Vector(hv), alpha_x=ax, alpha_y=ay)


def ggx_pdf(h: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Density in solid angle of :func:`ggx_sample`: ``D(h) (h·n)``."""
    hv = _validate.directions("h", h)
    ax, ay = _alphas(alpha_x, alpha_y)
    return _run(_core_mf.ggx_pdf, h=_Vector(hv), alpha_x=ax, alpha_y=ay)


def ggx_sample(u1: RealArrayLike, u2: RealArrayLike, alpha_x: RealArrayLike,
               alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Half vectors ``(..., 3)`` by the projected half vector, eq. (14)-(15)::

        h' = sqrt(u2/(1-u2)) (αx cos 2πu1 x + αy sin 2πu1 y) + n,   h = h'/|h'|

    with density :func:`ggx_pdf`.
    """
    v1 = _uniform("u1", u1)
    v2 = _uniform("u2", u2)
    ax, ay = _alphas(alpha_x, alpha_y)
    return _run(_core_mf.ggx_sample, returns_vector=True, u1=v1, u2=v2, alpha_x=ax, alpha_y=ay)


def ggx_sample_visible(wo: RealArrayLike, u1: RealArrayLike, u2: RealArrayLike, alpha_x: RealArrayLike,
                       alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Visible normals seen from ``wo`` (Heitz 2018), ``(..., 3)``, density :func:`ggx_pdf_visible`.

    ``wo`` is stretched to the α = 1 configuration, a point is drawn on the
    projected visible hemisphere (disk radius ``sqrt(u2)``, angle ``2π u1``,
    warped towards the visible half), lifted and unstretched. A ``wo`` below the
    horizon is mirrored to ``-wo`` (two-sided use).
    """
    w = _validate.directions("wo", wo)
    v1 = _uniform("u1", u1)
    v2 = _uniform("u2", u2)
    ax, ay = _alphas(alpha_x, alpha_y)
    return _run(_core_mf.ggx_sample_visible, returns_vector=True, wo=_Vector(w), u1=v1, u2=v2, alpha_x=ax, alpha_y=ay)


def ggx_pdf_visible(h: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                    alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Density of visible normals in solid angle::

        D_wo(h) = G1(wo) max(0, wo·h) D(h) / |wo·n|

    with ``G1 / |wo·n|`` written ``2 / (|wo·n| + sqrt((wo·n)² + αx² wox² + αy² woy²))``, finite at
    grazing ``wo``; ``wo`` below the horizon is mirrored to ``-wo`` as in the sampler.
    """
    hv = _validate.directions("h", h)
    w = _validate.directions("wo", wo)
    ax, ay = _alphas(alpha_x, alpha_y)
    return _run(_core_mf.ggx_pdf_visible, h=_Vector(hv), wo=_Vector(w), alpha_x=ax, alpha_y=ay)


def ggx_lambda(w: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Smith Λ for anisotropic GGX::

        Λ(w) = (-1 + sqrt(1 + (αx² wx² + αy² wy²) / wz²)) / 2

    evaluated as ``p² / (2|wz| (sqrt(wz² + p²) + |wz|))``, ``p² = αx² wx² + αy² wy²``:
    no cancellation and no overflow as ``wz -> 0``; +inf at exactly ``wz = 0``.
    """
    wv = _validate.directions("w", w)
    ax, ay = _alphas(alpha_x, alpha_y)
    return _run(_core_mf.ggx_lambda, w=_Vector(wv), alpha_x=ax, alpha_y=ay)


def ggx_g1(w: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Smith masking ``G1 = 1 / (1 + Λ(w)) = 2|wz| / (|wz| + sqrt(wz² + αx² wx² + αy² wy²))``."""
    wv = _validate.directions("w", w)
    ax, ay = _alphas(alpha_x, alpha_y)
    return _run(_core_mf.ggx_g1, w=_Vector(wv), alpha_x=ax, alpha_y=ay)


def ggx_g2_separable(wi: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                     alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Separable masking-shadowing ``G2 = G1(wi) G1(wo)`` (what the model uses)."""
    a = _validate.directions("wi", wi)
    b = _validate.directions("wo", wo)
    ax, ay = _alphas(alpha_x, alpha_y)
    return _run(_core_mf.ggx_g2_separable, wi=_Vector(a), wo=_Vector(b), alpha_x=ax, alpha_y=ay)


def ggx_g2_height_correlated(wi: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                             alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Height-correlated masking-shadowing ``G2 = 1 / (1 + Λ(wi) + Λ(wo))``.

    Evaluated as ``2|zi||zo| / (|zi| ro + |zo| ri)``, ``r = sqrt(z² + αx² x² + αy² y²)``;
    0 when either direction is grazing.
    """
    a = _validate.directions("wi", wi)
    b = _validate.directions("wo", wo)
    ax, ay = _alphas(alpha_x, alpha_y)
    return _run(_core_mf.ggx_g2_height_correlated, wi=_Vector(a), wo=_Vector(b), alpha_x=ax, alpha_y=ay)


# --------------------------------------------------------------------------
# anisotropic Beckmann (Walter et al. 2007)


def beckmann_d(h: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Anisotropic Beckmann (Walter et al. 2007), stretched as in Heitz 2014::

        D = exp(-((h·x/αx)² + (h·y/αy)²) / (h·n)²) / (π αx αy (h·n)⁴),  0 for h·n <= 0.
    """
    hv = _validate.directions("h", h)
    ax, ay = _alphas(alpha_x, alpha_y)
    return _run(_core_mf.beckmann_d, h=_Vector(hv), alpha_x=ax, alpha_y=ay)


def beckmann_pdf(h: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Density in solid angle of :func:`beckmann_sample`: ``D(h) (h·n)``."""
    hv = _validate.directions("h", h)
    ax, ay = _alphas(alpha_x, alpha_y)
    return _run(_core_mf.beckmann_pdf, h=_Vector(hv), alpha_x=ax, alpha_y=ay)


def beckmann_sample(u1: RealArrayLike, u2: RealArrayLike, alpha_x: RealArrayLike,
                    alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Half vectors ``(..., 3)`` with density :func:`beckmann_pdf`::

        h ∝ sqrt(-ln(1 - u2)) (αx cos 2πu1 x + αy sin 2πu1 y) + n

    (the stretched slopes are Gaussian; ``u2 = 1`` gives the horizon).
    """
    v1 = _uniform("u1", u1)
    v2 = _uniform("u2", u2)
    ax, ay = _alphas(alpha_x, alpha_y)
    return _run(_core_mf.beckmann_sample, returns_vector=True, u1=v1, u2=v2, alpha_x=ax, alpha_y=ay)


def beckmann_lambda(w: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Smith Λ for Beckmann (Heitz 2014), exact (not Walter's rational fit)::

        Λ = (erf(a) - 1) / 2 + exp(-a²) / (2 a sqrt(π)),   a = |wz| / sqrt(αx² wx² + αy² wy²)

    (``a = 1 / (α_o tan θ)`` by eq. (3-25)); 0 at the normal, +inf at exactly grazing.
    """
    wv = _validate.directions("w", w)
    ax, ay = _alphas(alpha_x, alpha_y)
    return _run(_core_mf.beckmann_lambda, w=_Vector(wv), alpha_x=ax, alpha_y=ay)


def beckmann_g1(w: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Smith masking for Beckmann, ``G1 = 1 / (1 + Λ(w))``."""
    wv = _validate.directions("w", w)
    ax, ay = _alphas(alpha_x, alpha_y)
    return _run(_core_mf.beckmann_g1, w=_Vector(wv), alpha_x=ax, alpha_y=ay)
