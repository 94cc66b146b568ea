"""Lobes the data do not need stay off (docs/fitting.md#lobes-the-data-do-not-need).

A clearcoat imitating a Beckmann conductor's tail, a metallic imitating a
plastic's coat: the fit without the lobe costs little more, and the lobe is held
off, said in the notes. Lobes the data need (the model's own material with a
clearcoat and a sheen) are kept, at their values. Per problem in a batch, with
either method.
"""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb

pytest.importorskip("scipy")

STEP = (1, 3, 12)
GOLD = pb.synthetic.conductor("gold", 0.2)  # Beckmann: fitted with clearcoat 1 without selection
PLASTIC = pb.synthetic.layered_plastic((0.5, 0.1, 0.05), 0.1)
OWN = pb.Material(base_color=(0.2, 0.5, 0.7), roughness=0.35, specular=0.6, sheen=0.3, clearcoat=0.5,
                  clearcoat_gloss=0.8)


def _own(wi, wo):
    f = pb.reference.eval(OWN, wi, wo)
    return np.where(((wi[..., 2] > 0) & (wo[..., 2] > 0))[..., None], f, np.nan)


@pytest.fixture(scope="module")
def pairs():
    return pb.measured.merl_pairs(step=STEP)


@pytest.mark.parametrize("method", ["batched", "scipy"])
def test_a_beckmann_conductor_fits_without_clearcoat(pairs, method):
    wi, wo = pairs
    measured = GOLD(wi, wo)
    kept = pb.fit(wi, wo, measured, method=method, select_lobes=False)
    assert float(kept.material.clearcoat) > 0.5  # what selection is for
    selected = pb.fit(wi, wo, measured, method=method)
    assert float(selected.material.clearcoat) == 0.0
    assert float(selected.material.metallic) > 0.95
    assert any(note.startswith("clearcoat held off") for note in selected.notes)
    assert "clearcoat held off" in selected.summary()
    # within the factor: the cost without the lobe is at most LOBE_GAIN times the cost with it
    assert float(selected.cost) <= pb.fitting.LOBE_GAIN * float(kept.cost)
    # the parameter only the clearcoat reads goes back to its start
    assert float(selected.material.clearcoat_gloss) == float(pb.Material().clearcoat_gloss)


def test_a_plastic_fits_without_metallic(pairs):
    wi, wo = pairs
    result = pb.fit(wi, wo, PLASTIC(wi, wo))
    assert float(result.material.metallic) <= 0.05


def test_lobes_the_data_need_are_kept(pairs):
    wi, wo = pairs
    result = pb.fit(wi, wo, _own(wi, wo))
    assert not any("held off" in note for note in result.notes)
    assert float(result.cost) < 0.1  # f matched (another model costs 100 and more); clearcoat and its gloss trade
    for name in ("clearcoat", "sheen"):
        assert float(getattr(result.material, name)) == pytest.approx(float(getattr(OWN, name)), rel=0.1), name


def test_a_batch_selects_per_problem_as_alone(pairs):
    wi, wo = pairs
    gold, own = GOLD(wi, wo), _own(wi, wo)
    missing = np.full_like(gold, np.nan)
    batch = pb.fit(wi, wo, np.stack([gold, own, missing]), init={"clearcoat": 0.5})
    for row, alone in enumerate((pb.fit(wi, wo, gold, init={"clearcoat": 0.5}),
                                 pb.fit(wi, wo, own, init={"clearcoat": 0.5}))):
        np.testing.assert_array_equal(batch.slots[row], alone.slots)
        assert batch.cost[row] == alone.cost
    # the problem without data keeps its start (clearcoat 0.5), and no note counts it
    assert float(batch.material.clearcoat[2]) == 0.5
    assert any(note.startswith("clearcoat held off in 1 of 3 problems") for note in batch.notes)


def test_a_lobe_held_by_equal_bounds_is_not_selected(pairs):
    wi, wo = pairs
    result = pb.fit(wi, wo, GOLD(wi, wo), bounds={"clearcoat": (0.3, 0.3)})
    assert float(result.material.clearcoat) == 0.3
    assert not any(note.startswith("clearcoat") for note in result.notes)


def test_select_lobes_is_checked(pairs):
    wi, wo = pairs
    with pytest.raises(TypeError, match="select_lobes"):
        pb.fit(wi[:100], wo[:100], GOLD(wi[:100], wo[:100]), select_lobes="yes")
