"""A call's model and mode, checked with the rules the model sets for the call's
material: the parameters it does not read at their defaults, ``specular``
within its bound, and energy compensation only where the model offers it."""

from __future__ import annotations

from ._validate import mode_index, model_index, require_energy_compensation_offered
from .material import Material

__all__ = ["model_and_mode"]


def model_and_mode(material: object, model: object, mode: object = "radiance",
                   energy_compensation: object = False) -> tuple[int, int]:
    """The indices of ``model`` and ``mode``, after the rules the model sets
    (:meth:`Material.require_read_by`, and no energy compensation for the 2015 models)."""
    model_id, mode_id = model_index(model), mode_index(mode)
    if isinstance(material, Material):  # (else the caller's material check names the argument)
        material.require_read_by(str(model))
    require_energy_compensation_offered(model, energy_compensation)
    return model_id, mode_id
