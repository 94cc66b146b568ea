"""Checks at the Python boundary (docs/bad-input.md).

Every check names the argument and the first offending element, e.g.
``wi[2, 7]: length 1.2 is not 1 (within 1e-3)``.
"""

from __future__ import annotations

import math
import numbers
import operator
import sys
from typing import TYPE_CHECKING

import numpy as np

from . import _core, _models

if TYPE_CHECKING:
    from numpy.typing import NDArray

    from ._typing import Float64Array, FloatArray, Layout

DIRECTION_LENGTH_TOLERANCE = 1e-3
# A direction passes when its float64 squared length, summed as x² + y² + z²,
# lies within these: the rule the kernels apply (batch.hpp, DirectionCheck).
DIRECTION_LENGTH2_BOUNDS = tuple(_core.direction_length2_bounds(DIRECTION_LENGTH_TOLERANCE))
# The C++ side's name tables (params.hpp), each in its enum's order.
MODELS = {name: index for index, name in enumerate(_models.MODEL_NAMES)}
SAMPLERS = {name: index for index, name in enumerate(_core.SAMPLER_NAMES)}  # of the primary specular lobe
MODES = {name: index for index, name in enumerate(_core.MODE_NAMES)}
LAYOUTS = ("aos", "soa")  # (..., 3) and (3, ...): where a direction's components lie
FLOAT32_MAX = float(np.finfo(np.float32).max)
MAX_RESOLUTION = 16384  # pixels (or angles) along a picture's side: 16384² pixels is 3 GB of float32 RGB
_REAL_KINDS = "biuf"  # bool, signed and unsigned integers, floats


def unit_length(array: FloatArray) -> NDArray[np.bool_]:
    """Which vectors on the last axis pass the direction check (False for NaN)."""
    w = array.astype(np.float64, copy=False)
    with np.errstate(invalid="ignore", over="ignore"):
        length2 = w[..., 0] * w[..., 0] + w[..., 1] * w[..., 1] + w[..., 2] * w[..., 2]
        return (length2 >= DIRECTION_LENGTH2_BOUNDS[0]) & (length2 <= DIRECTION_LENGTH2_BOUNDS[1])


def direction_error(name: str, flat_index: int, leading: tuple[int, ...], vector: FloatArray) -> ValueError:
    """The error for a vector that fails the direction check."""
    where = element_name(name, flat_index, leading)
    vector = np.asarray(vector, dtype=np.float64)
    if not np.all(np.isfinite(vector)):
        return ValueError(f"{where}: {vector.tolist()} is not a finite vector")
    length = float(np.sqrt(np.sum(vector ** 2)))
    shown = f"{length:.7g}"  # float32's digits, more where that much looks within the tolerance
    if abs(float(shown) - 1.0) <= DIRECTION_LENGTH_TOLERANCE:
        shown = f"{length:.10g}"
    return ValueError(f"{where}: length {shown} is not 1 (within {DIRECTION_LENGTH_TOLERANCE:g})")


