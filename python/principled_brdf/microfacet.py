"""Microfacet toolkit (docs/microfacet.md), float64: the distributions of the microfacet family as types.

Each distribution is an immutable object built from its parameters, with one method per
quantity (pbrt-v4's ``TrowbridgeReitzDistribution`` and Mitsuba 3's
``MicrofacetDistribution`` are shaped the same way):

- :class:`GGX` (anisotropic Trowbridge-Reitz, GTR2), :class:`Beckmann`,
  :class:`BlinnPhong`, :class:`StudentT` and :class:`ExponentialPower`, of roughness
  ``alpha_x`` (along the tangent ``x``) and ``alpha_y`` (along the bitangent ``y``;
  ``None``, the default, is ``alpha_x``: isotropic);
- :class:`GTR`, Burley 2012's generalized Trowbridge-Reitz (isotropic, ``alpha`` and
  ``gamma``).

The parameters are read-only properties (float64 arrays); setting one raises
``AttributeError``. Two distributions are equal when their type and the parameters in
effect are (``GGX(0.3) == GGX(0.3, 0.3)``); they hash, copy and pickle, and their
``repr`` shows the parameters as the constructor takes them.

The methods, named as the math:

===============================  ===  ========  ==========  ========  ================  ===
method                           GGX  Beckmann  BlinnPhong  StudentT  ExponentialPower  GTR
===============================  ===  ========  ==========  ========  ================  ===
``d(h)``                         yes  yes       yes         yes       yes               yes
``pdf(h)``                       yes  yes       yes         yes       yes               yes
``sample(u1, u2)``               yes  yes       yes         yes       yes               yes
``lambda_(w)``                   yes  yes       yes         yes       yes               --
``g1(w)``                        yes  yes       yes         yes       yes               --
``g2(wi, wo, correlated=True)``  yes  yes       yes         yes       yes               --
``pdf_visible(h, wo)``           yes  yes       yes         yes       yes               --
``sample_visible(wo, u1, u2)``   yes  yes       --          --        --                --
``g2_over_4cos(wi, wo)``         yes  --        --          --        --                --
===============================  ===  ========  ==========  ========  ================  ===

A method a family lacks ("--") is absent: reading it raises ``AttributeError`` with the
reason (GTR is not shape-invariant, so it has no Smith Λ; no visible-normal sampler is
known in closed form for Blinn-Phong, Student-t and exponential power), so
``hasattr(distribution, "sample_visible")`` tells whether a family has one.

Arguments: the half vectors ``h`` and directions ``w``, ``wi``, ``wo`` are ``(..., 3)``
unit vectors in the local frame ``n = z``, ``x`` tangent, ``y`` bitangent (never
cosines); they are checked to be of length 1 within 1e-3 and normalised before use.
The uniforms ``u1``, ``u2`` are numbers or arrays in [0, 1]. The parameters may be arrays
too: they are checked once, by the constructor, and broadcast numpy-style with the
arguments of every method (a direction contributes its leading shape ``(...)``). Every
method returns a new float64 array: ``(...)`` for values, ``(..., 3)`` for sampled half
vectors.

Domains (docs/bad-input.md: anything else raises ``ValueError``/``TypeError`` naming the
argument and its first offending element): GTR ``alpha`` in (0, 1] and ``gamma`` in
(0, 1e6]; GGX, Beckmann, Student-t and exponential-power ``alpha_x``, ``alpha_y`` > 0,
Blinn-Phong's in (0, 1]; Student-t ``gamma`` in (3/2, 1e12], exponential-power ``p`` in
[0.1, 10]. Roughness is clamped to at least ``MIN_ALPHA`` (and GGX/Beckmann to at most
``MAX_ALPHA``), which keeps every result finite and free of NaN; the only infinity is Λ
at exactly grazing angles (its true value) or within ~1e-298 of them (where its true
value exceeds the double range).

Each distribution ``D`` is zero for ``h·n <= 0`` and normalised,
``∫ D(h) (h·n) dω_h = 1``; ``pdf`` returns that density of ``h`` in solid angle,
``D(h) (h·n)``, which is what ``sample`` draws from.

Example::

    >>> import principled_brdf as pb
    >>> ggx = pb.microfacet.GGX(0.3, 0.1)
    >>> ggx
    GGX(alpha_x=0.3, alpha_y=0.1)
    >>> h = ggx.sample([0.2, 0.7], [0.5, 0.5])   # (2, 3) half vectors
    >>> ggx.pdf(h).shape
    (2,)
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

__all__ = [
    "GGX",
    "Beckmann",
    "BlinnPhong",
    "StudentT",
    "ExponentialPower",
    "GTR",
    "hyp2f1",
    "fresnel_dielectric",
    "fresnel_conductor",
    "refract",
    "generalized_half_vector",
    "refraction_jacobian",
    "ETA_RANGE",
    "MIN_ALPHA",
    "MAX_ALPHA",
    "MAX_GAMMA",
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
    return _frozen(array)


def _in_range(name: str, value: RealArrayLike, lower: float, upper: float) -> Float64Array:
    array = _validate.as_real_array(name, value)
    _validate.require_in_domain(name, array, lower, upper)
    return array


def _uniform(name: str, value: RealArrayLike) -> Float64Array:
    return _in_range(name, value, 0.0, 1.0)


def _frozen(array: Float64Array) -> Float64Array:
    """A read-only copy (a parameter must not change under the distribution that holds it)."""
    copy = np.array(array, dtype=np.float64)
    copy.setflags(write=False)
    return copy


def _student_t_gamma(gamma: RealArrayLike) -> Float64Array:
    array = _validate.as_real_array("gamma", gamma)
    _validate.require_in_domain("gamma", array, 1.5, MAX_STUDENT_T_GAMMA)
    bad = array <= 1.5
    if bad.any():
        i = _validate.first_true(bad)
        raise ValueError(f"{_validate.element_name('gamma', i, array.shape)}: {float(array.ravel()[i])!r} is outside "
                         f"its domain (1.5, {MAX_STUDENT_T_GAMMA:g}]")
    return _frozen(array)


def _beckmann_approximation(approximation: object) -> bool:
    """True for Walter's rational Λ, False for the exact one."""
    if approximation is None:
        return False
    if isinstance(approximation, str) and approximation == "walter":
        return True
    raise ValueError(f"approximation: expected None or 'walter', got {approximation!r}")


