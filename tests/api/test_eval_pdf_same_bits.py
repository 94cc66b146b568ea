"""pb.eval_pdf: f and the sampling pdf in one kernel pass, the same bits as eval and pdf."""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb
from conftest import MODELS, random_direction_pairs, random_material_arrays, seeded_rng

ISAS = tuple(pb.cpu_info()["available"])


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("model", MODELS)
def test_same_bits_as_eval_and_pdf(isa, model):
    rng = seeded_rng("eval-pdf", model)
    n = 20_011
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, n))
    wi[::9] *= np.float32([1, 1, -1])  # some below the horizon
    for material in (pb.Material(**random_material_arrays(rng, n)), pb.presets.get("car_paint")):
        for sampler in ("visible", "distribution"):
            for cosine in (False, True):
                both = pb.eval_pdf(material, wi, wo, model=model, cosine=cosine, specular_sampler=sampler, isa=isa)
                np.testing.assert_array_equal(both.value, pb.eval(material, wi, wo, model=model, cosine=cosine, isa=isa))
                np.testing.assert_array_equal(both.pdf, pb.pdf(material, wi, wo, specular_sampler=sampler, isa=isa))
        soa = pb.eval_pdf(material, np.ascontiguousarray(wi.T), np.ascontiguousarray(wo.T), model=model, layout="soa",
                          isa=isa, threads=1)
        np.testing.assert_array_equal(soa.value.T, pb.eval(material, wi, wo, model=model, isa=isa))


def test_out_and_bad_input():
    rng = seeded_rng("eval-pdf-api")
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, 33))
    m = pb.Material(roughness=0.2)
    value, density = np.empty((33, 3), np.float32), np.empty(33, np.float32)
    result = pb.eval_pdf(m, wi, wo, out=(value, density))
    assert result.value is value and result.pdf is density
    with pytest.raises(TypeError, match="out: expected a tuple"):
        pb.eval_pdf(m, wi, wo, out=value)
    with pytest.raises(ValueError, match="out: the value and pdf arrays overlap"):
        pb.eval_pdf(m, wi, wo, out=(value, value.reshape(-1)[:33]))
    bad = wo.copy()
    bad[5] = np.nan
    with pytest.raises(ValueError, match=r"wo\[5\]"):
        pb.eval_pdf(m, wi, bad)