def flag(name: str, value: object) -> bool:
    """A yes/no option: True, False (or numpy's bool); TypeError otherwise."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise TypeError(f"{name}: expected True or False, got {type(value).__name__}")


def element_name(name: str, flat_index: int, shape: tuple[int, ...]) -> str:
    """``name[i, j]`` for the element at ``flat_index`` of an array of ``shape``."""
    if not shape:
        return name
    index = np.unravel_index(flat_index, shape)
    return f"{name}[{', '.join(str(int(i)) for i in index)}]"


def first_true(mask: NDArray[np.bool_]) -> int:
    return int(np.flatnonzero(mask.ravel())[0])


def as_real_array(name: str, value: object) -> Float64Array:
    """A float64 array from a number or array of real numbers; TypeError otherwise."""
    if type(value) is float:  # the common case, without numpy's dtype inspection
        return np.array(value)
    if isinstance(value, (str, bytes)) or value is None:
        raise TypeError(f"{name}: expected a real number or an array of them, got {type(value).__name__}")
    if isinstance(value, numbers.Number) and not isinstance(value, numbers.Real):
        raise TypeError(f"{name}: expected a real number, got {type(value).__name__}")
    try:
        array = np.asarray(value)
    except (TypeError, ValueError) as error:
        raise TypeError(f"{name}: cannot be read as an array of real numbers ({error})") from None
    if np.issubdtype(array.dtype, np.complexfloating):
        raise TypeError(f"{name}: expected real numbers, got complex values")
    if array.dtype.kind not in _REAL_KINDS:  # objects, strings, datetime64, timedelta64, ...
        raise TypeError(f"{name}: expected real numbers, got an array of dtype {array.dtype}")
    array = array.astype(np.float64, copy=False)
    return array if array.flags.aligned else array.copy()


def _not_finite_message(name: str, flat_index: int, array: FloatArray) -> str:
    # float() so the message reads "nan", not numpy 2's "np.float64(nan)"
    return f"{element_name(name, flat_index, array.shape)}: {float(array.ravel()[flat_index])!r} is not a finite number"


def all_within(array: FloatArray, lower: float, upper: float) -> bool:
    """Every value finite and within [lower, upper]: two reductions and no
    temporary arrays, several times faster than an elementwise mask (min and
    max propagate NaN, which fails both comparisons). The checks below take it
    as their fast path and build a mask only to name an offending element."""
    if array.size == 0:
        return True
    lowest, highest = max(lower, -sys.float_info.max), min(upper, sys.float_info.max)
    # as Python floats: compared with a float32 reduction, a float64 bound would be
    # rounded to float32 (numpy's promotion), sys.float_info.max to infinity
    return lowest <= float(array.min()) and float(array.max()) <= highest


def require_float32(name: str, array: FloatArray) -> None:
    """Every value finite and within float32's range (for the float32 kernels)."""
    if all_within(array, -FLOAT32_MAX, FLOAT32_MAX):
        return
    with np.errstate(invalid="ignore"):
        bad = ~(np.abs(array) <= FLOAT32_MAX)
    if bad.any():
        i = first_true(bad)
        value = float(array.ravel()[i])
        if np.isfinite(value):
            raise ValueError(f"{element_name(name, i, array.shape)}: {value!r} is beyond float32's range "
                             f"(|x| <= {FLOAT32_MAX:.7g})")
        raise ValueError(_not_finite_message(name, i, array))


def require_finite(name: str, array: FloatArray) -> None:
    if all_within(array, -np.inf, np.inf):
        return
    bad = ~np.isfinite(array)
    if bad.any():
        raise ValueError(_not_finite_message(name, first_true(bad), array))


def require_in_domain(name: str, array: FloatArray, lower: float, upper: float) -> None:
    if array.ndim == 0:  # a number inside the domain passes without array operations
        number = float(array)
        if math.isfinite(number) and lower <= number <= upper:
            return
    elif all_within(array, lower, upper):
        return
    not_finite = ~np.isfinite(array)
    with np.errstate(invalid="ignore"):
        bad = not_finite | (array < lower) | (array > upper)
    if bad.any():
        i = first_true(bad)  # the first offending element, whichever the fault
        if not_finite.ravel()[i]:
            raise ValueError(_not_finite_message(name, i, array))
        raise ValueError(f"{element_name(name, i, array.shape)}: {float(array.ravel()[i])!r} is outside its domain "
                         f"{interval(lower, upper)}")


def interval(lower: float, upper: float, open_lower: bool = False, open_upper: bool = False) -> str:
    """``[0, 1]``, ``[0, inf)``, ``(0, 100]``: an infinite end is always open."""
    left = "(" if open_lower or math.isinf(lower) else "["
    right = ")" if open_upper or math.isinf(upper) else "]"
    return f"{left}{lower:g}, {upper:g}{right}"


def real_number(name: str, value: object, lower: float = -math.inf, upper: float = math.inf, *,
                open_lower: bool = False, open_upper: bool = False) -> float:
    """One real number (a Python or numpy number or a 0-d array, not a bool), finite and within
    [lower, upper], an end excluded where ``open_lower``/``open_upper``: TypeError or ValueError
    naming the argument (``exposure: -1.0 is outside its domain [0, inf)``)."""
    if isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name}: expected a real number, got {type(value).__name__}")
    array = as_real_array(name, value)
    if array.shape != ():
        raise ValueError(f"{name}: expected one number, got shape {array.shape}")
    number = float(array)
    if not math.isfinite(number):
        raise ValueError(f"{name}: {number!r} is not a finite number")
    if not lower <= number <= upper or (open_lower and number == lower) or (open_upper and number == upper):
        raise ValueError(f"{name}: {number!r} is outside its domain {interval(lower, upper, open_lower, open_upper)}")
    return number


def directions(name: str, value: object) -> Float64Array:
    """A float64 ``(..., 3)`` array of unit vectors, checked."""
    array = as_real_array(name, value)
    if array.ndim == 0 or array.shape[-1] != 3:
        raise ValueError(f"{name}: expected shape (..., 3) with unit 3-vectors on the last axis, got {array.shape}")
    bad = ~unit_length(array)
    if bad.any():
        i = first_true(bad)  # the first offending vector, whichever the fault
        vector = array.reshape(-1, 3)[i]
        not_finite = ~np.isfinite(vector)
        if not_finite.any():
            raise ValueError(_not_finite_message(name, 3 * i + first_true(not_finite), array))
        raise direction_error(name, i, array.shape[:-1], vector)
    return array