_GGX_VISIBILITY_FORMS = {None: 0, "karis": 1, "hammon": 2}


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


def _format(value: Float64Array) -> str:
    return repr(float(value)) if value.ndim == 0 else repr(np.asarray(value))


def _rebuild(cls: type[_Distribution], parameters: dict[str, object]) -> _Distribution:
    """Unpickling: the distribution from its constructor's arguments."""
    return cls(**parameters)


# --------------------------------------------------------------------------
# what the distributions share


class _Distribution:
    """Immutability, ``repr``, equality, pickling and the absent methods' ``AttributeError``."""

    __slots__ = ()
    # the methods a family lacks, each with the reason
    _ABSENT: typing.ClassVar[dict[str, str]] = {}

    def _parameters(self) -> dict[str, object]:
        """The constructor's arguments that rebuild this distribution (defaults left out)."""
        raise NotImplementedError

    def __setattr__(self, name: str, value: object) -> None:
        raise AttributeError(f"{type(self).__name__} is immutable: build a new one rather than set {name!r}")

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"{type(self).__name__} is immutable: cannot delete {name!r}")

    if not typing.TYPE_CHECKING:  # (a type checker reports the absent methods by itself)
        def __getattr__(self, name: str) -> typing.NoReturn:
            reason = type(self)._ABSENT.get(name)
            if reason is None:
                raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
            raise AttributeError(f"{type(self).__name__} has no {name}(): {reason}")

    def __repr__(self) -> str:
        shown = ", ".join(f"{name}={_format(value) if isinstance(value, np.ndarray) else repr(value)}"
                          for name, value in self._parameters().items())
        return f"{type(self).__name__}({shown})"

    def _values(self) -> dict[str, object]:
        """What equality compares: the parameters in effect."""
        return self._parameters()

    def _key(self) -> tuple[object, ...]:
        return tuple((name, value.shape, value.tobytes()) if isinstance(value, np.ndarray) else (name, value)
                     for name, value in self._values().items())

    def __eq__(self, other: object) -> bool:
        if type(other) is not type(self):
            return NotImplemented
        assert isinstance(other, _Distribution)
        return self._key() == other._key()

    def __hash__(self) -> int:
        return hash((type(self).__name__, self._key()))

    def __reduce__(self) -> tuple[object, ...]:
        return (_rebuild, (type(self), self._parameters()))


class _Anisotropic(_Distribution):
    """The families of roughness ``alpha_x``, ``alpha_y``: checks, properties and the methods they
    share, each calling the binding ``_core.microfacet.<_FAMILY>_<quantity>``."""

    __slots__ = ("_alpha_x", "_alpha_y", "_isotropic")
    _alpha_x: Float64Array
    _alpha_y: Float64Array
    _isotropic: bool
    _UPPER: typing.ClassVar[float] = np.inf  # the alphas' domain is (0, _UPPER]
    _FAMILY: typing.ClassVar[str]  # the prefix of the family's bindings in _core.microfacet

    def __init__(self, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None) -> None:
        ax = _positive("alpha_x", alpha_x, self._UPPER)
        ay = ax if alpha_y is None else _positive("alpha_y", alpha_y, self._UPPER)
        object.__setattr__(self, "_alpha_x", ax)
        object.__setattr__(self, "_alpha_y", ay)
        object.__setattr__(self, "_isotropic", alpha_y is None)

    @property
    def alpha_x(self) -> Float64Array:
        """Roughness along the tangent ``x`` (a read-only float64 array)."""
        return self._alpha_x

    @property
    def alpha_y(self) -> Float64Array:
        """Roughness along the bitangent ``y`` (``alpha_x`` when built isotropic)."""
        return self._alpha_y

    def _parameters(self) -> dict[str, object]:
        parameters: dict[str, object] = {"alpha_x": self._alpha_x}
        if not self._isotropic:
            parameters["alpha_y"] = self._alpha_y
        return parameters

    def _values(self) -> dict[str, object]:
        # GGX(0.3) is GGX(0.3, 0.3)
        return {"alpha_x": self._alpha_x, "alpha_y": self._alpha_y, **self._parameters()}

    def _shape_argument(self) -> dict[str, Float64Array]:
        """The shape argument of the family's bindings (none for GGX and Beckmann)."""
        return {}

    def _binding(self, quantity: str) -> _Core:
        """The family's binding of ``quantity``."""
        core_function: _Core = getattr(_core_mf, f"{self._FAMILY}_{quantity}")
        return core_function

    def _smith(self, quantity: str) -> tuple[_Core, dict[str, Float64Array] | None]:
        """The binding of a quantity of the Smith Λ in use, and its shape argument (``None``:
        the family's own)."""
        return self._binding(quantity), None

    def _call(self, core_function: _Core, directions: dict[str, RealArrayLike],
              uniforms: dict[str, RealArrayLike] | None = None, *, shape: dict[str, Float64Array] | None = None,
              flags: tuple[int, ...] = (), returns_vector: bool = False) -> Float64Array:
        """Checks the directions, then the uniforms, and calls the binding with them, the
        alphas and the shape argument, in that order."""
        arguments: dict[str, Float64Array | _Vector] = {
            name: _Vector(_validate.directions(name, value)) for name, value in directions.items()
        }
        arguments.update((name, _uniform(name, value)) for name, value in (uniforms or {}).items())
        arguments["alpha_x"], arguments["alpha_y"] = self._alpha_x, self._alpha_y
        arguments.update(self._shape_argument() if shape is None else shape)
        return _run(core_function, *flags, returns_vector=returns_vector, **arguments)

    def _sample_visible(self, wo: RealArrayLike, u1: RealArrayLike, u2: RealArrayLike) -> Float64Array:
        return self._call(self._binding("sample_visible"), {"wo": wo}, {"u1": u1, "u2": u2}, returns_vector=True)

    def d(self, h: RealArrayLike) -> Float64Array:
        """The distribution of normals ``D(h)`` (its formula is in the class's description),
        0 for ``h·n <= 0``.

        Parameters
        ----------
        h : array_like, shape (..., 3)
            Half vectors (unit, local frame).

        Returns
        -------
        numpy.ndarray
            ``D(h)``, float64, shape ``(...)``.
        """
        return self._call(self._binding("d"), {"h": h})

    def pdf(self, h: RealArrayLike) -> Float64Array:
        """Density in solid angle of :meth:`sample`: ``D(h) (h·n)``.

        Parameters
        ----------
        h : array_like, shape (..., 3)
            Half vectors (unit, local frame).

        Returns
        -------
        numpy.ndarray
            The density, float64, shape ``(...)``.
        """
        return self._call(self._binding("pdf"), {"h": h})

    def sample(self, u1: RealArrayLike, u2: RealArrayLike) -> Float64Array:
        """Half vectors with density :meth:`pdf` (the class's description gives the warp).

        Parameters
        ----------
        u1, u2 : float or array_like
            Uniforms in [0, 1].

        Returns
        -------
        numpy.ndarray
            Unit half vectors, float64, shape ``(..., 3)``.
        """
        return self._call(self._binding("sample"), {}, {"u1": u1, "u2": u2}, returns_vector=True)

    def lambda_(self, w: RealArrayLike) -> Float64Array:
        """Smith Λ of the family (its form and accuracy are in the class's description).

        0 at the normal, +inf at exactly grazing.

        Parameters
        ----------
        w : array_like, shape (..., 3)
            Directions (unit, local frame); two-sided (reads ``|w·n|``).

        Returns
        -------
        numpy.ndarray
            ``Λ(w)``, float64, shape ``(...)``.
        """
        core_function, shape = self._smith("lambda")
        return self._call(core_function, {"w": w}, shape=shape)

    def g1(self, w: RealArrayLike) -> Float64Array:
        """Smith masking ``G1 = 1 / (1 + Λ(w))`` with the Λ of :meth:`lambda_`.

        Parameters
        ----------
        w : array_like, shape (..., 3)
            Directions (unit, local frame).

        Returns
        -------
        numpy.ndarray
            ``G1(w)``, float64, shape ``(...)``.
        """
        core_function, shape = self._smith("g1")
        return self._call(core_function, {"w": w}, shape=shape)

    def g2(self, wi: RealArrayLike, wo: RealArrayLike, *, correlated: bool = True) -> Float64Array:
        """Smith masking-shadowing of the pair ``wi``, ``wo``, with the Λ of :meth:`lambda_`.

        Height-correlated by default, ``G2 = 1 / (1 + Λ(wi) + Λ(wo))`` (Heitz 2014 eq. 99);
        ``correlated=False``: the separable ``G2 = G1(wi) G1(wo)``.

        Parameters
        ----------
        wi, wo : array_like, shape (..., 3)
            Directions (unit, local frame).
        correlated : bool, optional
            ``True`` (default): height-correlated; ``False``: separable.

        Returns
        -------
        numpy.ndarray
            ``G2(wi, wo)``, float64, shape ``(...)``.
        """
        form = "g2_height_correlated" if _validate.flag("correlated", correlated) else "g2_separable"
        core_function, shape = self._smith(form)
        return self._call(core_function, {"wi": wi, "wo": wo}, shape=shape)

    def pdf_visible(self, h: RealArrayLike, wo: RealArrayLike) -> Float64Array:
        """Density of visible normals, ``G1(wo) max(0, wo·h) D(h) / |wo·n|`` (Heitz 2014 eq. 38).

        The density :meth:`sample_visible` draws, where the family has one. ``wo`` below the
        horizon is mirrored to ``-wo``.

        Parameters
        ----------
        h : array_like, shape (..., 3)
            Half vectors (unit, local frame).
        wo : array_like, shape (..., 3)
            The viewing direction (unit, local frame).

        Returns
        -------
        numpy.ndarray
            The density, float64, shape ``(...)``.
        """
        return self._call(self._binding("pdf_visible"), {"h": h, "wo": wo})


