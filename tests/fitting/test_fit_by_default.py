"""The default pb.fit is right on measurements it was not made from (docs/fitting.md#losses).

Conductors (Beckmann and GGX, complex indices), Lambert + GGX plastics and a
Beckmann dielectric over a dusty floor (``pb.synthetic``) are written as MERL
files with ``save_merl`` and read back; the library's own model is measured
with 5 % noise. The call a newcomer makes, ``pb.fit(wi, wo, values)``, must
recover the directional albedo at normal incidence within 5 % per channel and
the peak of the reflected lobe within one table cell, and hold ``anisotropic``
at 0 on a table's isotropic data, saying so. How the figures are measured:
tests/fitting/known_answers.py.
"""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb
import known_answers as quality
from principled_brdf._loss_scale import log_scale

pytest.importorskip("scipy")

ALBEDO_TOLERANCE = 0.05
PEAK_CELLS = 1


@pytest.fixture(scope="module")
def measurements(tmp_path_factory):
    """name -> (wi, wo, measured values) at the coarse cells, the other models' through a MERL file."""
    folder = tmp_path_factory.mktemp("merl")
    read = {}
    for k, (name, (f, noise)) in enumerate(quality.CASES.items()):
        values = None
        if f is not quality.own_model:
            path = folder / f"case{k}.binary"
            pb.measured.save_merl(path, f)
            values = pb.measured.load_merl(path).values(step=quality.MERL_STEP)
        read[name] = quality.measure(f, noise, values)
    return read


@pytest.mark.parametrize("name", list(quality.CASES))
def test_the_default_fit_recovers_albedo_and_peak(name, measurements):
    truth = quality.CASES[name][0]
    wi, wo, measured = measurements[name]
    result = pb.fit(wi, wo, measured)
    albedo_error, peak_error = quality.errors(truth, result)
    assert albedo_error <= ALBEDO_TOLERANCE, (f"{name}: albedo at normal incidence off by {albedo_error:.1%}\n"
                                              f"{result.summary()}")
    assert peak_error <= PEAK_CELLS, f"{name}: the peak {peak_error} cells away\n{result.summary()}"
    # a table's pairs are isotropic: anisotropy held at 0, and said
    assert "anisotropic" not in result.names and float(result.material.anisotropic) == 0.0
    assert "anisotropic held" in result.summary()


def test_far_starts_reach_the_default_fits_minimum(measurements):
    """One basin for the default loss from a glossy metal and a rough grey dielectric: the
    default start needs no company (docs/fitting.md#starts)."""
    wi, wo, measured = measurements["gold, Beckmann α 0.2"]
    default = pb.fit(wi, wo, measured)
    for start in (dict(metallic=1.0, roughness=0.1), dict(base_color=(0.3, 0.3, 0.3), roughness=0.9)):
        other = pb.fit(wi, wo, measured, init=start)
        assert float(other.cost) == pytest.approx(float(default.cost), rel=1e-4), start
        np.testing.assert_allclose(quality.normal_albedo(quality.fitted_f(other)),
                                   quality.normal_albedo(quality.fitted_f(default)), rtol=1e-3)


def test_the_default_losss_scale_follows_the_data():
    """s is the median of m c, at least a tenth of its mean: a copy ten times darker has an s
    ten times smaller (the loss is the same for both), a glossy metal's nearly black bulk does
    not set it, a black measurement keeps it finite."""
    rng = np.random.default_rng(4)
    m, c = rng.uniform(0.0, 2.0, (500, 3)), rng.uniform(0.0, 1.0, 500)
    assert log_scale(m, c) == pytest.approx(np.median(m * c[:, None]), rel=1e-12)
    assert log_scale(0.1 * m, c) == pytest.approx(0.1 * log_scale(m, c), rel=1e-12)
    glossy = np.zeros((1000, 3))
    glossy[:50] = 40.0  # 5 % of the samples hold the lobe: the median is 0
    assert log_scale(glossy, np.ones(1000)) == pytest.approx(0.1 * 2.0, rel=1e-12)
    assert log_scale(np.zeros((10, 3)), np.ones(10)) == 1e-9


def test_a_black_measurement_fits_towards_black():
    wi, wo = pb.measured.merl_pairs(step=(6, 6, 24))
    up = (wi[:, 2] > 0.05) & (wo[:, 2] > 0.05)
    result = pb.fit(wi[up], wo[up], np.zeros((int(up.sum()), 3)), max_iterations=30)
    assert np.isfinite(result.cost) and np.all(np.isfinite(result.slots))
    # as dark as the model goes: Schlick's grazing term stays (F -> 1 at θd -> 90° for any F0)
    fitted, default = (np.mean(pb.reference.eval(m, wi[up], wo[up])) for m in (result.material, pb.Material()))
    assert fitted < 0.05 * default


def test_losses_are_named():
    wi, wo = pb.measured.merl_pairs(step=(9, 9, 36))
    with pytest.raises(ValueError, match="loss: expected one of scaled_log, log, relative, linear"):
        pb.fit(wi, wo, np.ones_like(wi), loss="median")
