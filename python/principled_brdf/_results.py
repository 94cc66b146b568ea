"""What the calls return: f's lobes, a drawn sample, f with its density, f with
its derivatives, and the directional albedo. Plain named tuples of arrays,
built by the SIMD kernels and the float64 reference alike."""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from . import _core

if TYPE_CHECKING:
    from numpy.typing import NDArray

    from ._typing import Float32Array, Float64Array, FloatArray

__all__ = ["Lobes", "Sample", "ValuePdf", "Gradient", "Albedo"]


if TYPE_CHECKING:  # the fields of LOBE_NAMES (the C++ table), spelled out for type checkers
    class _LobeArrays(NamedTuple):
        diffuse: FloatArray
        sheen: FloatArray
        specular: FloatArray
        clearcoat: FloatArray
        multiple_scattering: FloatArray
        transmission: FloatArray
        diffuse_transmission: FloatArray
else:
    _LobeArrays = NamedTuple("LobeArrays", [(name, np.ndarray) for name in _core.LOBE_NAMES])


class Lobes(_LobeArrays):
    """The lobes of f (docs/model.md, "The model"), in the C++ table's order: ``diffuse``
    (with subsurface, times 1 - metallic), ``sheen`` (times 1 - metallic),
    ``specular``, ``clearcoat`` (grey) and ``multiple_scattering`` (the energy
    compensation's, 0 unless it is on), each shaped like :func:`eval`'s
    result, already weighted as they enter the sum."""

    __slots__ = ()

    def total(self) -> FloatArray:
        return sum(self[1:], self[0])


class Sample(NamedTuple):
    """What :func:`sample` and ``pb.reference.sample`` return."""

    wi: FloatArray  # (..., 3) drawn direction towards the light
    pdf: FloatArray  # (...) mixture density in solid angle; 0 where the draw is no sample (docs/sampling.md)
    weight: FloatArray  # (..., 3) f(wi, wo) |cos θl| / pdf; 0 where pdf is 0
    # (...) int32, an index into SAMPLED_LOBE_NAMES: 0 cosine, 1 primary specular, 2 clearcoat,
    # 3 transmission, 4 diffuse_transmission (the last two: the 2015 models)
    lobe: NDArray[np.int32]


class ValuePdf(NamedTuple):
    """What :func:`eval_pdf` returns."""

    value: Float32Array  # f, as eval returns it
    pdf: Float32Array  # the sampling density of wi given wo, as pdf returns it


class Gradient(NamedTuple):
    """f and its partial derivatives: ``jacobian[..., c, k] = ∂f_c / ∂names[k]``."""

    value: FloatArray  # (..., 3) as eval returns it
    jacobian: FloatArray  # (..., 3, P)
    names: tuple[str, ...]  # the P parameters in the table's order, then any direction components


class Albedo(NamedTuple):
    """Directional albedo at each cos θo, RGB ``(..., 3)``, with standard errors."""

    total: Float64Array
    lobes: Lobes  # diffuse, sheen, specular, clearcoat, multiple_scattering, transmission
    total_error: Float64Array  # standard error of the mean
    lobe_errors: Lobes
    reflectance: Float64Array  # the part from wo's side of the surface (the total for a BRDF)
    transmittance: Float64Array  # the part through the surface (0 for a BRDF)
