"""A small library of named materials (linear base colors, within the parameters' domains).

    pb.presets.get("gold")            # a Material
    pb.presets.names()                # what there is
    pb.Material.mix(pb.presets.get("gold"), pb.presets.get("blue_rubber"), mask)
"""

from __future__ import annotations

import typing

from .material import Material

if typing.TYPE_CHECKING:  # (typing.TYPE_CHECKING: this module shows its public names only)
    from typing import Any

__all__ = ["get", "names", "parameters"]

_PRESETS: dict[str, dict[str, float | tuple[float, float, float]]] = {
    # Metals: base_color is the specular color at normal incidence.
    "gold": dict(base_color=(1.0, 0.766, 0.336), metallic=1.0, roughness=0.3),
    "copper": dict(base_color=(0.955, 0.638, 0.538), metallic=1.0, roughness=0.35),
    "chrome": dict(base_color=(0.55, 0.556, 0.554), metallic=1.0, roughness=0.08),
    "brushed_metal": dict(base_color=(0.91, 0.92, 0.92), metallic=1.0, roughness=0.4, anisotropic=0.9),
    # Dielectrics
    "blue_rubber": dict(base_color=(0.03, 0.08, 0.45), roughness=0.75, specular=0.3),
    "white_plastic": dict(base_color=(0.8, 0.8, 0.8), roughness=0.25, specular=0.5),
    "car_paint": dict(base_color=(0.5, 0.015, 0.02), metallic=0.2, roughness=0.45, clearcoat=1.0,
                      clearcoat_gloss=0.93),
    "satin_cloth": dict(base_color=(0.45, 0.12, 0.3), roughness=0.85, sheen=1.0, sheen_tint=0.6, specular=0.3),
    "skin": dict(base_color=(0.8, 0.5, 0.4), subsurface=0.8, roughness=0.55, specular=0.35, sheen=0.1),
    "ceramic": dict(base_color=(0.85, 0.82, 0.75), roughness=0.5, clearcoat=0.8, clearcoat_gloss=1.0),
}


def names() -> list[str]:
    """The preset names, sorted."""
    return sorted(_PRESETS)


def parameters(name: str) -> dict[str, Any]:
    """The parameters of preset ``name`` (the rest take their defaults): numbers, and
    ``base_color`` a triple (typed ``Any`` so that ``pb.Material(**parameters(name))`` checks)."""
    if name not in _PRESETS:
        raise ValueError(f"name: unknown preset {name!r}; choose one of {', '.join(names())}")
    return dict(_PRESETS[name])


def get(name: str) -> Material:
    """Preset ``name`` as a Material."""
    return Material(**parameters(name))
