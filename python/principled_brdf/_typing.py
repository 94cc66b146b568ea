"""Type aliases of the package's annotations (for type checkers and editors;
the modules import them under ``TYPE_CHECKING`` only, so nothing here runs in a call).

``RealArrayLike`` is what the checks of docs/bad-input.md accept as numbers
or arrays of real numbers: Python and numpy numbers, arrays (and objects with
``__array__``) of bool, integer or floating dtype, and nested sequences of
them. Unlike ``numpy.typing.ArrayLike`` it leaves out ``str``, ``bytes`` and
complex numbers, which the checks reject. Any numpy array is let through (the
dtype numpy's stubs infer is often ``generic``), to be checked at run time.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal, Protocol, SupportsIndex, Union

import numpy as np
from numpy.typing import NDArray

__all__ = ["RealArrayLike", "Index", "Model", "Mode", "Layout", "SpecularSampler", "Float32Array", "Float64Array",
           "FloatArray"]

_RealDType = np.dtype[Union[np.bool_, np.integer[Any], np.floating[Any]]]


class _SupportsRealArray(Protocol):
    def __array__(self) -> np.ndarray[Any, _RealDType]: ...


_RealScalar = Union[float, int, np.floating[Any], np.integer[Any], np.bool_]
_Leaf = Union[_RealScalar, "np.ndarray[Any, Any]", _SupportsRealArray]
RealArrayLike = Union[
    _Leaf,
    Sequence[_Leaf],
    Sequence[Sequence[_Leaf]],
    Sequence[Sequence[Sequence[_Leaf]]],
    Sequence[Sequence[Sequence[Sequence[_Leaf]]]],
]

_Key = Union[SupportsIndex, slice, None, NDArray[Union[np.integer[Any], np.bool_]], Sequence[int]]
Index = Union[_Key, tuple[_Key, ...]]  # what indexes a Material's leading shape, as numpy indexes

Model = Literal["disney2014", "disney2012", "disney2015", "disney2015_thin"]  # _core.MODEL_NAMES
Mode = Literal["radiance", "importance"]  # _core.MODE_NAMES
SpecularSampler = Literal["visible", "distribution"]  # _core.SAMPLER_NAMES
Layout = Literal["aos", "soa"]

Float32Array = NDArray[np.float32]
Float64Array = NDArray[np.float64]
FloatArray = NDArray[np.floating[Any]]  # float32 from the SIMD kernels, float64 from the reference
