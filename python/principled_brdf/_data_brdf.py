"""f(wi, wo) of measured data or of any callable, checked: what the plots and the
pictures take beside a Material. Directions are in the shading frame (z the
normal), f is in 1/sr, ``(..., 3)`` RGB, NaN where the data has no value."""

from __future__ import annotations

import typing

import numpy as np

from . import _validate
from .measured import MerlBRDF

if typing.TYPE_CHECKING:
    from collections.abc import Callable

    from ._typing import Float64Array

DataBrdf = typing.Callable[["Float64Array", "Float64Array"], "Float64Array"]


def is_data(value: object) -> bool:
    """Measured data or a callable f(wi, wo) (a Material is neither)."""
    return isinstance(value, MerlBRDF) or callable(value)


def data_brdf(name: str, value: object) -> DataBrdf:
    """f of a :class:`MerlBRDF` (its nearest cell; 0 at or below the horizon) or of a callable
    ``f(wi, wo) -> (..., 3)``, whose values are checked: the shape of the pairs' broadcast with
    3 channels, finite and >= 0 or NaN (no data); otherwise an error naming ``name``."""
    if isinstance(value, MerlBRDF):
        return value.eval
    if callable(value):
        return _checked(name, value)
    raise TypeError(f"{name}: expected a principled_brdf.Material, a preset name, a MerlBRDF or a callable "
                    f"f(wi, wo), got {type(value).__name__}")


def _checked(name: str, function: Callable[..., object]) -> DataBrdf:
    def called(wi: Float64Array, wo: Float64Array) -> Float64Array:
        wi, wo = np.broadcast_arrays(wi, wo)
        returned = np.asarray(function(wi, wo))
        if returned.dtype.kind not in "biuf":
            raise TypeError(f"{name}: the callable returned {returned.dtype} values, expected real f in 1/sr")
        f = returned.astype(np.float64, copy=False)
        if f.shape != wi.shape:
            raise ValueError(f"{name}: expected the callable to return f of shape {wi.shape} (RGB per pair), "
                             f"got {f.shape}")
        with np.errstate(invalid="ignore"):
            bad = ~((f >= 0.0) & (f < np.inf)) & ~np.isnan(f)
        if bad.any():
            i = _validate.first_true(bad)
            raise ValueError(f"{name}: the callable returned {float(f.ravel()[i])!r}; expected f >= 0, finite "
                             "(or NaN where there is no data)")
        return f
    return called
