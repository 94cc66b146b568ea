"""Regressions of pb.fit and principled_brdf.distributed (docs/fitting.md, docs/distributed.md):
each defect found once, held by the test that found it.

- The scipy method left a parameter on the bound it started at (one iteration, success).
- The relative loss settled on a dark dielectric of a rough copper's data from the default start.
- The methods took different models (the batched one refused the 2015 models), and none fitted
  the 2015 models' own parameters.
- A tiled evaluation named a bad texel by its index in its tile; a string for textures failed
  inside dict().
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import principled_brdf as pb
from conftest import random_direction_pairs, seeded_rng
from principled_brdf._gradient import GRADIENT_NAMES_2015

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "fitting"))
from known_answers import normal_albedo  # noqa: E402

METHODS = [dict(method="batched"), dict(method="batched", precision="float64"), dict(method="scipy")]
METHOD_IDS = ["batched", "float64", "scipy"]


# ------------------------------------------------------------------ a parameter that starts on its bound

@pytest.mark.parametrize("fitted", [["clearcoat"], ["sheen", "clearcoat"]])
def test_the_scipy_method_moves_parameters_off_the_bound_they_start_on(fitted):
    # the 2014 model: its derivatives in clearcoat and sheen at 0 are those of the lobes they weigh
    pytest.importorskip("scipy")
    wi, wo = random_direction_pairs(seeded_rng("off-the-bound"), 400, min_cos=0.05)
    truth = dict(base_color=(0.5, 0.3, 0.2), roughness=0.4, clearcoat=0.8, clearcoat_gloss=0.7, sheen=0.6)
    measured = pb.reference.eval(pb.Material(**truth), wi, wo)
    start = dict(truth, **{name: 0.0 for name in fitted})
    for method in ("scipy", "batched"):
        result = pb.fit(wi, wo, measured, init=start, fit=fitted, method=method)
        assert result.iterations > 1, method
        for name in fitted:
            assert float(getattr(result.material, name)) == pytest.approx(truth[name], abs=2e-3), (method, name)


# ------------------------------------------------------------------ the relative loss on a rough conductor

def test_the_relative_loss_does_not_settle_on_a_dark_dielectric_of_a_rough_copper():
    # copper's complex index under a Beckmann distribution (pb.synthetic: exact Fresnel, Smith G2),
    # at a MERL table's cells; from the default start alone the fit ended at metallic 0 and
    # base_color 0.01, 91 % of the albedo at normal incidence missing
    copper = pb.synthetic.conductor("copper", 0.5)
    wi, wo = pb.measured.merl_pairs(step=(1, 3, 12))
    measured = copper(wi, wo)
    result = pb.fit(wi, wo, measured, loss="relative")
    dielectric_start = pb.fit(wi, wo, measured, loss="relative", init=pb.Material())
    assert result.cost <= dielectric_start.cost
    assert float(result.material.metallic) > 0.9
    albedo = normal_albedo(copper)
    fitted = normal_albedo(lambda a, b: pb.reference.eval(result.material, a, b))
    assert np.max(np.abs(fitted / albedo - 1.0)) < 0.8


# ------------------------------------------------------------------ one rule for the models

def whole_sphere_pairs(n, key):
    """Views above the surface, lights on the whole sphere (a third below: the transmission)."""
    wi, wo = random_direction_pairs(seeded_rng(key), n, min_cos=0.05)
    below = np.arange(n) % 3 == 0
    wi[below, 2] = -wi[below, 2]
    return wi, wo


@pytest.mark.parametrize("model, own", [("disney2015", {"flatness": 0.5, "spec_trans": 0.3}),
                                        ("disney2015_thin", {"flatness": 0.5, "spec_trans": 0.3, "diff_trans": 0.8})])
@pytest.mark.parametrize("options", METHODS, ids=METHOD_IDS)
def test_every_method_recovers_the_2015_models_own_parameters(model, own, options):
    if options["method"] == "scipy":
        pytest.importorskip("scipy")
    wi, wo = whole_sphere_pairs(300, model)
    truth = pb.Material(base_color=(0.6, 0.4, 0.2), roughness=0.4, **own)
    measured = pb.eval(truth, wi, wo, model=model).astype(np.float64)
    fitted = ["base_color", "roughness", *own]
    result = pb.fit(wi, wo, measured, model=model, fit=fitted, **options)
    assert result.slots.shape == (16,)
    assert result.names == tuple(n for n in GRADIENT_NAMES_2015
                                 if n in ("base_color_r", "base_color_g", "base_color_b", "roughness", *own))
    for name in ("roughness", *own):
        assert float(getattr(result.material, name)) == pytest.approx(float(getattr(truth, name)), abs=2e-3), name
    np.testing.assert_allclose(result.material.base_color, truth.base_color, atol=2e-3)


@pytest.mark.parametrize("model", ["disney2014", "disney2012", "disney2015", "disney2015_thin"])
@pytest.mark.parametrize("options", METHODS, ids=METHOD_IDS)
def test_every_method_takes_every_model_and_fits_what_it_reads(model, options):
    if options["method"] == "scipy":
        pytest.importorskip("scipy")
    wi, wo = random_direction_pairs(seeded_rng("every-model"), 64, min_cos=0.1)
    measured = pb.reference.eval(pb.Material(roughness=0.3, metallic=0.5), wi, wo, model=model)
    result = pb.fit(wi, wo, measured, model=model, max_iterations=3, **options)
    reads = [name for name in pb.PARAMETERS if name not in pb.material.unread_parameters(model)]
    assert result.slots.shape == ((16,) if model.startswith("disney2015") else (13,))
    # (the pairs' half vectors lie at many azimuths: anisotropic is fitted too)
    assert {name.removesuffix("_r").removesuffix("_g").removesuffix("_b") for name in result.names} == set(reads)
    for name in pb.material.unread_parameters(model):
        with pytest.raises(ValueError, match=rf"^fit: model '{model}' does not read '{name}'"):
            pb.fit(wi, wo, measured, model=model, fit=[name], **options)


def test_a_tiled_fit_takes_the_2015_models():
    pytest.importorskip("dask.array")
    from principled_brdf import distributed as pbd

    wi, wo = whole_sphere_pairs(120, "tiled-2015")
    truth = pb.Material(base_color=(0.6, 0.4, 0.2), roughness=0.4, flatness=0.5, spec_trans=0.3)
    measured = np.broadcast_to(pb.eval(truth, wi, wo, model="disney2015").astype(np.float64), (2, 3, 120, 3))
    options = dict(model="disney2015", fit=["base_color", "roughness", "flatness", "spec_trans"])
    texture = pbd.fit(wi, wo, measured, **options)
    slots, = pbd.compute(texture.slots, progress=False)
    assert slots.shape == (2, 3, 16)
    np.testing.assert_array_equal(slots, np.broadcast_to(pb.fit(wi, wo, measured[0, 0], **options).slots, slots.shape))
    fitted = texture.material()
    np.testing.assert_allclose(fitted.flatness, 0.5, atol=2e-3)
    np.testing.assert_allclose(fitted.spec_trans, 0.3, atol=2e-3)


# ------------------------------------------------------------------ distributed: bad texels and textures

def test_a_tiled_evaluation_names_a_bad_texel_by_its_index_in_the_texture():
    da = pytest.importorskip("dask.array")
    from principled_brdf import distributed as pbd

    wi = np.broadcast_to(np.float32([0.0, 0.6, 0.8]), (40, 30, 3)).copy()
    roughness = np.full((40, 30), 0.5, np.float32)
    roughness[30, 20] = -0.5
    f = pbd.eval(pb.Material(), da.from_array(wi, chunks=(16, 16, 3)), [0.0, 0.0, 1.0],
                 textures={"roughness": da.from_array(roughness, chunks=(16, 16))})
    with pytest.raises(ValueError, match=r"^roughness\[30, 20\]: "):
        f.compute()
    base_color = np.full((40, 30, 3), 0.5, np.float32)
    base_color[25, 17, 2] = np.nan
    f = pbd.eval(pb.Material(), da.from_array(wi, chunks=(16, 16, 3)), [0.0, 0.0, 1.0],
                 textures={"base_color": da.from_array(base_color, chunks=(16, 16, 3))})
    with pytest.raises(ValueError, match=r"^base_color\[25, 17, 2\]: "):
        f.compute()
    bad_wi = wi.copy()
    bad_wi[33, 21] = (0.0, 0.0, 2.0)
    with pytest.raises(ValueError, match=r"^wi\[33, 21\]: "):
        pbd.eval(pb.Material(), da.from_array(bad_wi, chunks=(16, 16, 3)), [0.0, 0.0, 1.0]).compute()


def test_a_tiled_fit_names_a_bad_texel_by_its_index_in_the_texture():
    da = pytest.importorskip("dask.array")
    from principled_brdf import distributed as pbd

    wi, wo = random_direction_pairs(seeded_rng("tiled-bad-texel"), 8, min_cos=0.1)
    measured = np.full((20, 18, 8, 3), 0.1)
    measured[17, 11, 5, 1] = 1e39  # beyond float32
    texture = pbd.fit(wi, wo, da.from_array(measured, chunks=(8, 8, 8, 3)), fit=["roughness"], max_iterations=2)
    with pytest.raises(ValueError, match=r"^measured\[17, 11, 5, 1\]: "):
        pbd.compute(texture.slots, progress=False)


def test_textures_must_be_a_mapping():
    pytest.importorskip("dask.array")
    from principled_brdf import distributed as pbd

    wi = np.broadcast_to(np.float32([0.0, 0.6, 0.8]), (4, 4, 3))
    with pytest.raises(TypeError, match=r"^textures: expected a mapping \{name: array\}, got str"):
        pbd.eval(pb.Material(), wi, [0.0, 0.0, 1.0], textures="roughness")
