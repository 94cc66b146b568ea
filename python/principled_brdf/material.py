"""The material: the 14 parameters of docs/model.md, "The model", and docs/model-2015.md, each uniform or per element."""

from __future__ import annotations

import warnings
from typing import TYPE_CHECKING

import numpy as np

from . import _color, _core, _models
from ._models import MAX_BSDF_SPECULAR, MAX_IOR, unread_parameters  # noqa: F401 - principled_brdf.material's names too
from ._segments import unexpanded
from ._validate import as_real_array, broadcast_leading, element_name, first_true, flag, require_in_domain

if TYPE_CHECKING:
    from collections.abc import Callable, Sequence
    from typing import NoReturn, SupportsIndex

    from numpy.typing import NDArray

    from ._typing import Float32Array, Float64Array, Index, RealArrayLike


class _ParamInfo:
    __slots__ = ("name", "first_slot", "slots", "default", "lower", "upper")

    name: str
    first_slot: int
    slots: int
    default: float | tuple[float, ...]  # a number, or base_color's three
    lower: float
    upper: float

    def __init__(self, name: str, first_slot: int, slots: int, default: tuple[float, ...], lower: float,
                 upper: float) -> None:
        self.name, self.first_slot, self.slots = name, first_slot, slots
        self.default = default[0] if slots == 1 else tuple(default)
        self.lower, self.upper = lower, upper


# Names, defaults and domains come from the C++ table (params.hpp), defined once.
PARAMETERS = {row[0]: _ParamInfo(*row) for row in _core.PARAMETER_TABLE}


def _owned_copy(array: Float64Array) -> Float64Array:
    """A read-only copy of ``array``; a broadcast view (stride-0 axes, np.broadcast_to)
    stays one, over a copy of the values it holds, never expanded."""
    values = unexpanded(array)
    if values.shape != array.shape:
        return np.broadcast_to(values.copy(), array.shape)  # (read-only)
    copy = array.copy()
    copy.flags.writeable = False
    return copy


