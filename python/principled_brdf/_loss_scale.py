"""The scale of the default loss, ``"scaled_log"`` (docs/fitting.md#losses).

``log(1 + f c / s) - log(1 + m c / s)`` is about the absolute error (over s)
where f c is well below s and about the relative error above it. A fixed s
(the ``"log"`` loss: s = 1/sr) fits a dim material almost linearly, so its
diffuse floor, which holds most of its albedo, weighs little against a few
bright cells; s taken from the data makes the loss the same for a material and
a copy of it ten times darker. s is the median of the samples' m c (the level
of the bulk of the samples, robust to the peak and to noise), but at least a
tenth of their mean: on a glossy metal most samples hold almost no light and
their median says nothing of the lobe that carries it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ._typing import Float64Array

_MEAN_FRACTION = 0.1
_FLOOR = 1e-9  # 1/sr: a black problem (every m = 0) keeps a finite loss and fits f towards 0


def log_scale(measured: Float64Array, cos_theta: Float64Array) -> float:
    """s of one problem: ``measured`` ``(n, 3)`` values of f present (no NaN), ``cos_theta``
    ``(n,)`` the loss's cosine factor c."""
    weighted = measured * cos_theta[:, None]
    return max(float(np.median(weighted)), _MEAN_FRACTION * float(np.mean(weighted)), _FLOOR)


def log_scales(measured: Float64Array, cos_theta: Float64Array) -> Float64Array:
    """``log_scale`` of B problems with every sample present: ``measured`` ``(B, n, 3)``,
    ``cos_theta`` ``(B, n)``; the same values as one problem at a time."""
    if len(measured) == 0:
        return np.zeros(0)
    weighted = (measured * cos_theta[..., None]).reshape(len(measured), -1)
    return np.maximum(np.maximum(np.median(weighted, axis=1), _MEAN_FRACTION * np.mean(weighted, axis=1)), _FLOOR)
