"""Inputs away from the kinks (clamps, the horizon, domain edges), where f is smooth
and finite differences and gradient checks are meaningful."""

from __future__ import annotations

import numpy as np

from conftest import random_directions


def interior_inputs(rng: np.random.Generator, n: int) -> dict[str, np.ndarray]:
    """Directions with cos θ >= 0.2 and per-element parameters inside their domains."""
    return {
        "wi": random_directions(rng, n, min_cos=0.2, grazing_fraction=0.0),
        "wo": random_directions(rng, n, min_cos=0.2, grazing_fraction=0.0),
        "roughness": rng.uniform(0.25, 0.9, n),
        "base_color": rng.uniform(0.1, 0.9, (n, 3)),
        "metallic": rng.uniform(0.1, 0.9, n),
        "anisotropic": rng.uniform(0.1, 0.9, n),
        "sheen": rng.uniform(0.1, 0.9, n),
        "clearcoat": rng.uniform(0.1, 0.9, n),
        "clearcoat_gloss": rng.uniform(0.1, 0.9, n),
    }


PARAMETER_NAMES = ("roughness", "base_color", "metallic", "anisotropic", "sheen", "clearcoat", "clearcoat_gloss")