_NO_VISIBLE_SAMPLER = ("no visible-normal sampler is known in closed form for this family; sample() draws "
                       "D(h) (h·n) and pdf_visible() gives the density of visible normals")
_NO_VISIBILITY = "the combined G2 / (4 cos θi cos θo) and its approximations are GGX's (GGX.g2_over_4cos)"

_SAMPLE_VISIBLE_DOC = """Visible normals seen from ``wo``, with density :meth:`pdf_visible`.

        The class's description gives the method. A ``wo`` below the horizon is mirrored to
        ``-wo`` (two-sided use).

        Parameters
        ----------
        wo : array_like, shape (..., 3)
            The viewing direction (unit, local frame).
        u1, u2 : float or array_like
            Uniforms in [0, 1].

        Returns
        -------
        numpy.ndarray
            Unit half vectors, float64, shape ``(..., 3)``.
        """


# --------------------------------------------------------------------------
# anisotropic GGX (Trowbridge-Reitz, GTR2) and its Smith masking


class GGX(_Anisotropic):
    """Anisotropic GGX (Trowbridge-Reitz, GTR2; Burley 2012 appendix B eq. 13) with Smith masking.

    The distribution the model's specular lobe uses. Its normal distribution (appendix B
    eq. 13) is::

        D = 1 / (π αx αy ((h·x/αx)² + (h·y/αy)² + (h·n)²)²),  0 for h·n <= 0.

    :meth:`sample` draws it by the projected half vector, eq. (14)-(15)::

        h' = sqrt(u2/(1-u2)) (αx cos 2πu1 x + αy sin 2πu1 y) + n,   h = h'/|h'|

    Its Smith Λ (:meth:`lambda_`)::

        Λ(w) = (-1 + sqrt(1 + (αx² wx² + αy² wy²) / wz²)) / 2

    is evaluated as ``p² / (2|wz| (sqrt(wz² + p²) + |wz|))``, ``p² = αx² wx² + αy² wy²``: no
    cancellation and no overflow as ``wz -> 0``; +inf at exactly ``wz = 0``. So
    ``G1 = 2|wz| / (|wz| + sqrt(wz² + αx² wx² + αy² wy²))``, and the height-correlated
    :meth:`g2` is evaluated as ``2|zi||zo| / (|zi| ro + |zo| ri)``, ``r = sqrt(z² + αx² x² + αy² y²)``,
    0 when either direction is grazing (the model uses the separable one). In
    :meth:`pdf_visible`, ``G1 / |wo·n|`` is written
    ``2 / (|wo·n| + sqrt((wo·n)² + αx² wox² + αy² woy²))``, finite at grazing ``wo``.

    :meth:`sample_visible` follows Heitz 2018: ``wo`` is stretched to the α = 1
    configuration, a point is drawn on the projected visible hemisphere (disk radius
    ``sqrt(u2)``, angle ``2π u1``, warped towards the visible half), lifted and unstretched.

    Parameters
    ----------
    alpha_x : float or array_like
        Roughness along the tangent ``x``, > 0 (clamped to [``MIN_ALPHA``, ``MAX_ALPHA``]).
    alpha_y : float or array_like, optional
        Roughness along the bitangent ``y``, > 0; ``None`` (the default) is ``alpha_x``.

    Examples
    --------
    >>> import principled_brdf as pb
    >>> pb.microfacet.GGX(0.3, 0.1)
    GGX(alpha_x=0.3, alpha_y=0.1)
    >>> float(pb.microfacet.GGX(0.3).g1([0.0, 0.0, 1.0]))
    1.0
    """

    __slots__ = ()
    _FAMILY = "ggx"

    def __init__(self, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> None:
        super().__init__(alpha_x, alpha_y)

    def sample_visible(self, wo: RealArrayLike, u1: RealArrayLike, u2: RealArrayLike) -> Float64Array:
        return self._sample_visible(wo, u1, u2)

    sample_visible.__doc__ = _SAMPLE_VISIBLE_DOC

    def g2_over_4cos(self, wi: RealArrayLike, wo: RealArrayLike, *,
                     approximation: str | None = None) -> Float64Array:
        """The height-correlated ``G2 / (4 |n·wi| |n·wo|)``, the "visibility" V of real-time shading.

        Exact (default; Heitz 2014 eq. 99, the form of Lagarde & de Rousiers 2014)::

            V = 0.5 / (μo sqrt(α_i² (1 - μi²) + μi²) + μi sqrt(α_o² (1 - μo²) + μo²))

        with ``μ = |n·w|`` and ``α_i``, ``α_o`` the roughness projected on each direction
        (``sqrt((αx² wx² + αy² wy²) / (wx² + wy²))``, Heitz 2014 eq. 80; ``α`` itself when
        isotropic). ``approximation="karis"``: the separable Schlick-GGX of Karis 2013 (UE4
        course notes), ``G1 ≈ μ / (μ (1 - k) + k)`` with ``k = α/2``, so
        ``V ≈ 1 / (4 (μi (1-k) + k) (μo (1-k) + k))``. ``approximation="hammon"``: Hammon 2017
        (GDC), ``V ≈ 0.5 / lerp(2 μi μo, μi + μo, α)`` (anisotropically
        ``0.5 / (μo lerp(μi, 1, α_i) + μi lerp(μo, 1, α_o))``). Measured against the exact V
        over μ in [0.05, 1]² and α in [0.05, 1] (neither ever exceeds it): Karis's G1 is
        within 18.5% of the exact G1, but its separable V falls up to 82% below the
        height-correlated one (both directions grazing, α = 1); Hammon's V is within 27.6%
        (grazing directions at α = 0.05), within 1.3% at α = 0.95
        (``tests/microfacet/test_distribution_family.py`` asserts these).

        Parameters
        ----------
        wi, wo : array_like, shape (..., 3)
            Directions (unit, local frame).
        approximation : {None, "karis", "hammon"}, optional
            ``None`` (default): exact.

        Returns
        -------
        numpy.ndarray
            ``V``, float64, shape ``(...)``.
        """
        if approximation not in _GGX_VISIBILITY_FORMS:
            raise ValueError(f"approximation: expected None, 'karis' or 'hammon', got {approximation!r}")
        return self._call(_core_mf.ggx_g2_over_4cos, {"wi": wi, "wo": wo},
                          flags=(_GGX_VISIBILITY_FORMS[approximation],))


# --------------------------------------------------------------------------
# anisotropic Beckmann (Walter et al. 2007)


class Beckmann(_Anisotropic):
    """Anisotropic Beckmann (Walter et al. 2007), stretched as in Heitz 2014, with Smith masking.

    Its normal distribution is::

        D = exp(-((h·x/αx)² + (h·y/αy)²) / (h·n)²) / (π αx αy (h·n)⁴),  0 for h·n <= 0.

    :meth:`sample` draws it with Gaussian stretched slopes, ``u2 = 1`` giving the horizon::

        h ∝ sqrt(-ln(1 - u2)) (αx cos 2πu1 x + αy sin 2πu1 y) + n

    Its exact Smith Λ (Heitz 2014), the default::

        Λ = (erf(a) - 1) / 2 + exp(-a²) / (2 a sqrt(π)),   a = |wz| / sqrt(αx² wx² + αy² wy²)

    (``a = 1 / (α_o tan θ)``). ``approximation="walter"``: Walter et al. 2007 eq. 27's
    rational fit, as Λ, ``(1 - 1.259 a + 0.396 a²) / (3.535 a + 2.181 a²)`` for ``a < 1.6``,
    else 0: within 3.2e-3 of the exact G1 relatively (at most 3.13e-3, at a = 1.33), so within
    3.2e-3 (1 + Λ) of the exact Λ, and 1.8e-3 absolutely beyond the cut at a = 1.6.

    :meth:`sample_visible` follows Heitz & d'Eon 2014: ``wo`` is stretched to unit
    roughness; the visible slope along its azimuth is drawn by inverting its CDF
    ``(1 + erf(x) + tan θ exp(-x²)/√π) / (1 + erf(cot θ) + tan θ exp(-cot²θ)/√π)``
    numerically (Newton's iteration inside a bisection bracket, to 1e-15 in the CDF), the
    other slope is Gaussian; the slope is rotated to the azimuth and unstretched.
    :meth:`pdf_visible` is its density, with the exact Λ, 0 for a grazing ``wo``.

    Parameters
    ----------
    alpha_x : float or array_like
        Roughness along the tangent ``x``, > 0 (clamped to [``MIN_ALPHA``, ``MAX_ALPHA``]).
    alpha_y : float or array_like, optional
        Roughness along the bitangent ``y``, > 0; ``None`` (the default) is ``alpha_x``.
    approximation : {None, "walter"}, optional
        The Smith Λ of :meth:`lambda_`, :meth:`g1` and :meth:`g2`: ``None`` (default) the exact
        erf form, ``"walter"`` Walter et al. 2007 eq. 27's rational fit. :meth:`d`,
        :meth:`pdf`, :meth:`sample`, :meth:`pdf_visible` and :meth:`sample_visible` are
        exact either way (the visible-normal density stays the one its sampler draws).

    Examples
    --------
    >>> import principled_brdf as pb
    >>> pb.microfacet.Beckmann(0.3, approximation="walter")
    Beckmann(alpha_x=0.3, approximation='walter')
    """

    __slots__ = ("_walter",)
    _walter: bool
    _FAMILY = "beckmann"
    _ABSENT: typing.ClassVar[dict[str, str]] = {"g2_over_4cos": _NO_VISIBILITY}

    def __init__(self, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None, *,
                 approximation: str | None = None) -> None:
        super().__init__(alpha_x, alpha_y)
        object.__setattr__(self, "_walter", _beckmann_approximation(approximation))

    @property
    def approximation(self) -> str | None:
        """The Smith Λ in use: ``None`` (exact) or ``"walter"``."""
        return "walter" if self._walter else None

    def _parameters(self) -> dict[str, object]:
        parameters = super()._parameters()
        if self._walter:
            parameters["approximation"] = "walter"
        return parameters

    def _smith(self, quantity: str) -> tuple[_Core, dict[str, Float64Array] | None]:
        # Walter's bindings take a shape argument
        if self._walter:
            return self._binding(f"walter_{quantity}"), {"shape": _NO_SHAPE}
        return super()._smith(quantity)

    def sample_visible(self, wo: RealArrayLike, u1: RealArrayLike, u2: RealArrayLike) -> Float64Array:
        return self._sample_visible(wo, u1, u2)

    sample_visible.__doc__ = _SAMPLE_VISIBLE_DOC


# --------------------------------------------------------------------------
# Blinn-Phong (Blinn 1977) with Walter et al. 2007's exponent α_p = 2/α² - 2


class BlinnPhong(_Anisotropic):
    """Blinn-Phong with Walter et al. 2007's exponent ``α_p = 2/α² - 2``, anisotropic as Ashikhmin & Shirley 2000.

    ``alpha`` means what it means for Beckmann; its normal distribution is::

        D = cos^e θh / (π αx αy),   e = (2/αx² - 2) cos²φh + (2/αy² - 2) sin²φh

    (isotropically ``(α_p + 2) / (2π) cos^α_p θh``), 0 for ``h·n <= 0``. :meth:`sample` draws
    it as Ashikhmin & Shirley 2000, ``u2 = 1`` giving the horizon::

        φh = azimuth of (αx cos 2πu1, αy sin 2πu1),   cos θh = u2^(1/(e(φh) + 2))

    Blinn-Phong is not shape-invariant and has no exact Smith Λ: :meth:`lambda_` is
    Beckmann's exact Λ at the same alphas (Walter et al. 2007 §5.2), an approximation, good
    for smooth surfaces only: against the Smith G1 of Blinn-Phong's own D, G1 is off by 2e-5
    at α = 0.05, 2e-2 at 0.3, 0.13 at 0.6 and 0.64 at 1 (85° views), and the weak white
    furnace misses 1 by 3e-4, 3e-2, 0.15 and 0.73 (88° views; checked in
    ``tests/microfacet/test_distribution_family.py``). With it :meth:`pdf_visible` integrates
    to 1 only approximately (3e-2 at α = 0.4). No visible-normal sampler (none is known in
    closed form): no ``sample_visible``.

    Parameters
    ----------
    alpha_x : float or array_like
        Roughness along the tangent ``x``, in (0, 1].
    alpha_y : float or array_like, optional
        Roughness along the bitangent ``y``, in (0, 1]; ``None`` (the default) is ``alpha_x``.

    Examples
    --------
    >>> import principled_brdf as pb
    >>> pb.microfacet.BlinnPhong(0.5)
    BlinnPhong(alpha_x=0.5)
    """

    __slots__ = ()
    _UPPER = 1.0
    _FAMILY = "blinn_phong"
    _ABSENT: typing.ClassVar[dict[str, str]] = {"sample_visible": _NO_VISIBLE_SAMPLER, "g2_over_4cos": _NO_VISIBILITY}

    def __init__(self, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None) -> None:
        super().__init__(alpha_x, alpha_y)

    def _shape_argument(self) -> dict[str, Float64Array]:
        return {"shape": _NO_SHAPE}


# --------------------------------------------------------------------------
# Student-t slopes (Ribardière et al. 2017)


class StudentT(_Anisotropic):
    """The Student-t distribution of slopes (Ribardière et al. 2017), shape ``gamma`` = γ > 3/2.

    γ = 2 is GGX; γ -> ∞ is Beckmann (the difference falls as 1/γ). Its normal distribution is::

        D = (γ-1)^γ / (π αx αy cos⁴θh ((γ-1) + r²)^γ),   r² = ((h·x/αx)² + (h·y/αy)²) / (h·n)²

    0 for ``h·n <= 0``. :meth:`sample` draws the stretched slope radius in closed form,
    ``ρ² = (γ-1) ((1-u2)^(-1/(γ-1)) - 1)`` (the inverse of its CDF
    ``1 - (1 + ρ²/(γ-1))^(1-γ)``), azimuth ``2π u1``; ``u2 = 1`` gives the horizon.

    Its Smith Λ, with ``a = |wz| / sqrt(αx² wx² + αy² wy²)``::

        Λ = Γ(γ-1/2) / (Γ(γ) sqrt(π)) ((γ-1)^γ / (2γ-3) S1 + sqrt(γ-1) S2) - 1/2,
        S1 = ((γ-1) + a²)^(3/2-γ) / a,   S2 = a 2F1(1/2, γ-1/2; 3/2; -a²/(γ-1))

    with 2F1 by :func:`hyp2f1` and ``1/2 - ... S2`` taken as the incomplete-beta tail where
    it would cancel: against the closed form in 30-digit mpmath, below 1e-12 relative for
    γ <= 20; at large γ the two terms cancel where Λ is small, leaving ~1e-15 absolutely
    (3e-6 relative at γ = 300, Λ = 4e-10). :meth:`pdf_visible` is 0 for a grazing ``wo``.
    No visible-normal sampler (none is known in closed form): no ``sample_visible``.

    Parameters
    ----------
    alpha_x : float or array_like
        Roughness along the tangent ``x``, > 0.
    alpha_y : float or array_like, optional
        Roughness along the bitangent ``y``, > 0; ``None`` (the default) is ``alpha_x``.
    gamma : float or array_like
        The shape γ, in (3/2, ``MAX_STUDENT_T_GAMMA``] (keyword only).

    Examples
    --------
    >>> import principled_brdf as pb
    >>> pb.microfacet.StudentT(0.3, gamma=2.0)
    StudentT(alpha_x=0.3, gamma=2.0)
    """

    __slots__ = ("_gamma",)
    _gamma: Float64Array
    _FAMILY = "student_t"
    _ABSENT: typing.ClassVar[dict[str, str]] = {"sample_visible": _NO_VISIBLE_SAMPLER, "g2_over_4cos": _NO_VISIBILITY}

    def __init__(self, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None, *,
                 gamma: RealArrayLike) -> None:
        super().__init__(alpha_x, alpha_y)
        object.__setattr__(self, "_gamma", _student_t_gamma(gamma))

    @property
    def gamma(self) -> Float64Array:
        """The shape γ (a read-only float64 array)."""
        return self._gamma

    def _parameters(self) -> dict[str, object]:
        return {**super()._parameters(), "gamma": self._gamma}

    def _shape_argument(self) -> dict[str, Float64Array]:
        return {"gamma": self._gamma}


# --------------------------------------------------------------------------
# exponential-power slopes (Holzschuch & Pacanowski 2017)


class ExponentialPower(_Anisotropic):
    """The exponential-power (generalised Gaussian) distribution of slopes (Holzschuch & Pacanowski 2017).

    Shape ``p`` in [0.1, 10]; ``p = 1`` is Beckmann. Its normal distribution is::

        D = p exp(-r^(2p)) / (π Γ(1/p) αx αy cos⁴θh),   r² = ((h·x/αx)² + (h·y/αy)²) / (h·n)²

    0 for ``h·n <= 0``. :meth:`sample` draws it by numerical inversion: the stretched slope
    radius ρ has ``ρ^(2p)`` Gamma(1/p)-distributed; it is drawn by inverting the regularised
    incomplete gamma function (Halley's iteration to 1e-15 relative), azimuth ``2π u1``;
    ``u2 = 1`` gives the horizon.

    Its Smith Λ is computed by quadrature of Smith's definition: with
    ``a = |wz| / sqrt(αx² wx² + αy² wy²)``, the one-dimensional integral (Heitz 2014 eq. 72 in
    polar slope coordinates)::

        Λ(a) = (2/a) ∫_0^∞ f(sqrt(a² + t²)) (t - a atan(t/a)) t dt,   f(r) = p exp(-r^(2p)) / (π Γ(1/p))

    by 20-point Gauss-Legendre panels doubling in width out to where the integrand is
    below e^-60 of its start: within 3.4e-10 relative of a fine two-dimensional quadrature
    of Smith's definition (p in [0.3, 4], 5° to 89.9°), and at p = 1 within 2e-14 of
    Beckmann's erf form (6e-11 where Λ ~ 1e-250). :meth:`pdf_visible` is 0 for a grazing
    ``wo``. No visible-normal sampler (none is known in closed form): no ``sample_visible``.

    Parameters
    ----------
    alpha_x : float or array_like
        Roughness along the tangent ``x``, > 0.
    alpha_y : float or array_like, optional
        Roughness along the bitangent ``y``, > 0; ``None`` (the default) is ``alpha_x``.
    p : float or array_like
        The shape, in ``EXPONENTIAL_POWER_P_RANGE`` = [0.1, 10] (keyword only).

    Examples
    --------
    >>> import principled_brdf as pb
    >>> pb.microfacet.ExponentialPower(0.3, 0.1, p=0.5)
    ExponentialPower(alpha_x=0.3, alpha_y=0.1, p=0.5)
    """

    __slots__ = ("_p",)
    _p: Float64Array
    _FAMILY = "exponential_power"
    _ABSENT: typing.ClassVar[dict[str, str]] = {"sample_visible": _NO_VISIBLE_SAMPLER, "g2_over_4cos": _NO_VISIBILITY}

    def __init__(self, alpha_x: RealArrayLike, alpha_y: RealArrayLike | None = None, *, p: RealArrayLike) -> None:
        super().__init__(alpha_x, alpha_y)
        object.__setattr__(self, "_p", _frozen(_in_range("p", p, *EXPONENTIAL_POWER_P_RANGE)))

    @property
    def p(self) -> Float64Array:
        """The shape ``p`` (a read-only float64 array)."""
        return self._p

    def _parameters(self) -> dict[str, object]:
        return {**super()._parameters(), "p": self._p}

    def _shape_argument(self) -> dict[str, Float64Array]:
        return {"p": self._p}


# --------------------------------------------------------------------------
# GTR (Burley 2012 appendix B)

_NOT_SHAPE_INVARIANT = ("GTR is not shape-invariant (changing α is not a stretch of its slopes), so its Smith Λ "
                        "has no closed form and none is offered (docs/model.md \"The microfacet family\"); GGX is "
                        "GTR at γ = 2 with Smith masking")


class GTR(_Distribution):
    """Burley 2012's generalized Trowbridge-Reitz distribution (appendix B), isotropic, for any γ > 0.

    ``γ = 1`` is the clearcoat's GTR1, ``γ = 2`` is GGX. GTR is not shape-invariant (changing
    α is not a stretch of its slopes), so its Smith Λ has no closed form: it has :meth:`d`,
    :meth:`pdf` and :meth:`sample` only (no ``lambda_``, ``g1``, ``g2``, ``pdf_visible`` or
    ``sample_visible``; see docs/model.md "The microfacet family").

    Parameters
    ----------
    alpha : float or array_like
        Roughness, in (0, 1].
    gamma : float or array_like
        The exponent γ, in (0, ``MAX_GAMMA``].
    closed_forms : bool, optional
        ``True`` (default): γ = 1, 3/2 and 2 use appendix B's closed forms, eq. (4), (6), (8)
        (and (5), (7), (9) to sample); ``False``: the general form serves every γ.

    Examples
    --------
    >>> import principled_brdf as pb
    >>> pb.microfacet.GTR(0.2, 1.5)
    GTR(alpha=0.2, gamma=1.5)
    """

    __slots__ = ("_alpha", "_gamma", "_closed_forms")
    _alpha: Float64Array
    _gamma: Float64Array
    _closed_forms: bool
    _ABSENT: typing.ClassVar[dict[str, str]] = {
        "lambda_": _NOT_SHAPE_INVARIANT, "g1": _NOT_SHAPE_INVARIANT, "g2": _NOT_SHAPE_INVARIANT,
        "pdf_visible": _NOT_SHAPE_INVARIANT, "sample_visible": _NOT_SHAPE_INVARIANT, "g2_over_4cos": _NO_VISIBILITY,
    }

    def __init__(self, alpha: RealArrayLike, gamma: RealArrayLike, *, closed_forms: bool = True) -> None:
        object.__setattr__(self, "_alpha", _positive("alpha", alpha, 1.0))
        object.__setattr__(self, "_gamma", _positive("gamma", gamma, MAX_GAMMA))
        object.__setattr__(self, "_closed_forms", _validate.flag("closed_forms", closed_forms))

    @property
    def alpha(self) -> Float64Array:
        """Roughness α (a read-only float64 array)."""
        return self._alpha

    @property
    def gamma(self) -> Float64Array:
        """The exponent γ (a read-only float64 array)."""
        return self._gamma

    @property
    def closed_forms(self) -> bool:
        """Whether γ = 1, 3/2 and 2 use their closed forms."""
        return self._closed_forms

    def _parameters(self) -> dict[str, object]:
        parameters: dict[str, object] = {"alpha": self._alpha, "gamma": self._gamma}
        if not self._closed_forms:
            parameters["closed_forms"] = False
        return parameters

    def d(self, h: RealArrayLike) -> Float64Array:
        """The distribution of normals D(θh), appendix B eq. (1).

        Of ``cos θh = h·n`` (``h`` normalised first)::

            D = (γ-1)(α²-1) / (π (1 - (α²)^(1-γ))) / (1 + (α²-1) cos²θh)^γ

        for any γ > 0, 0 for ``h·n <= 0``. The limits are built in: γ = 1 gives eq. (4)
        ``(α²-1) / (π ln α² (1 + (α²-1) cos²θh))``, α = 1 gives 1/π. With ``closed_forms``
        γ = 1, 3/2 and 2 use eq. (4), (6) ``(α²+α) / (2π (1 + (α²-1) cos²θh)^(3/2))`` and (8)
        ``α² / (π (1 + (α²-1) cos²θh)²)``. :meth:`pdf` reads ``sin²θh`` from the components
        of ``h`` as well, which keeps narrow peaks accurate.

        Parameters
        ----------
        h : array_like, shape (..., 3)
            Half vectors (unit, local frame).

        Returns
        -------
        numpy.ndarray
            ``D(h)``, float64, shape ``(...)``.
        """
        hv = _validate.directions("h", h)
        cos_theta_h = np.clip(hv[..., 2] / np.sqrt(np.sum(hv * hv, axis=-1)), -1.0, 1.0)
        return _run(_core_mf.gtr_d, self._closed_forms, cos_theta_h=cos_theta_h, alpha=self._alpha,
                    gamma=self._gamma)

    def pdf(self, h: RealArrayLike) -> Float64Array:
        """Density in solid angle of :meth:`sample`: ``D(h) (h·n)``.

        ``cos²θh`` and ``sin²θh`` are taken from the components of ``h``, so narrow peaks stay
        accurate where ``1 - cos²θh`` would cancel.

        Parameters
        ----------
        h : array_like, shape (..., 3)
            Half vectors (unit, local frame).

        Returns
        -------
        numpy.ndarray
            The density, float64, shape ``(...)``.
        """
        hv = _validate.directions("h", h)
        return _run(_core_mf.gtr_pdf, self._closed_forms, h=_Vector(hv), alpha=self._alpha, gamma=self._gamma)

    def sample(self, u1: RealArrayLike, u2: RealArrayLike) -> Float64Array:
        """Half vectors with density :meth:`pdf`, appendix B eq. (2)-(3).

        The warp::

            φ = 2π u1,  cos θh = sqrt((1 - [(α²)^(1-γ)(1-u2) + u2]^(1/(1-γ))) / (1 - α²))

        (eq. (5), (7), (9) at γ = 1, 3/2, 2), evaluated with expm1/log1p so that it is accurate
        near γ = 1 and α = 1; ``u2 = 1`` gives the horizon.

        Parameters
        ----------
        u1, u2 : float or array_like
            Uniforms in [0, 1].

        Returns
        -------
        numpy.ndarray
            Unit half vectors, float64, shape ``(..., 3)``.
        """
        v1 = _uniform("u1", u1)
        v2 = _uniform("u2", u2)
        return _run(_core_mf.gtr_sample, self._closed_forms, returns_vector=True, u1=v1, u2=v2, alpha=self._alpha,
                    gamma=self._gamma)


# --------------------------------------------------------------------------
# the Gauss hypergeometric function


def hyp2f1(a: RealArrayLike, b: RealArrayLike, c: RealArrayLike, z: RealArrayLike) -> Float64Array:
    """The Gauss hypergeometric function 2F1(a, b; c; z) for the arguments the Student-t Λ needs.

    ``(a, c) = (1/2, 3/2)``, ``b > 1/2``, any ``z <= 0``: from whichever of two positive-term
    series is shorter, ``(1-z)^-b 2F1(1, b; 3/2; z/(z-1))`` (Pfaff, DLMF 15.8.1) or the
    incomplete-beta tail (DLMF 8.17.8), accurate to ~1e-14 relative (against mpmath, b up to 1e3
    and z down to -1e8). Any other ``(a, b, c)``: the defining series for ``|z| <= 1/2`` and
    Pfaff's transformation for ``z`` in [-1, -1/2); NaN elsewhere.

    Parameters
    ----------
    a, b, c, z : float or array_like
        Finite real numbers, broadcast together.

    Returns
    -------
    numpy.ndarray
        2F1(a, b; c; z), float64.
    """
    values = [_validate.as_real_array(name, value) for name, value in (("a", a), ("b", b), ("c", c), ("z", z))]
    for name, array in zip("abcz", values):
        _validate.require_in_domain(name, array, -np.inf, np.inf)
    return _run(_core_mf.hyp2f1, a=values[0], b=values[1], c=values[2], z=values[3])


# --------------------------------------------------------------------------
# interfaces: the Fresnel factors and the geometry of refraction
#
# The interface is the tangent plane, normal n = (0, 0, 1); ``eta`` is the relative
# index of refraction, the index of the far side over that of the near side, within
# ETA_RANGE (beyond it 1/η² leaves the double range's comfortable middle for no physical use).

ETA_RANGE = (1e-6, 1e6)


def _cosines(cos_theta: RealArrayLike) -> Float64Array:
    array = _validate.as_real_array("cos_theta", cos_theta)
    _validate.require_in_domain("cos_theta", array, -1.0, 1.0)
    return array


def _eta(eta: RealArrayLike) -> Float64Array:
    return _in_range("eta", eta, ETA_RANGE[0], ETA_RANGE[1])


def fresnel_dielectric(cos_theta: RealArrayLike, eta: RealArrayLike) -> Float64Array:
    """The unpolarised Fresnel reflectance of a smooth dielectric interface, exact.

    With ``c = |cos_theta|`` and ``cos²θt = 1 - (1 - c²) / η²`` (Snell's law),
    ``rs = (c - η cos θt) / (c + η cos θt)``, ``rp = (η c - cos θt) / (η c + cos θt)`` and
    ``F = (rs² + rp²) / 2`` (Walter et al. 2007 eq. 22); ``F = 1`` under total internal
    reflection (``η < 1`` beyond the critical angle). It is the model's own Fresnel factor.

    Parameters
    ----------
    cos_theta : float or array_like
        Cosine between the direction and the interface's normal, in [-1, 1] (the light
        arrives from the near side whatever its sign).
    eta : float or array_like
        Relative index of refraction, in ``ETA_RANGE`` (1.5: air to glass; 1/1.5: glass to air).

    Returns
    -------
    numpy.ndarray
        F in [0, 1], float64, the broadcast shape of the arguments.
    """
    return _run(_core_mf.fresnel_dielectric, cos_theta=_cosines(cos_theta), eta=_eta(eta))


def fresnel_conductor(cos_theta: RealArrayLike, eta: RealArrayLike, k: RealArrayLike) -> Float64Array:
    """The unpolarised Fresnel reflectance of a conductor of complex index ``eta + i k``.

    As :func:`fresnel_dielectric` with a complex index ``n = η + ik``:
    ``cos θt = sqrt(1 - (1 - c²) / n²)``, ``rs = (c - n cos θt) / (c + n cos θt)``,
    ``rp = (n c - cos θt) / (n c + cos θt)``, ``F = (|rs|² + |rp|²) / 2``. Per channel: pass
    RGB arrays of ``eta`` and ``k`` (e.g. measured indices of gold) for an RGB ``F``.

    Parameters
    ----------
    cos_theta : float or array_like
        Cosine between the direction and the normal, in [-1, 1].
    eta : float or array_like
        Real part of the relative index, in ``ETA_RANGE``.
    k : float or array_like
        Extinction coefficient, >= 0 (0 gives :func:`fresnel_dielectric`).

    Returns
    -------
    numpy.ndarray
        F in [0, 1], float64.
    """
    extinction = _validate.as_real_array("k", k)
    _validate.require_in_domain("k", extinction, 0.0, 1e10)
    return _run(_core_mf.fresnel_conductor, cos_theta=_cosines(cos_theta), eta=_eta(eta),
                k=extinction)


def refract(w: RealArrayLike, eta: RealArrayLike) -> Float64Array:
    """The direction refracted from ``w`` through the interface (Snell's law).

    ``wt = -w / η + (c / η - cos θt) sign(w·n) n`` with ``c = |w·n|``: a unit vector on the
    far side, its azimuth opposite to ``w``'s (both point away from the surface). Zero
    under total internal reflection.

    Parameters
    ----------
    w : array_like
        Unit directions ``(..., 3)`` on the near side, pointing away from the surface.
    eta : float or array_like
        Relative index of refraction, in ``ETA_RANGE``.

    Returns
    -------
    numpy.ndarray
        ``(..., 3)`` float64.
    """
    return _run(_core_mf.refract, returns_vector=True, w=_Vector(_validate.directions("w", w)),
                eta=_eta(eta))


def generalized_half_vector(wi: RealArrayLike, wo: RealArrayLike, eta: RealArrayLike) -> Float64Array:
    """The generalized half vector of a pair, ``h = normalize(wo + η wi)`` turned to ``h·n >= 0``.

    Each direction is weighted by the index of its own side (Walter et al. 2007 eq. 16):
    ``eta`` is the index on ``wi``'s side over that on ``wo``'s. For a reflection
    (``eta = 1``) it is the usual half vector; for a refraction it is the microfacet normal
    that refracts one direction into the other. Zero where ``wo + η wi = 0``.

    Parameters
    ----------
    wi, wo : array_like
        Unit directions ``(..., 3)``.
    eta : float or array_like
        Index on ``wi``'s side over that on ``wo``'s, in ``ETA_RANGE``.

    Returns
    -------
    numpy.ndarray
        ``(..., 3)`` float64 unit vectors.
    """
    return _run(_core_mf.generalized_half_vector, returns_vector=True, wi=_Vector(_validate.directions("wi", wi)),
                wo=_Vector(_validate.directions("wo", wo)), eta=_eta(eta))


def refraction_jacobian(wi: RealArrayLike, wo: RealArrayLike, eta: RealArrayLike) -> Float64Array:
    """``dω_h / dω_i`` of refraction: ``η² |wi·h| / (wo·h + η wi·h)²`` (Walter et al. 2007 eq. 17).

    ``h`` is :func:`generalized_half_vector` of the pair. A density of half vectors times
    it is the density of the refracted direction ``wi``: the transmission pdf.

    Parameters
    ----------
    wi, wo : array_like
        Unit directions ``(..., 3)``, on opposite sides of the interface.
    eta : float or array_like
        Index on ``wi``'s side over that on ``wo``'s, in ``ETA_RANGE``.

    Returns
    -------
    numpy.ndarray
        ``(...)`` float64; +inf where the denominator vanishes.
    """
    return _run(_core_mf.refraction_jacobian, wi=_Vector(_validate.directions("wi", wi)),
                wo=_Vector(_validate.directions("wo", wo)), eta=_eta(eta))
