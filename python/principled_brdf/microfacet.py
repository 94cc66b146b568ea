"""Microfacet toolkit (docs/microfacet.md), float64: GTR, anisotropic GGX with Smith masking, Beckmann,
and the rest of the family (docs/model.md "The microfacet family"): Blinn-Phong, Student-t, exponential power.

Every function takes numbers or arrays, broadcasts them numpy-style (a
direction contributes its leading shape ``(...)`` of ``(..., 3)``) and returns
a new float64 array: ``(...)`` for values, ``(..., 3)`` for sampled half
vectors. Directions are unit 3-vectors in the local frame ``n = z``, ``x``
tangent (``alpha_x``), ``y`` bitangent (``alpha_y``); they are checked to be of
length 1 within 1e-3 and normalised before use. ``alpha_y`` defaults to
``alpha_x`` (isotropic).

Domains (docs/bad-input.md: anything else raises ``ValueError``/``TypeError`` naming the
argument and its first offending element): ``cos_theta_h`` in [-1, 1];
uniforms ``u1``, ``u2`` in [0, 1]; GTR ``alpha`` in (0, 1] and ``gamma`` in
(0, 1e6]; GGX, Beckmann, Student-t and exponential-power ``alpha_x``, ``alpha_y`` > 0,
Blinn-Phong's in (0, 1]; Student-t ``gamma`` in (3/2, 1e12], exponential-power ``p`` in [0.1, 10]. Roughness is clamped
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

    _Core = Callable[..., Float64Array]  # a binding of _core.microfacet
    _AlphaCheck = Callable[[RealArrayLike, RealArrayLike | None], tuple[Float64Array, Float64Array]]
    # a family's shape argument: fixed, or checked (by calling it) after the alphas; None: the binding takes none
    _Shape = Float64Array | Callable[[], Float64Array] | None
    # Beckmann's Walter binding and the approximation keyword, checked after the alphas
    _Walter = tuple[_Core, str | None] | None

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
    "beckmann_g2_separable",
    "beckmann_g2_height_correlated",
    "beckmann_pdf_visible",
    "beckmann_sample_visible",
    "ggx_g2_over_4cos",
    "blinn_phong_d",
    "blinn_phong_pdf",
    "blinn_phong_sample",
    "blinn_phong_lambda",
    "blinn_phong_g1",
    "blinn_phong_g2_separable",
    "blinn_phong_g2_height_correlated",
    "blinn_phong_pdf_visible",
    "student_t_d",
    "student_t_pdf",
    "student_t_sample",
    "student_t_lambda",
    "student_t_g1",
    "student_t_g2_separable",
    "student_t_g2_height_correlated",
    "student_t_pdf_visible",
    "exponential_power_d",
    "exponential_power_pdf",
    "exponential_power_sample",
    "exponential_power_lambda",
    "exponential_power_g1",
    "exponential_power_g2_separable",
    "exponential_power_g2_height_correlated",
    "exponential_power_pdf_visible",
    "hyp2f1",
    "MAX_STUDENT_T_GAMMA",
    "EXPONENTIAL_POWER_P_RANGE",
]

MIN_ALPHA = 1e-10  # roughness below this is clamped to it (microfacet.hpp kMinAlpha)
MAX_ALPHA = 1e10  # GGX / Beckmann roughness above this is clamped to it (kMaxAlpha)
MAX_GAMMA = 1e6  # upper end of the GTR gamma domain (kMaxGamma)
MAX_STUDENT_T_GAMMA = 1e12  # Student-t gamma domain: (3/2, MAX_STUDENT_T_GAMMA]
EXPONENTIAL_POWER_P_RANGE = (0.1, 10.0)  # exponential-power p domain (closed)

_core_mf = _core.microfacet
_NO_SHAPE = np.zeros(())  # the shape argument of the family's bindings, for members without one

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


def _run(core_function: Callable[..., Float64Array], *args: bool | int, returns_vector: bool = False,
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


def _checked_run(core_function: _Core, directions: dict[str, RealArrayLike], uniforms: dict[str, RealArrayLike],
                 alpha_x: RealArrayLike, alpha_y: RealArrayLike | None, alphas: _AlphaCheck, shape: _Shape,
                 walter: _Walter, flags: tuple[int, ...] = (), returns_vector: bool = False) -> Float64Array:
    """Checks the arguments of a GGX-like wrapper in its order (the directions, the uniforms, the
    alphas, then the shape or Beckmann's ``approximation``) and calls the binding with them in that order."""
    arguments: dict[str, Float64Array | _Vector] = {
        name: _Vector(_validate.directions(name, value)) for name, value in directions.items()
    }
    arguments.update((name, _uniform(name, value)) for name, value in uniforms.items())
    arguments["alpha_x"], arguments["alpha_y"] = alphas(alpha_x, alpha_y)
    if walter is not None and _beckmann_approximation(walter[1]):
        core_function, shape = walter[0], _NO_SHAPE
    if shape is not None:
        arguments["shape"] = shape if isinstance(shape, np.ndarray) else shape()
    return _run(core_function, *flags, returns_vector=returns_vector, **arguments)


def _one_direction(core_function: _Core, name: str, direction: RealArrayLike, alpha_x: RealArrayLike,
                   alpha_y: RealArrayLike | None, *, alphas: _AlphaCheck = _alphas, shape: _Shape = None,
                   walter: _Walter = None) -> Float64Array:
    """D, pdf, Λ, G1: of one direction ``name`` (``h`` or ``w``)."""
    return _checked_run(core_function, {name: direction}, {}, alpha_x, alpha_y, alphas, shape, walter)


def _two_directions(core_function: _Core, wi: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                    alpha_y: RealArrayLike | None, *, alphas: _AlphaCheck = _alphas, shape: _Shape = None,
                    walter: _Walter = None, flags: tuple[int, ...] = ()) -> Float64Array:
    """The G2 forms, of ``wi`` and ``wo``."""
    return _checked_run(core_function, {"wi": wi, "wo": wo}, {}, alpha_x, alpha_y, alphas, shape, walter, flags)


def _h_and_wo(core_function: _Core, h: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
              alpha_y: RealArrayLike | None, *, alphas: _AlphaCheck = _alphas, shape: _Shape = None) -> Float64Array:
    """The visible-normal densities, of ``h`` seen from ``wo``."""
    return _checked_run(core_function, {"h": h, "wo": wo}, {}, alpha_x, alpha_y, alphas, shape, None)


def _sample(core_function: _Core, u1: RealArrayLike, u2: RealArrayLike, alpha_x: RealArrayLike,
            alpha_y: RealArrayLike | None, *, alphas: _AlphaCheck = _alphas, shape: _Shape = None) -> Float64Array:
    """The samplers of ``D(h) (h·n)``: half vectors from the uniforms ``u1``, ``u2``."""
    return _checked_run(core_function, {}, {"u1": u1, "u2": u2}, alpha_x, alpha_y, alphas, shape, None,
                        returns_vector=True)


def _sample_visible(core_function: _Core, wo: RealArrayLike, u1: RealArrayLike, u2: RealArrayLike,
                    alpha_x: RealArrayLike, alpha_y: RealArrayLike | None) -> Float64Array:
    """The visible-normal samplers: half vectors seen from ``wo``, from the uniforms ``u1``, ``u2``."""
    return _checked_run(core_function, {"wo": wo}, {"u1": u1, "u2": u2}, alpha_x, alpha_y, _alphas, None, None,
                        returns_vector=True)


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

    GTR is not shape-invariant (changing α is not a stretch of its slopes), so its Smith Λ
    has no closed form and none is offered (docs/model.md "The microfacet family").
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
    return _one_direction(_core_mf.ggx_d, "h", h, alpha_x, alpha_y)


def ggx_pdf(h: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Density in solid angle of :func:`ggx_sample`: ``D(h) (h·n)``."""
    return _one_direction(_core_mf.ggx_pdf, "h", h, alpha_x, alpha_y)


def ggx_sample(u1: RealArrayLike, u2: RealArrayLike, alpha_x: RealArrayLike,
               alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Half vectors ``(..., 3)`` by the projected half vector, eq. (14)-(15)::

        h' = sqrt(u2/(1-u2)) (αx cos 2πu1 x + αy sin 2πu1 y) + n,   h = h'/|h'|

    with density :func:`ggx_pdf`.
    """
    return _sample(_core_mf.ggx_sample, u1, u2, alpha_x, alpha_y)


def ggx_sample_visible(wo: RealArrayLike, u1: RealArrayLike, u2: RealArrayLike, alpha_x: RealArrayLike,
                       alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Visible normals seen from ``wo`` (Heitz 2018), ``(..., 3)``, density :func:`ggx_pdf_visible`.

    ``wo`` is stretched to the α = 1 configuration, a point is drawn on the
    projected visible hemisphere (disk radius ``sqrt(u2)``, angle ``2π u1``,
    warped towards the visible half), lifted and unstretched. A ``wo`` below the
    horizon is mirrored to ``-wo`` (two-sided use).
    """
    return _sample_visible(_core_mf.ggx_sample_visible, wo, u1, u2, alpha_x, alpha_y)


def ggx_pdf_visible(h: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                    alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Density of visible normals in solid angle::

        D_wo(h) = G1(wo) max(0, wo·h) D(h) / |wo·n|

    with ``G1 / |wo·n|`` written ``2 / (|wo·n| + sqrt((wo·n)² + αx² wox² + αy² woy²))``, finite at
    grazing ``wo``; ``wo`` below the horizon is mirrored to ``-wo`` as in the sampler.
    """
    return _h_and_wo(_core_mf.ggx_pdf_visible, h, wo, alpha_x, alpha_y)


def ggx_lambda(w: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Smith Λ for anisotropic GGX::

        Λ(w) = (-1 + sqrt(1 + (αx² wx² + αy² wy²) / wz²)) / 2

    evaluated as ``p² / (2|wz| (sqrt(wz² + p²) + |wz|))``, ``p² = αx² wx² + αy² wy²``:
    no cancellation and no overflow as ``wz -> 0``; +inf at exactly ``wz = 0``.
    """
    return _one_direction(_core_mf.ggx_lambda, "w", w, alpha_x, alpha_y)


def ggx_g1(w: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Smith masking ``G1 = 1 / (1 + Λ(w)) = 2|wz| / (|wz| + sqrt(wz² + αx² wx² + αy² wy²))``."""
    return _one_direction(_core_mf.ggx_g1, "w", w, alpha_x, alpha_y)


def ggx_g2_separable(wi: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                     alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Separable masking-shadowing ``G2 = G1(wi) G1(wo)`` (what the model uses)."""
    return _two_directions(_core_mf.ggx_g2_separable, wi, wo, alpha_x, alpha_y)


def ggx_g2_height_correlated(wi: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                             alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Height-correlated masking-shadowing ``G2 = 1 / (1 + Λ(wi) + Λ(wo))``.

    Evaluated as ``2|zi||zo| / (|zi| ro + |zo| ri)``, ``r = sqrt(z² + αx² x² + αy² y²)``;
    0 when either direction is grazing.
    """
    return _two_directions(_core_mf.ggx_g2_height_correlated, wi, wo, alpha_x, alpha_y)


# --------------------------------------------------------------------------
# anisotropic Beckmann (Walter et al. 2007)


def beckmann_d(h: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Anisotropic Beckmann (Walter et al. 2007), stretched as in Heitz 2014::

        D = exp(-((h·x/αx)² + (h·y/αy)²) / (h·n)²) / (π αx αy (h·n)⁴),  0 for h·n <= 0.
    """
    return _one_direction(_core_mf.beckmann_d, "h", h, alpha_x, alpha_y)


def beckmann_pdf(h: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Density in solid angle of :func:`beckmann_sample`: ``D(h) (h·n)``."""
    return _one_direction(_core_mf.beckmann_pdf, "h", h, alpha_x, alpha_y)


def beckmann_sample(u1: RealArrayLike, u2: RealArrayLike, alpha_x: RealArrayLike,
                    alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Half vectors ``(..., 3)`` with density :func:`beckmann_pdf`::

        h ∝ sqrt(-ln(1 - u2)) (αx cos 2πu1 x + αy sin 2πu1 y) + n

    (the stretched slopes are Gaussian; ``u2 = 1`` gives the horizon).
    """
    return _sample(_core_mf.beckmann_sample, u1, u2, alpha_x, alpha_y)


def _beckmann_approximation(approximation: str | None) -> bool:
    """True for Walter's rational Λ, False for the exact one."""
    if approximation is None:
        return False
    if approximation == "walter":
        return True
    raise ValueError(f"approximation: expected None or 'walter', got {approximation!r}")


def beckmann_lambda(w: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None, *,
                    approximation: str | None = None) -> Float64Array:
    """Smith Λ for Beckmann (Heitz 2014), exact by default::

        Λ = (erf(a) - 1) / 2 + exp(-a²) / (2 a sqrt(π)),   a = |wz| / sqrt(αx² wx² + αy² wy²)

    (``a = 1 / (α_o tan θ)``); 0 at the normal, +inf at exactly grazing.
    ``approximation="walter"``: Walter et al. 2007 eq. 27's rational fit, as Λ,
    ``(1 - 1.259 a + 0.396 a²) / (3.535 a + 2.181 a²)`` for ``a < 1.6``, else 0:
    within 3.2e-3 of the exact G1 relatively (at most 3.13e-3, at a = 1.33), so
    within 3.2e-3 (1 + Λ) of the exact Λ, and 1.8e-3 absolutely beyond the cut at a = 1.6.
    """
    return _one_direction(_core_mf.beckmann_lambda, "w", w, alpha_x, alpha_y,
                          walter=(_core_mf.beckmann_walter_lambda, approximation))


def beckmann_g1(w: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None, *,
                approximation: str | None = None) -> Float64Array:
    """Smith masking for Beckmann, ``G1 = 1 / (1 + Λ(w))`` (``approximation`` as :func:`beckmann_lambda`)."""
    return _one_direction(_core_mf.beckmann_g1, "w", w, alpha_x, alpha_y,
                          walter=(_core_mf.beckmann_walter_g1, approximation))


def beckmann_g2_separable(wi: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                          alpha_y: RealArrayLike | None = None, *, approximation: str | None = None) -> Float64Array:
    """Separable masking-shadowing ``G2 = G1(wi) G1(wo)`` for Beckmann
    (``approximation`` as :func:`beckmann_lambda`)."""
    return _two_directions(_core_mf.beckmann_g2_separable, wi, wo, alpha_x, alpha_y,
                           walter=(_core_mf.beckmann_walter_g2_separable, approximation))


def beckmann_g2_height_correlated(wi: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                                  alpha_y: RealArrayLike | None = None, *,
                                  approximation: str | None = None) -> Float64Array:
    """Height-correlated ``G2 = 1 / (1 + Λ(wi) + Λ(wo))`` (Heitz 2014 eq. 99) for Beckmann."""
    return _two_directions(_core_mf.beckmann_g2_height_correlated, wi, wo, alpha_x, alpha_y,
                           walter=(_core_mf.beckmann_walter_g2_height_correlated, approximation))


def beckmann_pdf_visible(h: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                         alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Density of Beckmann's visible normals, ``G1(wo) max(0, wo·h) D(h) / |wo·n|`` (Heitz 2014 eq. 38),
    exact Λ; ``wo`` below the horizon is mirrored, 0 for a grazing ``wo``; drawn by :func:`beckmann_sample_visible`."""
    return _h_and_wo(_core_mf.beckmann_pdf_visible, h, wo, alpha_x, alpha_y)


def beckmann_sample_visible(wo: RealArrayLike, u1: RealArrayLike, u2: RealArrayLike, alpha_x: RealArrayLike,
                            alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Beckmann's visible normals seen from ``wo`` (Heitz & d'Eon 2014), ``(..., 3)``, density
    :func:`beckmann_pdf_visible`.

    ``wo`` is stretched to unit roughness; the visible slope along its azimuth is drawn by
    inverting its CDF ``(1 + erf(x) + tan θ exp(-x²)/√π) / (1 + erf(cot θ) + tan θ exp(-cot²θ)/√π)``
    numerically (Newton's iteration inside a bisection bracket, to 1e-15 in the CDF), the other
    slope is Gaussian; the slope is rotated to the azimuth and unstretched. ``wo`` below the
    horizon is mirrored to ``-wo``.
    """
    return _sample_visible(_core_mf.beckmann_sample_visible, wo, u1, u2, alpha_x, alpha_y)


# --------------------------------------------------------------------------
# GGX's combined G2 / (4 cos θi cos θo)

_GGX_VISIBILITY_FORMS = {None: 0, "karis": 1, "hammon": 2}


def ggx_g2_over_4cos(wi: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                     alpha_y: RealArrayLike | None = None, *, approximation: str | None = None) -> Float64Array:
    """GGX's height-correlated ``G2 / (4 |n·wi| |n·wo|)``, the "visibility" V of real-time shading.

    Exact (default; Heitz 2014 eq. 99, the form of Lagarde & de Rousiers 2014)::

        V = 0.5 / (μo sqrt(α_i² (1 - μi²) + μi²) + μi sqrt(α_o² (1 - μo²) + μo²))

    with ``μ = |n·w|`` and ``α_i``, ``α_o`` the roughness projected on each direction
    (``sqrt((αx² wx² + αy² wy²) / (wx² + wy²))``, Heitz 2014 eq. 80; ``α`` itself when isotropic).
    ``approximation="karis"``: the separable Schlick-GGX of Karis 2013 (UE4 course notes),
    ``G1 ≈ μ / (μ (1 - k) + k)`` with ``k = α/2``, so ``V ≈ 1 / (4 (μi (1-k) + k) (μo (1-k) + k))``.
    ``approximation="hammon"``: Hammon 2017 (GDC), ``V ≈ 0.5 / lerp(2 μi μo, μi + μo, α)``
    (anisotropically ``0.5 / (μo lerp(μi, 1, α_i) + μi lerp(μo, 1, α_o))``).
    Measured against the exact V over μ in [0.05, 1]² and α in [0.05, 1] (neither ever exceeds it):
    Karis's G1 is within 18.5% of the exact G1, but its separable V falls up to 82% below the
    height-correlated one (both directions grazing, α = 1); Hammon's V is within 27.6% (grazing
    directions at α = 0.05), within 1.3% at α = 0.95 (``tests/test_microfacet_family.py`` asserts these).
    """
    if approximation not in _GGX_VISIBILITY_FORMS:
        raise ValueError(f"approximation: expected None, 'karis' or 'hammon', got {approximation!r}")
    return _two_directions(_core_mf.ggx_g2_over_4cos, wi, wo, alpha_x, alpha_y,
                           flags=(_GGX_VISIBILITY_FORMS[approximation],))


# --------------------------------------------------------------------------
# Blinn-Phong (Blinn 1977) with Walter et al. 2007's exponent α_p = 2/α² - 2


def _blinn_phong_alphas(alpha_x: RealArrayLike, alpha_y: RealArrayLike | None) -> tuple[Float64Array, Float64Array]:
    ax = _positive("alpha_x", alpha_x, 1.0)
    ay = ax if alpha_y is None else _positive("alpha_y", alpha_y, 1.0)
    return ax, ay


def blinn_phong_d(h: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Blinn-Phong with Walter et al. 2007's exponent ``α_p = 2/α² - 2`` (so ``alpha`` means what it
    means for Beckmann), anisotropic as Ashikhmin & Shirley 2000::

        D = cos^e θh / (π αx αy),   e = (2/αx² - 2) cos²φh + (2/αy² - 2) sin²φh

    (isotropically ``(α_p + 2) / (2π) cos^α_p θh``), 0 for ``h·n <= 0``; ``alpha`` in (0, 1].
    """
    return _one_direction(_core_mf.blinn_phong_d, "h", h, alpha_x, alpha_y, alphas=_blinn_phong_alphas, shape=_NO_SHAPE)


def blinn_phong_pdf(h: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Density in solid angle of :func:`blinn_phong_sample`: ``D(h) (h·n)``."""
    return _one_direction(_core_mf.blinn_phong_pdf, "h", h, alpha_x, alpha_y,
                          alphas=_blinn_phong_alphas, shape=_NO_SHAPE)


def blinn_phong_sample(u1: RealArrayLike, u2: RealArrayLike, alpha_x: RealArrayLike,
                       alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Half vectors ``(..., 3)`` with density :func:`blinn_phong_pdf` (Ashikhmin & Shirley 2000)::

        φh = azimuth of (αx cos 2πu1, αy sin 2πu1),   cos θh = u2^(1/(e(φh) + 2))

    ``u2 = 1`` gives the horizon. (No visible-normal sampler: none is known in closed form.)
    """
    return _sample(_core_mf.blinn_phong_sample, u1, u2, alpha_x, alpha_y, alphas=_blinn_phong_alphas, shape=_NO_SHAPE)


def blinn_phong_lambda(w: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Λ of Blinn-Phong: Beckmann's exact Λ at the same alphas (Walter et al. 2007 §5.2).

    Blinn-Phong is not shape-invariant and has no exact Smith Λ; this one is an
    approximation, good for smooth surfaces only: against the Smith G1 of Blinn-Phong's own D,
    G1 is off by 2e-5 at α = 0.05, 2e-2 at 0.3, 0.13 at 0.6 and 0.64 at 1 (85° views), and the
    weak white furnace misses 1 by 3e-4, 3e-2, 0.15 and 0.73 (88° views; checked in
    ``tests/test_microfacet_family.py``).

    Two-sided (reads ``|w·n|``); 0 at the normal, +inf at exactly grazing.
    """
    return _one_direction(_core_mf.blinn_phong_lambda, "w", w, alpha_x, alpha_y,
                          alphas=_blinn_phong_alphas, shape=_NO_SHAPE)


def blinn_phong_g1(w: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Smith masking ``G1 = 1 / (1 + Λ(w))`` with :func:`blinn_phong_lambda`."""
    return _one_direction(_core_mf.blinn_phong_g1, "w", w, alpha_x, alpha_y,
                          alphas=_blinn_phong_alphas, shape=_NO_SHAPE)


def blinn_phong_g2_separable(wi: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                             alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Separable masking-shadowing ``G2 = G1(wi) G1(wo)``."""
    return _two_directions(_core_mf.blinn_phong_g2_separable, wi, wo, alpha_x, alpha_y,
                           alphas=_blinn_phong_alphas, shape=_NO_SHAPE)


def blinn_phong_g2_height_correlated(wi: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                                     alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Height-correlated masking-shadowing ``G2 = 1 / (1 + Λ(wi) + Λ(wo))`` (Heitz 2014 eq. 99)."""
    return _two_directions(_core_mf.blinn_phong_g2_height_correlated, wi, wo, alpha_x, alpha_y,
                           alphas=_blinn_phong_alphas, shape=_NO_SHAPE)


def blinn_phong_pdf_visible(h: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                            alpha_y: RealArrayLike | None = None) -> Float64Array:
    """Density of visible normals, ``G1(wo) max(0, wo·h) D(h) / |wo·n|`` (Heitz 2014 eq. 38);
    ``wo`` below the horizon is mirrored, 0 for a grazing ``wo``."""
    return _h_and_wo(_core_mf.blinn_phong_pdf_visible, h, wo, alpha_x, alpha_y,
                     alphas=_blinn_phong_alphas, shape=_NO_SHAPE)

# --------------------------------------------------------------------------
# Student-t slopes (Ribardière et al. 2017)


def _student_t_gamma(gamma: RealArrayLike) -> Float64Array:
    array = _validate.as_real_array("gamma", gamma)
    _validate.require_in_domain("gamma", array, 1.5, MAX_STUDENT_T_GAMMA)
    bad = array <= 1.5
    if bad.any():
        i = _validate.first_true(bad)
        raise ValueError(f"{_validate.element_name('gamma', i, array.shape)}: {float(array.ravel()[i])!r} is outside "
                         f"its domain (1.5, {MAX_STUDENT_T_GAMMA:g}]")
    return array


def student_t_d(h: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None, *,
                gamma: RealArrayLike) -> Float64Array:
    """Student-t distribution of slopes (Ribardière et al. 2017), shape ``gamma`` = γ > 3/2::

        D = (γ-1)^γ / (π αx αy cos⁴θh ((γ-1) + r²)^γ),   r² = ((h·x/αx)² + (h·y/αy)²) / (h·n)²

    γ = 2 is GGX; γ -> ∞ is Beckmann (the difference falls as 1/γ).
    """
    return _one_direction(_core_mf.student_t_d, "h", h, alpha_x, alpha_y, shape=lambda: _student_t_gamma(gamma))


def student_t_pdf(h: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None, *,
                  gamma: RealArrayLike) -> Float64Array:
    """Density in solid angle of :func:`student_t_sample`: ``D(h) (h·n)`` (``gamma`` as :func:`student_t_d`)."""
    return _one_direction(_core_mf.student_t_pdf, "h", h, alpha_x, alpha_y, shape=lambda: _student_t_gamma(gamma))


def student_t_sample(u1: RealArrayLike, u2: RealArrayLike, alpha_x: RealArrayLike,
                     alpha_y: RealArrayLike | None = None, *, gamma: RealArrayLike) -> Float64Array:
    """Half vectors ``(..., 3)`` with density :func:`student_t_pdf`: the stretched slope radius in
    closed form, ``ρ² = (γ-1) ((1-u2)^(-1/(γ-1)) - 1)`` (the inverse of its CDF
    ``1 - (1 + ρ²/(γ-1))^(1-γ)``), azimuth ``2π u1``.

    ``u2 = 1`` gives the horizon. (No visible-normal sampler: none is known in closed form.)
    """
    return _sample(_core_mf.student_t_sample, u1, u2, alpha_x, alpha_y, shape=lambda: _student_t_gamma(gamma))


def student_t_lambda(w: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None, *,
                     gamma: RealArrayLike) -> Float64Array:
    """Smith Λ of the Student-t slopes (Ribardière et al. 2017), ``a = |wz| / sqrt(αx² wx² + αy² wy²)``::

        Λ = Γ(γ-1/2) / (Γ(γ) sqrt(π)) ((γ-1)^γ / (2γ-3) S1 + sqrt(γ-1) S2) - 1/2,
        S1 = ((γ-1) + a²)^(3/2-γ) / a,   S2 = a 2F1(1/2, γ-1/2; 3/2; -a²/(γ-1))

    with 2F1 by :func:`hyp2f1` and ``1/2 - ... S2`` taken as the incomplete-beta tail where it would
    cancel: against the closed form in 30-digit mpmath, below 1e-12 relative for γ <= 20; at
    large γ the two terms cancel where Λ is small, leaving ~1e-15 absolutely (3e-6 relative at
    γ = 300, Λ = 4e-10).

    Two-sided (reads ``|w·n|``); 0 at the normal, +inf at exactly grazing.
    """
    return _one_direction(_core_mf.student_t_lambda, "w", w, alpha_x, alpha_y, shape=lambda: _student_t_gamma(gamma))


def student_t_g1(w: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None, *,
                 gamma: RealArrayLike) -> Float64Array:
    """Smith masking ``G1 = 1 / (1 + Λ(w))`` with :func:`student_t_lambda` (``gamma`` as :func:`student_t_d`)."""
    return _one_direction(_core_mf.student_t_g1, "w", w, alpha_x, alpha_y, shape=lambda: _student_t_gamma(gamma))


def student_t_g2_separable(wi: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                           alpha_y: RealArrayLike | None = None, *, gamma: RealArrayLike) -> Float64Array:
    """Separable masking-shadowing ``G2 = G1(wi) G1(wo)`` (``gamma`` as :func:`student_t_d`)."""
    return _two_directions(_core_mf.student_t_g2_separable, wi, wo, alpha_x, alpha_y,
                           shape=lambda: _student_t_gamma(gamma))


def student_t_g2_height_correlated(wi: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                                   alpha_y: RealArrayLike | None = None, *, gamma: RealArrayLike) -> Float64Array:
    """Height-correlated masking-shadowing ``G2 = 1 / (1 + Λ(wi) + Λ(wo))`` (Heitz 2014 eq. 99)
    (``gamma`` as :func:`student_t_d`)."""
    return _two_directions(_core_mf.student_t_g2_height_correlated, wi, wo, alpha_x, alpha_y,
                           shape=lambda: _student_t_gamma(gamma))


def student_t_pdf_visible(h: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                          alpha_y: RealArrayLike | None = None, *, gamma: RealArrayLike) -> Float64Array:
    """Density of visible normals, ``G1(wo) max(0, wo·h) D(h) / |wo·n|`` (Heitz 2014 eq. 38)
    (``gamma`` as :func:`student_t_d`);
    ``wo`` below the horizon is mirrored, 0 for a grazing ``wo``."""
    return _h_and_wo(_core_mf.student_t_pdf_visible, h, wo, alpha_x, alpha_y, shape=lambda: _student_t_gamma(gamma))

# --------------------------------------------------------------------------
# exponential-power slopes (Holzschuch & Pacanowski 2017)


def _exponential_power_p(p: RealArrayLike) -> Float64Array:
    return _in_range("p", p, *EXPONENTIAL_POWER_P_RANGE)


def exponential_power_d(h: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None, *,
                        p: RealArrayLike) -> Float64Array:
    """Exponential-power (generalised Gaussian) distribution of slopes (Holzschuch & Pacanowski 2017),
    shape ``p`` in [0.1, 10]::

        D = p exp(-r^(2p)) / (π Γ(1/p) αx αy cos⁴θh),   r² = ((h·x/αx)² + (h·y/αy)²) / (h·n)²

    ``p = 1`` is Beckmann.
    """
    return _one_direction(_core_mf.exponential_power_d, "h", h, alpha_x, alpha_y, shape=lambda: _exponential_power_p(p))


def exponential_power_pdf(h: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None, *,
                          p: RealArrayLike) -> Float64Array:
    """Density in solid angle of :func:`exponential_power_sample`: ``D(h) (h·n)``
    (``p`` as :func:`exponential_power_d`)."""
    return _one_direction(_core_mf.exponential_power_pdf, "h", h, alpha_x, alpha_y,
                          shape=lambda: _exponential_power_p(p))


def exponential_power_sample(u1: RealArrayLike, u2: RealArrayLike, alpha_x: RealArrayLike,
                             alpha_y: RealArrayLike | None = None, *, p: RealArrayLike) -> Float64Array:
    """Half vectors ``(..., 3)`` with density :func:`exponential_power_pdf`: the stretched slope
    radius ρ with ``ρ^(2p)`` Gamma(1/p)-distributed, by numerical inversion of the regularised
    incomplete gamma function (Halley's iteration to 1e-15 relative), azimuth ``2π u1``.

    ``u2 = 1`` gives the horizon. (No visible-normal sampler: none is known in closed form.)
    """
    return _sample(_core_mf.exponential_power_sample, u1, u2, alpha_x, alpha_y, shape=lambda: _exponential_power_p(p))


def exponential_power_lambda(w: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None, *,
                             p: RealArrayLike) -> Float64Array:
    """Smith Λ of the exponential-power slopes, ``a = |wz| / sqrt(αx² wx² + αy² wy²)``, by the
    one-dimensional integral of Smith's definition (Heitz 2014 eq. 72 in polar slope coordinates)::

        Λ(a) = (2/a) ∫_0^∞ f(sqrt(a² + t²)) (t - a atan(t/a)) t dt,   f(r) = p exp(-r^(2p)) / (π Γ(1/p))

    by 20-point Gauss-Legendre panels doubling in width out to where the integrand is
    below e^-60 of its start: within 3.4e-10 relative of a fine two-dimensional
    quadrature of Smith's definition (p in [0.3, 4], 5° to 89.9°), and at p = 1 within 2e-14 of
    Beckmann's erf form (6e-11 where Λ ~ 1e-250).

    Two-sided (reads ``|w·n|``); 0 at the normal, +inf at exactly grazing.
    """
    return _one_direction(_core_mf.exponential_power_lambda, "w", w, alpha_x, alpha_y,
                          shape=lambda: _exponential_power_p(p))


def exponential_power_g1(w: RealArrayLike, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None, *,
                         p: RealArrayLike) -> Float64Array:
    """Smith masking ``G1 = 1 / (1 + Λ(w))`` with :func:`exponential_power_lambda`
    (``p`` as :func:`exponential_power_d`)."""
    return _one_direction(_core_mf.exponential_power_g1, "w", w, alpha_x, alpha_y,
                          shape=lambda: _exponential_power_p(p))


def exponential_power_g2_separable(wi: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                                   alpha_y: RealArrayLike | None = None, *, p: RealArrayLike) -> Float64Array:
    """Separable masking-shadowing ``G2 = G1(wi) G1(wo)`` (``p`` as :func:`exponential_power_d`)."""
    return _two_directions(_core_mf.exponential_power_g2_separable, wi, wo, alpha_x, alpha_y,
                           shape=lambda: _exponential_power_p(p))


def exponential_power_g2_height_correlated(wi: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                                           alpha_y: RealArrayLike | None = None, *, p: RealArrayLike) -> Float64Array:
    """Height-correlated masking-shadowing ``G2 = 1 / (1 + Λ(wi) + Λ(wo))`` (Heitz 2014 eq. 99)
    (``p`` as :func:`exponential_power_d`)."""
    return _two_directions(_core_mf.exponential_power_g2_height_correlated, wi, wo, alpha_x, alpha_y,
                           shape=lambda: _exponential_power_p(p))


def exponential_power_pdf_visible(h: RealArrayLike, wo: RealArrayLike, alpha_x: RealArrayLike,
                                  alpha_y: RealArrayLike | None = None, *, p: RealArrayLike) -> Float64Array:
    """Density of visible normals, ``G1(wo) max(0, wo·h) D(h) / |wo·n|`` (Heitz 2014 eq. 38)
    (``p`` as :func:`exponential_power_d`);
    ``wo`` below the horizon is mirrored, 0 for a grazing ``wo``."""
    return _h_and_wo(_core_mf.exponential_power_pdf_visible, h, wo, alpha_x, alpha_y,
                     shape=lambda: _exponential_power_p(p))


# --------------------------------------------------------------------------
# the Gauss hypergeometric function


def hyp2f1(a: RealArrayLike, b: RealArrayLike, c: RealArrayLike, z: RealArrayLike) -> Float64Array:
    """The Gauss hypergeometric function 2F1(a, b; c; z) for the arguments the Student-t Λ needs.

    ``(a, c) = (1/2, 3/2)``, ``b > 1/2``, any ``z <= 0``: from whichever of two positive-term
    series is shorter, ``(1-z)^-b 2F1(1, b; 3/2; z/(z-1))`` (Pfaff, DLMF 15.8.1) or the
    incomplete-beta tail (DLMF 8.17.8), accurate to ~1e-14 relative (against mpmath, b up to 1e3
    and z down to -1e8). Any other ``(a, b, c)``: the defining series for ``|z| <= 1/2`` and
    Pfaff's transformation for ``z`` in [-1, -1/2); NaN elsewhere.
    """
    values = [_validate.as_real_array(name, value) for name, value in (("a", a), ("b", b), ("c", c), ("z", z))]
    for name, array in zip("abcz", values):
        _validate.require_in_domain(name, array, -np.inf, np.inf)
    return _run(_core_mf.hyp2f1, a=values[0], b=values[1], c=values[2], z=values[3])
