"""Checks at the Python boundary (SPEC §7).

Every check raises before any output exists, and names the argument and the
first offending element, e.g. ``wi[2, 7]: length 1.2 is not 1 (within 1e-3)``.
"""

from __future__ import annotations

import numbers

import numpy as np

DIRECTION_LENGTH_TOLERANCE = 1e-3
MODELS = {"disney2014": 0, "disney2012": 1}


def element_name(name: str, flat_index: int, shape: tuple) -> str:
    """``name[i, j]`` for the element at ``flat_index`` of an array of ``shape``."""
    if not shape:
        return name
    index = np.unravel_index(flat_index, shape)
    return f"{name}[{', '.join(str(int(i)) for i in index)}]"


def first_true(mask: np.ndarray) -> int:
    return int(np.flatnonzero(mask.ravel())[0])


def as_real_array(name: str, value) -> np.ndarray:
    """A float64 array from a number or array of real numbers; TypeError otherwise."""
    if isinstance(value, (str, bytes)) or value is None:
        raise TypeError(f"{name}: expected a real number or an array of them, got {type(value).__name__}")
    if isinstance(value, numbers.Number) and not isinstance(value, numbers.Real):
        raise TypeError(f"{name}: expected a real number, got {type(value).__name__}")
    try:
        array = np.asarray(value)
    except (TypeError, ValueError) as error:
        raise TypeError(f"{name}: cannot be read as an array of real numbers ({error})") from None
    if array.dtype == object or not (np.issubdtype(array.dtype, np.number) or array.dtype == np.bool_):
        raise TypeError(f"{name}: expected real numbers, got an array of dtype {array.dtype}")
    if np.issubdtype(array.dtype, np.complexfloating):
        raise TypeError(f"{name}: expected real numbers, got complex values")
    return array.astype(np.float64, copy=False)


def _not_finite_message(name: str, flat_index: int, array: np.ndarray) -> str:
    # float() so the message reads "nan", not numpy 2's "np.float64(nan)"
    return f"{element_name(name, flat_index, array.shape)}: {float(array.ravel()[flat_index])!r} is not a finite number"


def require_finite(name: str, array: np.ndarray) -> None:
    bad = ~np.isfinite(array)
    if bad.any():
        raise ValueError(_not_finite_message(name, first_true(bad), array))


def require_in_domain(name: str, array: np.ndarray, lower: float, upper: float) -> None:
    not_finite = ~np.isfinite(array)
    with np.errstate(invalid="ignore"):
        bad = not_finite | (array < lower) | (array > upper)
    if bad.any():
        i = first_true(bad)  # the first offending element, whichever the fault
        if not_finite.ravel()[i]:
            raise ValueError(_not_finite_message(name, i, array))
        domain = f"[{lower:g}, {'inf' if np.isinf(upper) else f'{upper:g}'}{')' if np.isinf(upper) else ']'}"
        raise ValueError(
            f"{element_name(name, i, array.shape)}: {float(array.ravel()[i])!r} is outside its domain {domain}"
        )


def directions(name: str, value) -> np.ndarray:
    """A float64 ``(..., 3)`` array of unit vectors, checked."""
    array = as_real_array(name, value)
    if array.ndim == 0 or array.shape[-1] != 3:
        raise ValueError(f"{name}: expected shape (..., 3) with unit 3-vectors on the last axis, got {array.shape}")
    not_finite = ~np.isfinite(array)
    with np.errstate(invalid="ignore", over="ignore"):
        length = np.sqrt(np.einsum("...i,...i->...", array, array))
        bad = not_finite.any(axis=-1) | (np.abs(length - 1.0) > DIRECTION_LENGTH_TOLERANCE)
    if bad.any():
        i = first_true(bad)  # the first offending vector, whichever the fault
        if not_finite.reshape(-1, 3)[i].any():
            raise ValueError(_not_finite_message(name, 3 * i + first_true(not_finite.reshape(-1, 3)[i]), array))
        raise ValueError(
            f"{element_name(name, i, length.shape)}: length {length.ravel()[i]:.6g} is not 1 "
            f"(within {DIRECTION_LENGTH_TOLERANCE:g})"
        )
    return array


def model_index(model) -> int:
    if not isinstance(model, str) or model not in MODELS:
        raise ValueError(f"model: expected one of {sorted(MODELS)}, got {model!r}")
    return MODELS[model]


def broadcast_leading(**shapes: tuple) -> tuple:
    """The common leading shape of several arguments, or a ValueError naming them."""
    try:
        return np.broadcast_shapes(*shapes.values())
    except ValueError:
        described = ", ".join(f"{name} {shape}" for name, shape in shapes.items())
        raise ValueError(f"leading shapes do not broadcast: {described}") from None
