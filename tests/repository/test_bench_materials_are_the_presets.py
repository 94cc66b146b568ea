"""The benchmark's material set (bench/materials.hpp) holds the presets of
pb.presets as they are, with the defaults elsewhere, in params.hpp's slot order."""

from __future__ import annotations

import pathlib
import re

import numpy as np

import principled_brdf as pb

TABLE = pathlib.Path(__file__).resolve().parents[2] / "bench" / "materials.hpp"
SLOT_ORDER = ("base_color", "metallic", "subsurface", "specular", "specular_tint", "roughness", "anisotropic",
              "sheen", "sheen_tint", "clearcoat", "clearcoat_gloss")


def table_rows() -> dict[str, np.ndarray]:
    rows = re.findall(r'\{"(\w+)", \{([^}]*)\}\}', TABLE.read_text())
    return {name: np.array([float(v.rstrip("f")) for v in values.split(",")]) for name, values in rows}


def slots_of(material: pb.Material) -> np.ndarray:
    return np.concatenate([np.ravel(getattr(material, name)) for name in SLOT_ORDER]).astype(np.float32)


def test_every_preset_is_in_the_table_as_it_is():
    rows = table_rows()
    assert set(rows) == set(pb.presets.names()) | {"benchmark"}
    for name in pb.presets.names():
        np.testing.assert_array_equal(rows[name].astype(np.float32), slots_of(pb.presets.get(name)), err_msg=name)


def test_the_benchmark_material_has_every_lobe_on():
    slots = dict(zip(("r", "g", "b") + SLOT_ORDER[1:], table_rows()["benchmark"]))
    assert 0 < slots["metallic"] < 1
    assert all(slots[name] > 0 for name in ("subsurface", "anisotropic", "sheen", "clearcoat"))