def integer(name: str, value: object) -> int:
    """An integer (not a bool); TypeError otherwise."""
    if isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name}: expected an integer, got {type(value).__name__}")
    try:
        return operator.index(value)  # type: ignore[arg-type]  # a TypeError here is the check
    except TypeError:
        raise TypeError(f"{name}: expected an integer, got {type(value).__name__}") from None


def integer_in(name: str, value: object, minimum: int, maximum: int, unit: str = "") -> int:
    """An integer (not a bool) from ``minimum`` to ``maximum``: TypeError otherwise, ValueError
    outside, both naming the argument (``samples: expected 2 to 67108864, got 1``; ``unit``,
    e.g. ``" per pixel"``, follows the bounds)."""
    count = integer(name, value)
    if not minimum <= count <= maximum:
        raise ValueError(f"{name}: expected {minimum} to {maximum}{unit}, got {count}")
    return count


def resolution(name: str, value: object, minimum: int = 2, maximum: int = MAX_RESOLUTION,
               unit: str = " pixels") -> int:
    """The pictures' one rule for a resolution (``render``, ``plot``, the explorer): an integer,
    not a bool, from ``minimum`` (2 unless a picture needs more) to ``maximum``
    (:data:`MAX_RESOLUTION`, 16384), e.g. ``resolution: expected 2 to 16384 pixels, got 1``."""
    return integer_in(name, value, minimum, maximum, unit)


def seed_value(seed: object) -> int:
    value = integer("seed", seed)
    if not 0 <= value < 2**64:
        raise ValueError(f"seed: expected 0 <= seed < 2**64, got {value}")
    return value


def model_index(model: object) -> int:
    if not isinstance(model, str) or model not in MODELS:
        raise ValueError(f"model: expected one of {sorted(MODELS)}, got {model!r}")
    return MODELS[model]


def mode_index(mode: object) -> int:
    if not isinstance(mode, str) or mode not in MODES:
        raise ValueError(f"mode: expected one of {sorted(MODES)}, got {mode!r}")
    return MODES[mode]


def require_energy_compensation_offered(model: object, energy_compensation: object) -> None:
    """A ValueError for ``energy_compensation=True`` with a model that does not offer it
    (the 2015 models)."""
    if not _models.offers_energy_compensation(model) and flag("energy_compensation", energy_compensation):
        raise ValueError(f"energy_compensation: not available for model {model!r} (docs/model-2015.md)")


def refuse_energy_compensation_derivative(energy_compensation: object, model: object) -> None:
    """The BRDFs' derivatives (eval_grad, in the parameters or the directions) take f without
    their multiple-scattering lobe: NotImplementedError for ``energy_compensation=True``
    (the 2015 solid's compensation has its derivatives)."""
    from . import _models

    if flag("energy_compensation", energy_compensation) and not _models.is_whole_sphere(model):
        raise NotImplementedError("eval_grad: energy_compensation=True is not supported with the BRDFs (the "
                                  "derivative of their multiple-scattering lobe is not implemented); evaluate f "
                                  "with pb.eval")


def layout(value: object) -> Layout:
    """``"aos"`` (directions ``(..., 3)``) or ``"soa"`` (``(3, ...)``); a ValueError otherwise."""
    if not isinstance(value, str) or value not in LAYOUTS:
        raise ValueError(f"layout: expected 'aos' or 'soa' (directions (..., 3) or (3, ...)), got {value!r}")
    return value  # type: ignore[return-value]  # one of LAYOUTS


def sampler_index(specular_sampler: object) -> int:
    if not isinstance(specular_sampler, str) or specular_sampler not in SAMPLERS:
        raise ValueError(f"specular_sampler: expected one of {sorted(SAMPLERS)}, got {specular_sampler!r}")
    return SAMPLERS[specular_sampler]


def broadcast_leading(**shapes: tuple[int, ...]) -> tuple[int, ...]:
    """The common leading shape of several arguments, or a ValueError naming them."""
    distinct = {shape for shape in shapes.values() if shape != ()}
    if len(distinct) <= 1:  # the common case, without numpy's general rule
        return distinct.pop() if distinct else ()
    try:
        return np.broadcast_shapes(*shapes.values())
    except ValueError:
        described = ", ".join(f"{name} {shape}" for name, shape in shapes.items())
        raise ValueError(f"leading shapes do not broadcast: {described}") from None