class Material:
    """Disney principled BRDF parameters (docs/model.md, "The model").

    Each parameter is a number or an array broadcastable to the directions'
    leading shape; ``base_color`` is linear RGB, shape ``(3,)`` or ``(..., 3)``.
    Values are checked on construction: out of domain, NaN or infinite values
    raise ``ValueError`` naming the parameter and the first bad element.
    ``ior=`` (keyword, instead of ``specular``) sets ``specular`` from an index of
    refraction (:func:`specular_of_ior`); :attr:`ior` reads it back. It is not a
    second stored parameter.

    ``spec_trans``, ``flatness`` and ``diff_trans`` are read by the 2015 models
    only (docs/model-2015.md); a model refuses a parameter it does not read
    unless it is at its default (:meth:`require_read_by`).
    """

    __slots__ = tuple(PARAMETERS) + ("_shape", "_float32_cache", "_kernel_numbers")

    # The parameters as given, float64 and read-only: base_color (3,) or (..., 3), the others () or (...).
    base_color: Float64Array
    metallic: Float64Array
    subsurface: Float64Array
    specular: Float64Array
    specular_tint: Float64Array
    roughness: Float64Array
    anisotropic: Float64Array
    sheen: Float64Array
    sheen_tint: Float64Array
    clearcoat: Float64Array
    clearcoat_gloss: Float64Array
    spec_trans: Float64Array
    flatness: Float64Array
    diff_trans: Float64Array
    _shape: tuple[int, ...]
    _float32_cache: dict[tuple[str, tuple[int, ...] | None], Float32Array]
    # the SIMD kernels' per-parameter entry (a number, base_color's three, or None
    # when per element), set by the first SIMD call after its float32 range check
    _kernel_numbers: list[float | tuple[float, ...] | None] | None

    def __init__(
        self,
        base_color: RealArrayLike = PARAMETERS["base_color"].default,
        metallic: RealArrayLike = PARAMETERS["metallic"].default,
        subsurface: RealArrayLike = PARAMETERS["subsurface"].default,
        specular: RealArrayLike = PARAMETERS["specular"].default,
        specular_tint: RealArrayLike = PARAMETERS["specular_tint"].default,
        roughness: RealArrayLike = PARAMETERS["roughness"].default,
        anisotropic: RealArrayLike = PARAMETERS["anisotropic"].default,
        sheen: RealArrayLike = PARAMETERS["sheen"].default,
        sheen_tint: RealArrayLike = PARAMETERS["sheen_tint"].default,
        clearcoat: RealArrayLike = PARAMETERS["clearcoat"].default,
        clearcoat_gloss: RealArrayLike = PARAMETERS["clearcoat_gloss"].default,
        spec_trans: RealArrayLike = PARAMETERS["spec_trans"].default,
        flatness: RealArrayLike = PARAMETERS["flatness"].default,
        diff_trans: RealArrayLike = PARAMETERS["diff_trans"].default,
        *,
        ior: RealArrayLike | None = None,
        bright_base_color: bool = False,
    ) -> None:
        if ior is not None:
            if specular is not PARAMETERS["specular"].default:
                raise ValueError("ior: give specular or ior, not both (ior sets specular)")
            specular = specular_of_ior(ior)
        values = dict(locals())
        for name, info in PARAMETERS.items():
            if name == "base_color" and isinstance(values[name], np.ndarray) and values[name].dtype == np.uint8:
                raise TypeError("base_color: a uint8 color (0-255) is not linear RGB; convert it explicitly, "
                                "e.g. pb.srgb_to_linear(texture), which scales uint8 by 1/255")
            array = as_real_array(name, values[name])
            if info.slots == 3 and (array.ndim == 0 or array.shape[-1] != 3):
                raise ValueError(f"{name}: expected an RGB triple, shape (3,) or (..., 3), got shape {array.shape}")
            require_in_domain(name, array, info.lower, info.upper)
            array = _owned_copy(array)  # a Material never aliases the caller's buffers
            object.__setattr__(self, name, array)
        object.__setattr__(self, "_float32_cache", {})
        object.__setattr__(self, "_kernel_numbers", None)
        # raises now if the parameters' shapes do not broadcast; kept, as the parameters never change
        object.__setattr__(self, "_shape", broadcast_leading(**{name: self._leading_shape(name) for name in PARAMETERS}))
        if not flag("bright_base_color", bright_base_color) and self.base_color.size and self.base_color.max() > 1.0:
            warnings.warn(f"base_color: {self.base_color.max():g} > 1 reflects more than it receives (a 0-255 or "
                          "display-encoded color?); pass bright_base_color=True if it is meant", BrightColorWarning,
                          stacklevel=2)

    def __setattr__(self, name: str, value: object) -> NoReturn:
        raise AttributeError("Material is immutable; build a new one (or use Material.replace)")

    def __delattr__(self, name: str) -> NoReturn:
        raise AttributeError("Material is immutable; build a new one (or use Material.replace)")

    @property
    def shape(self) -> tuple[int, ...]:
        """Leading shape the per-element parameters broadcast to (``()`` if all uniform)."""
        return self._shape

    @property
    def ior(self) -> Float64Array:
        """The index of refraction that ``specular`` stands for, ``η = 2 / (1 - sqrt(0.08 specular)) - 1``
        (``((η - 1)/(η + 1))² = 0.08 specular``: 0.5 is 1.5); +inf from ``specular`` 12.5 on."""
        root = np.sqrt(0.08 * self.specular)
        with np.errstate(divide="ignore"):
            return np.where(root < 1.0, 2.0 / (1.0 - np.minimum(root, 1.0)) - 1.0, np.inf)

    @property
    def is_uniform(self) -> bool:
        return self.shape == ()

    def _leading_shape(self, name: str) -> tuple[int, ...]:
        array: Float64Array = getattr(self, name)
        return array.shape[:-1] if PARAMETERS[name].slots == 3 else array.shape

    def replace(self, **changes: RealArrayLike) -> Material:
        """A copy with some parameters changed (``ior=`` changes ``specular``)."""
        if "ior" in changes:
            if "specular" in changes:
                raise ValueError("ior: give specular or ior, not both (ior sets specular)")
            changes["specular"] = specular_of_ior(changes.pop("ior"))
        unknown = set(changes) - set(PARAMETERS)
        if unknown:
            raise TypeError(f"unknown parameter(s): {', '.join(sorted(unknown))}")
        # a bright base_color kept from self was reported when self was made
        return Material(**{**self.as_dict(), **changes}, bright_base_color="base_color" not in changes)

    def _per_element(self, transform: Callable[[Float64Array], Float64Array]) -> Material:
        """A material whose per-element parameters are ``transform(array broadcast to the
        leading shape + its trailing shape, trailing ndim)``; uniform ones stay uniform."""
        shape = self.shape
        values: dict[str, RealArrayLike] = {}
        for name, info in PARAMETERS.items():
            array = getattr(self, name)
            trailing: tuple[int, ...] = () if info.slots == 1 else (3,)
            values[name] = array if array.shape == trailing else transform(np.broadcast_to(array, shape + trailing))
        return Material(**values, bright_base_color=True)

    def __getitem__(self, key: Index) -> Material:
        """The material of some elements: ``m[i]``, ``m[2:5, ::2]``, ``m[mask]`` index the
        leading shape, as numpy indexes an array of that shape."""
        if self.shape == ():
            raise IndexError("material: a uniform material has no elements to index")
        # (Index has no Ellipsis; this is for untyped callers)
        if key is Ellipsis or (isinstance(key, tuple) and any(k is Ellipsis for k in key)):  # type: ignore[comparison-overlap]
            raise IndexError("material: index the leading shape without Ellipsis")
        np.empty(self.shape, dtype=np.int8)[key]  # numpy's IndexError for a bad key, before any copy
        return self._per_element(lambda array: array[key])

    def reshape(self, *shape: SupportsIndex | Sequence[SupportsIndex]) -> Material:
        """The same elements in a new leading shape (``m.reshape(-1)`` for flattened directions)."""
        new_shape = np.empty(self.shape, dtype=np.int8).reshape(*shape).shape  # type: ignore[arg-type]  # as numpy's
        return self._per_element(lambda array: array.reshape(new_shape + array.shape[len(self.shape):]))

    def require_read_by(self, model: str) -> None:
        """A ValueError naming the first parameter ``model`` does not read that is
        not at its default, or a ``specular`` the 2015 models cannot turn into an
        index of refraction (docs/model-2015.md, "Parameters")."""
        for name in unread_parameters(model):
            default = PARAMETERS[name].default
            self._require_everywhere(name, lambda array: array == default,
                                     f"model {model!r} does not read it and needs its default {default:g} "
                                     + ("(use flatness)" if name == "subsurface" else ""))
        limit = _models.max_specular(model)
        if limit < np.inf:
            self._require_everywhere("specular", lambda array: array <= limit,
                                     f"model {model!r} needs specular <= {limit:.6g} "
                                     f"(an index of refraction up to MAX_IOR = {MAX_IOR:g})")

    def _require_everywhere(self, name: str, holds: Callable[[Float64Array], NDArray[np.bool_]], rule: str) -> None:
        array: Float64Array = getattr(self, name)
        if array.size == 0 or holds(unexpanded(array)).all():
            return
        index = first_true(~np.broadcast_to(holds(array), array.shape))
        value = float(array.reshape(-1)[index])
        raise ValueError(f"{element_name(name, index, array.shape)}: {rule.strip()}, got {value:g}")

    def as_dict(self) -> dict[str, Float64Array]:
        return {name: getattr(self, name) for name in PARAMETERS}

    @staticmethod
    def mix(a: Material, b: Material, t: RealArrayLike) -> Material:
        """Every parameter linearly interpolated, ``a + (b - a) t`` (Burley 2012 §5.7).

        ``t`` is a number or a per-element mask in [0, 1], broadcast against the
        materials' leading shapes (it applies to all three channels of base_color).
        """
        require_material("a", a)
        require_material("b", b)
        weight = as_real_array("t", t)
        require_in_domain("t", weight, 0.0, 1.0)
        broadcast_leading(a=a.shape, b=b.shape, t=weight.shape)  # else numpy's message names no argument
        mixed: dict[str, RealArrayLike] = {}
        for name, info in PARAMETERS.items():
            start, end = getattr(a, name), getattr(b, name)
            w = weight[..., None] if info.slots == 3 else weight
            mixed[name] = start + (end - start) * w
        return Material(**mixed, bright_base_color=True)  # no brighter than a or b

    def packed(self, leading_shape: tuple[int, ...]) -> Float64Array:
        """All parameters broadcast to ``leading_shape`` as contiguous ``(N, 13)`` float64 rows."""
        n = int(np.prod(leading_shape, dtype=np.int64))
        rows = np.empty((n, _core.PARAM_SLOTS), dtype=np.float64)
        for name, info in PARAMETERS.items():
            array = getattr(self, name)
            if info.slots == 3:
                rows[:, info.first_slot : info.first_slot + 3] = np.broadcast_to(array, leading_shape + (3,)).reshape(n, 3)
            else:
                rows[:, info.first_slot] = np.broadcast_to(array, leading_shape).reshape(n)
        return rows

    def _float32_compact(self, name: str) -> Float32Array:
        """A per-element parameter as contiguous float32 in its compact form (its
        broadcast axes of size 1, as _owned_copy keeps them; cached)."""
        key = (name, None)
        cached = self._float32_cache.get(key)
        if cached is None:
            cached = np.ascontiguousarray(unexpanded(getattr(self, name)), dtype=np.float32)
            cached.flags.writeable = False
            if len(self._float32_cache) > 32:
                self._float32_cache.clear()
            self._float32_cache[key] = cached
        return cached

    def __reduce__(self) -> tuple[Callable[..., Material], tuple[Float64Array, ...]]:
        # pickling (multiprocessing, dask): rebuild through __init__, which re-checks
        return (_rebuilt, tuple(getattr(self, name) for name in PARAMETERS))

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Material):
            return NotImplemented
        return all(np.array_equal(getattr(self, n), getattr(other, n)) for n in PARAMETERS)

    __hash__ = None  # type: ignore[assignment]  # mutable-looking arrays: unhashable, as numpy's

    def __repr__(self) -> str:
        parts = []
        for name, info in PARAMETERS.items():
            array = getattr(self, name)
            if array.ndim == 0:
                parts.append(f"{name}={float(array):g}")
            elif info.slots == 3 and array.shape == (3,):
                parts.append(f"{name}=({', '.join(f'{v:g}' for v in array)})")
            else:
                parts.append(f"{name}=<{array.shape} in [{array.min():g}, {array.max():g}]>")
        return "Material(" + ", ".join(parts) + ")"


