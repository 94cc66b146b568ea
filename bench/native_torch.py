"""The Disney 2014 BRDF (bench/native_model.py) in torch operations, float32:
``eval`` for f; its backward pass is autograd's (``eval(...).sum().backward()``).
"""

from __future__ import annotations

from typing import Any

import torch

import native_model

OPS = native_model.Ops(sqrt=torch.sqrt, log=torch.log, where=torch.where, clip01=lambda x: torch.clamp(x, 0.0, 1.0),
                       at_least=lambda x, low: torch.clamp(x, min=low))


def as_material(material: dict[str, Any]) -> dict[str, torch.Tensor]:
    """Every parameter as a float32 tensor (numbers as 0-d tensors); tensors are kept as given."""
    return {name: value if isinstance(value, torch.Tensor) else torch.as_tensor(value, dtype=torch.float32)
            for name, value in material.items()}


def eval(material: dict[str, torch.Tensor], wi: torch.Tensor, wo: torch.Tensor) -> torch.Tensor:
    """f ``(N, 3)``; ``material`` holds all 11 parameters (as_material)."""
    return native_model.f(OPS, material, wi, wo)
