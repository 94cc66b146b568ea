"""The models and the rules each one sets, in one table: which lie on the whole
sphere, which parameters each reads, the slots its derivatives cover, the
lobes it makes and draws, whether it offers energy compensation, and the
largest ``specular`` it takes (docs/model.md, docs/model-2015.md).

Every other module asks this one; none keeps its own list of models.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, NamedTuple

from . import _core

if TYPE_CHECKING:
    from collections.abc import Mapping, Sequence
    from typing import Any

__all__ = ["MODEL_NAMES", "DEFAULT_MODEL", "PARAMETER_NAMES", "LOBE_NAMES", "SAMPLED_LOBE_NAMES", "ModelRules",
           "RULES", "WHOLE_SPHERE_MODELS", "MAX_IOR", "MAX_BSDF_SPECULAR", "is_whole_sphere", "unread_parameters",
           "offers_energy_compensation", "max_specular", "slot_names", "gradient_names"]

# The C++ side's name tables (params.hpp), each in its enum's order.
MODEL_NAMES: tuple[str, ...] = tuple(_core.MODEL_NAMES)
PARAMETER_NAMES: tuple[str, ...] = tuple(row[0] for row in _core.PARAMETER_TABLE)
LOBE_NAMES: tuple[str, ...] = tuple(_core.LOBE_NAMES)  # of f, as eval_lobes returns them
SAMPLED_LOBE_NAMES: tuple[str, ...] = tuple(_core.SAMPLED_LOBE_NAMES)  # by the index a sample reports


class ModelRules(NamedTuple):
    """What one model is and what it asks of its material."""

    name: str
    whole_sphere: bool  # a BSDF over the whole sphere (the 2015 models), else a BRDF of the upper hemisphere
    reads: tuple[str, ...]  # the parameters it reads; the others must stay at their defaults
    unread: tuple[str, ...]  # the others, in the parameter table's order
    gradient_slots: int  # its derivatives cover the first this many packed slots
    lobes: tuple[str, ...]  # the lobes of LOBE_NAMES it can make nonzero
    sampled_lobes: tuple[str, ...]  # the sampled lobes of SAMPLED_LOBE_NAMES it can draw
    energy_compensation: bool  # whether energy_compensation=True is offered
    max_ior: float  # the largest index of refraction it takes (inf: unbounded)
    max_specular: float  # the largest specular it takes, that index's (inf: unbounded)


def _rules(table: Sequence[Mapping[str, Any]]) -> dict[str, ModelRules]:
    rules = {}
    for row in table:
        reads = tuple(row["reads"])
        rules[row["name"]] = ModelRules(
            name=row["name"], whole_sphere=bool(row["whole_sphere"]), reads=reads,
            unread=tuple(name for name in PARAMETER_NAMES if name not in reads),
            gradient_slots=int(row["gradient_slots"]), lobes=tuple(row["lobes"]),
            sampled_lobes=tuple(row["sampled_lobes"]), energy_compensation=bool(row["energy_compensation"]),
            max_ior=float(row["max_ior"]), max_specular=float(row["max_specular"]))
    if tuple(rules) != MODEL_NAMES:
        raise ImportError(f"the model table names {tuple(rules)}, the extension's models are {MODEL_NAMES}")
    return rules


# The extension's model table (model_table.hpp), one row per model.
RULES: dict[str, ModelRules] = _rules(_core.MODEL_TABLE)
DEFAULT_MODEL = MODEL_NAMES[0]
# The models of the whole sphere (the 2015 BSDF of a solid and of a thin sheet); the others are BRDFs.
WHOLE_SPHERE_MODELS: tuple[str, ...] = tuple(name for name, rules in RULES.items() if rules.whole_sphere)
# The largest index of refraction a model with a bound takes (and ``ior=`` accepts), and its specular.
MAX_IOR = min(rules.max_ior for rules in RULES.values())
MAX_BSDF_SPECULAR = min(rules.max_specular for rules in RULES.values())


def _rules_of(model: object) -> ModelRules | None:
    return RULES.get(model) if isinstance(model, str) else None


def is_whole_sphere(model: object) -> bool:
    """Whether ``model`` lies on the whole sphere (False for a name that is no model)."""
    rules = _rules_of(model)
    return rules is not None and rules.whole_sphere


def unread_parameters(model: object) -> tuple[str, ...]:
    """The parameters ``model`` does not read (which must stay at their defaults), e.g.
    ``("subsurface", "diff_trans")`` for ``"disney2015"``; none for a name that is no model."""
    rules = _rules_of(model)
    return () if rules is None else rules.unread


def offers_energy_compensation(model: object) -> bool:
    """Whether ``model`` takes ``energy_compensation=True``."""
    rules = _rules_of(model)
    return rules is None or rules.energy_compensation


def max_specular(model: object) -> float:
    """The largest ``specular`` ``model`` takes: inf where it is unbounded."""
    rules = _rules_of(model)
    return math.inf if rules is None else rules.max_specular


def slot_names(slots: int) -> tuple[str, ...]:
    """The names of the first ``slots`` packed slots, ``base_color`` as ``base_color_r/g/b``."""
    names: list[str] = []
    for name, first_slot, count, *_ in _core.PARAMETER_TABLE:
        if first_slot < slots:
            names += [f"{name}_{c}" for c in "rgb"] if count == 3 else [name]
    return tuple(names)


_GRADIENT_NAMES = {name: slot_names(rules.gradient_slots) for name, rules in RULES.items()}


def gradient_names(model: object) -> tuple[str, ...]:
    """The columns of ``model``'s Jacobian in the parameters; the default model's for a
    name that is no model (the caller checks the name)."""
    rules = _rules_of(model)
    return _GRADIENT_NAMES[DEFAULT_MODEL if rules is None else rules.name]
