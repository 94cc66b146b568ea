"""A few of the fit benchmark's materials (bench/fit_quality.py, docs/fitting.md#the-benchmark),
fitted as a user fits a table, ``pb.fit(wi, wo, values)``, and held to bounds a little
above the benchmark's figures for them: the albedos at normal incidence and over the
hemisphere, the image error under the studio and the outdoor maps, and no lobe that the
material's kind has no use for. A change that makes the default fit worse on data of other
models fails here.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import principled_brdf as pb

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))
import fit_quality as benchmark  # noqa: E402

# name -> (albedo bound, image error bound)
BOUNDS = {
    "copper, GGX α 0.15": (0.03, 0.04),
    "silver, Beckmann α 0.15": (0.05, 0.25),
    "red plastic, Lambert under GGX α 0.1": (0.06, 0.10),
    "white plastic, Oren-Nayar σ 0.3 under Beckmann α 0.08": (0.03, 0.10),
    "gold, Beckmann α 0.2, cells missing": (0.10, 0.25),
}


@pytest.fixture(scope="module")
def cases():
    return {name: (kind, complete, fitted) for name, kind, complete, fitted in benchmark.cases(list(BOUNDS))}


@pytest.mark.parametrize("name", list(BOUNDS))
def test_the_default_fit_of_another_models_table(name, cases):
    kind, complete, fitted = cases[name]
    wi, wo = pb.measured.merl_pairs(step=benchmark.MERL_STEP)
    result = pb.fit(wi, wo, fitted.values(step=benchmark.MERL_STEP))
    data_albedos = benchmark.albedos(lambda a, b: complete.eval(a, b, interpolation="linear"))
    figures = benchmark.measure_fit(result, data_albedos, benchmark.pictures(complete))
    albedo_bound, image_bound = BOUNDS[name]
    summary = f"{name}: {figures}\n{result.summary()}"
    assert figures["normal_albedo"] <= albedo_bound, summary
    assert figures["hemispherical_albedo"] <= albedo_bound, summary
    assert max(figures["image"]) <= image_bound, summary
    assert not [lobe for lobe in benchmark.UNNEEDED[kind] if lobe in figures["lobes"]], summary


def test_the_albedo_quadrature_agrees_with_monte_carlo():
    """The benchmark's albedos: its half-vector quadrature against pb.albedo's 2^20 samples."""
    material = pb.Material(base_color=(0.2, 0.5, 0.7), roughness=0.1, metallic=0.3, clearcoat=0.5)
    normal, _ = benchmark.albedos(benchmark.fitted_f(material))
    estimate = pb.albedo(material, 1.0, samples=1 << 20)
    np.testing.assert_allclose(normal, estimate.total, rtol=2e-3)


def test_an_anisotropic_table_is_the_mean_over_azimuths():
    """A table holds an isotropic BRDF: of Ward's brushed metal, its mean over the half
    vector's azimuth, whose albedo is the material's (a slice would be four times too bright)."""
    ward = pb.synthetic.ward("gold", 0.2, 0.05)
    table = benchmark.table_of(ward)
    normal_table, _ = benchmark.albedos(lambda a, b: table.eval(a, b, interpolation="linear"))
    normal_truth, _ = benchmark.albedos(ward)
    np.testing.assert_allclose(normal_table, normal_truth, rtol=0.01)
