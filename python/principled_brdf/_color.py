"""The sRGB transfer curve (IEC 61966-2-1), written once.

Unchecked: float64 arrays in, float64 arrays out. The public, checked pair
is :func:`principled_brdf.srgb_to_linear` and :func:`principled_brdf.linear_to_srgb`;
the pictures (``render.to_srgb8``, ``plot``, the explorer) call these directly
on values they made themselves.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from ._typing import Float64Array, RealArrayLike

# Rec. 709 luminance of linear RGB: the tone curves' Y and plot's "luminance" channel.
LUMINANCE_WEIGHTS = (0.2126, 0.7152, 0.0722)


def srgb_encode(linear: RealArrayLike) -> Float64Array:
    """Linear to sRGB-encoded: ``12.92 c`` for ``c <= 0.0031308``, else ``1.055 c^(1/2.4) - 0.055``,
    after clipping ``c`` to [0, 1]."""
    c = np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)


def srgb_decode(encoded: RealArrayLike) -> Float64Array:
    """sRGB-encoded to linear: ``c / 12.92`` for ``c <= 0.04045``, else ``((c + 0.055) / 1.055)^2.4``
    (``c`` in [0, 1])."""
    c = np.asarray(encoded, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, np.power((c + 0.055) / 1.055, 2.4))