def require_material(name: str, value: object) -> Material:
    """``value``, if it is a Material; a TypeError naming the argument otherwise."""
    if not isinstance(value, Material):
        raise TypeError(f"{name}: expected a principled_brdf.Material, got {type(value).__name__}")
    return value


def _rebuilt(*values: RealArrayLike) -> Material:
    return Material(*values, bright_base_color=True)


def specular_of_ior(ior: RealArrayLike) -> Float64Array:
    """``specular`` for an index of refraction 1 <= η <= :data:`MAX_IOR`: ``((η - 1)/(η + 1))² / 0.08``
    (1.5 gives 0.5)."""
    eta = as_real_array("ior", ior)
    require_in_domain("ior", eta, 1.0, MAX_IOR)
    return _specular_of_eta(eta)


def _specular_of_eta(eta: Float64Array | float) -> Float64Array:
    return np.asarray(((eta - 1.0) / (eta + 1.0)) ** 2 / 0.08)



class BrightColorWarning(UserWarning):
    """A base_color above 1 without bright_base_color=True."""


def srgb_to_linear(color: RealArrayLike) -> Float64Array:
    """sRGB-encoded color to linear RGB by the exact piecewise curve (IEC 61966-2-1):
    ``c / 12.92`` for ``c <= 0.04045``, else ``((c + 0.055) / 1.055) ** 2.4``. A uint8
    array is taken as 0-255 and scaled by 1/255 first; other values must lie in [0, 1]."""
    if isinstance(color, np.ndarray) and color.dtype == np.uint8:
        color = color / 255.0
    array = as_real_array("color", color)
    require_in_domain("color", array, 0.0, 1.0)
    return _color.srgb_decode(array)


def linear_to_srgb(color: RealArrayLike) -> Float64Array:
    """Linear RGB to sRGB-encoded color, the inverse of :func:`srgb_to_linear`: ``12.92 c``
    for ``c <= 0.0031308``, else ``1.055 c ** (1 / 2.4) - 0.055``. Values must lie in
    [0, 1] (tone-map brighter ones first, e.g. with ``pb.render.tone_map``); float64 out,
    times 255 and rounded for 8 bits."""
    array = as_real_array("color", color)
    require_in_domain("color", array, 0.0, 1.0)
    return _color.srgb_encode(array)


def gamma22_to_linear(color: RealArrayLike) -> Float64Array:
    """Display (gamma 2.2) color to linear RGB, the BRDF Explorer's ``mon2lin``: ``c ** 2.2``."""
    array = as_real_array("color", color)
    require_in_domain("color", array, 0.0, np.inf)
    with np.errstate(over="ignore"):
        linear = np.power(array, 2.2)
    overflow = np.isinf(linear)
    if overflow.any():
        i = first_true(overflow)
        raise ValueError(f"{element_name('color', i, array.shape)}: {float(array.ravel()[i])!r} ** 2.2 is beyond "
                         "float64's range")
    return linear
