"""The batched SIMD API (pb.eval, pb.eval_lobes, pb.cpu_info): layouts,
broadcasting, out=, threads, instruction-set selection and its bad input."""

import os
import re
import subprocess
import sys

import numpy as np
import pytest

import principled_brdf as pb
from conftest import random_direction_pairs, random_directions, random_material_arrays, seeded_rng

ISAS = pb.cpu_info()["available"]


def test_cpu_info_reports_the_active_isa():
    info = pb.cpu_info()
    assert info["isa"] in info["available"]
    assert info["isa"] == info["available"][-1]  # the best is chosen by default
    assert info["float_lanes"] in (4, 8, 16)
    assert info["threads"] >= 1


@pytest.mark.parametrize("isa", ISAS)
def test_environment_forces_an_isa(isa):
    code = "import principled_brdf as pb; print(pb.cpu_info()['isa'])"
    env = dict(os.environ, PRINCIPLED_BRDF_ISA=isa)
    result = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert result.stdout.strip() == isa


def test_environment_with_an_unknown_isa_is_an_error():
    code = "import principled_brdf as pb; pb.cpu_info()"
    env = dict(os.environ, PRINCIPLED_BRDF_ISA="avx9000")
    result = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert result.returncode != 0
    assert "PRINCIPLED_BRDF_ISA" in result.stderr and "avx9000" in result.stderr


@pytest.mark.parametrize("isa", ISAS)
def test_results_do_not_depend_on_threads(isa):
    rng = seeded_rng("threads", isa)
    n = 200_003
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, n))
    material = pb.Material(**random_material_arrays(rng, n))
    one = pb.eval(material, wi, wo, threads=1, isa=isa)
    for threads in (2, 3, 7):
        np.testing.assert_array_equal(pb.eval(material, wi, wo, threads=threads, isa=isa), one)


def test_calls_from_several_python_threads_and_a_forked_child_share_the_pool_safely():
    """The pool runs one call at a time, its workers polling between calls: calls
    racing from Python threads, back to back, each get their own exact result,
    and a child forked after the pool started makes its own."""
    from concurrent.futures import ThreadPoolExecutor

    rng = seeded_rng("pool")
    n = 70_001  # several chunks, so that every call wakes a worker
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, n))
    materials = [pb.Material(roughness=r, clearcoat=0.5, sheen=0.3) for r in (0.1, 0.4, 0.7, 1.0)]
    expected = [pb.eval(m, wi, wo, threads=1) for m in materials]
    with ThreadPoolExecutor(max_workers=4) as callers:
        for _ in range(10):
            results = list(callers.map(lambda m: pb.eval(m, wi, wo, threads=2), materials))
            for got, want in zip(results, expected):
                np.testing.assert_array_equal(got, want)
    code = ("import os, numpy as np, principled_brdf as pb\n"
            "wi = np.tile(np.float32([0.6, 0, 0.8]), (70001, 1))\n"
            "m = pb.Material(roughness=0.4)\n"
            "want = pb.eval(m, wi, wi, threads=2)\n"
            "pid = os.fork()\n"
            "if pid == 0:\n"
            "    os._exit(0 if np.array_equal(pb.eval(m, wi, wi, threads=2), want) else 3)\n"
            "_, status = os.waitpid(pid, 0)\n"
            "raise SystemExit(os.waitstatus_to_exitcode(status))\n")
    child = subprocess.run([sys.executable, "-c", code], timeout=60)
    assert child.returncode == 0


@pytest.mark.parametrize("isa", ISAS)
def test_uniform_and_per_element_materials_agree_bitwise(isa):
    rng = seeded_rng("uniform", isa)
    n = 5000
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, n))
    params = dict(roughness=0.3, anisotropic=0.6, sheen=0.5, clearcoat=1.0, subsurface=0.4, metallic=0.25)
    uniform = pb.Material(**params)
    per_element = pb.Material(**{k: np.full(n, v) for k, v in params.items()}, base_color=np.tile([0.82, 0.67, 0.16], (n, 1)))
    np.testing.assert_array_equal(pb.eval(uniform, wi, wo, isa=isa), pb.eval(per_element, wi, wo, isa=isa))


def test_broadcasting_leading_shapes():
    rng = seeded_rng("broadcast")
    wi = random_directions(rng, (4, 5)).astype(np.float32)
    wo = random_directions(rng, 1)[0].astype(np.float32)  # one view direction for all
    roughness = np.linspace(0.0, 1.0, 5)
    f = pb.eval(pb.Material(roughness=roughness), wi, wo)
    assert f.shape == (4, 5, 3) and f.dtype == np.float32
    expected = pb.reference.eval(pb.Material(roughness=roughness), wi.astype(np.float64), wo.astype(np.float64))
    np.testing.assert_allclose(f, expected, rtol=1e-4, atol=1e-7)
    # (4, 1) against (1, 5): materialised broadcast
    g = pb.eval(pb.Material(), wi[:, :1], wi[None, 0, :, :])
    assert g.shape == (4, 5, 3)


def test_soa_layout_shapes_and_single_vectors():
    rng = seeded_rng("soa")
    wi = np.ascontiguousarray(random_directions(rng, (2, 3)).astype(np.float32).transpose(2, 0, 1))  # (3, 2, 3)
    wo = np.array([0.0, 0.0, 1.0], np.float32)
    f = pb.eval(pb.Material(), wi, wo, layout="soa")
    assert f.shape == (3, 2, 3)
    np.testing.assert_array_equal(f, np.moveaxis(pb.eval(pb.Material(), np.moveaxis(wi, 0, -1), wo), -1, 0))


def test_other_dtypes_and_strides_are_converted():
    rng = seeded_rng("dtypes")
    wi64, wo64 = random_direction_pairs(rng, 1000)
    expected = pb.eval(pb.Material(), wi64.astype(np.float32), wo64.astype(np.float32))
    np.testing.assert_array_equal(pb.eval(pb.Material(), wi64, wo64), expected)  # float64 in
    strided = np.asfortranarray(wi64.astype(np.float32))
    np.testing.assert_array_equal(pb.eval(pb.Material(), strided, wo64.tolist()), expected)  # F-order, lists


def test_out_is_filled_and_returned():
    rng = seeded_rng("out")
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, 100))
    out = np.full((100, 3), np.nan, np.float32)
    result = pb.eval(pb.Material(), wi, wo, out=out)
    assert result is out
    np.testing.assert_array_equal(out, pb.eval(pb.Material(), wi, wo))


@pytest.mark.parametrize(
    "out, error, message",
    [
        (np.zeros((100, 3), np.float64), TypeError, "out: expected dtype float32"),
        (np.zeros((99, 3), np.float32), ValueError, "out: expected shape (100, 3)"),
        (np.zeros((3, 100), np.float32).T, ValueError, "out: expected a writeable C-contiguous"),
        ([[0.0] * 3] * 100, TypeError, "out: expected a numpy array"),
    ],
)
def test_bad_out(out, error, message):
    rng = seeded_rng("bad-out")
    wi, wo = random_direction_pairs(rng, 100)
    with pytest.raises(error, match=message.replace("(", r"\(").replace(")", r"\)")):
        pb.eval(pb.Material(), wi, wo, out=out)


def test_bad_direction_in_out_call_is_named_and_out_holds_only_right_values():
    # docs/bad-input.md: the check rides along with the evaluation, so out=
    # may hold partial results after the error, each of them right.
    rng = seeded_rng("bad-direction")
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, 50_000))
    wi[31_337] *= 1.01
    out = np.full((50_000, 3), -1.0, np.float32)
    with pytest.raises(ValueError, match=r"wi\[31337\]: length 1.01 is not 1"):
        pb.eval(pb.Material(), wi, wo, out=out)
    written = np.all(out != -1.0, axis=1)
    assert not written[31_337]
    np.testing.assert_array_equal(out[written], pb.eval(pb.Material(), wi[written], wo[written]))
    wi[31_337] /= 1.01
    wo[7, 1] = np.nan
    with pytest.raises(ValueError, match=r"wo\[7\]: .* is not a finite vector"):
        pb.eval(pb.Material(), wi, wo, check=True, threads=1)


def test_check_false_skips_the_direction_checks():
    wi = np.array([[0.0, 0.0, 2.0], [np.nan, 0.0, 1.0]], np.float32)
    wo = np.array([0.0, 0.0, 1.0], np.float32)
    f = pb.eval(pb.Material(), wi, wo, check=False)
    assert np.all(np.isfinite(f[0])) and np.all(f[1] == 0.0)  # a non-finite direction gives 0


@pytest.mark.parametrize(
    "kwargs, error, message",
    [
        (dict(layout="xyz"), ValueError, "layout: expected 'aos'"),
        (dict(threads=0), ValueError, "threads: expected at least 1"),
        (dict(threads=1.5), TypeError, "threads: expected an integer"),
        (dict(isa="avx9000"), ValueError, "isa: 'avx9000' is not available"),
        (dict(model="disney2099"), ValueError, "model: expected one of"),
    ],
)
def test_bad_options(kwargs, error, message):
    wi = np.array([0.0, 0.0, 1.0])
    with pytest.raises(error, match=message):
        pb.eval(pb.Material(), wi, wi, **kwargs)


def test_soa_shape_errors_name_the_argument():
    with pytest.raises(ValueError, match=r"wi: expected shape \(3, \.\.\.\) with layout='soa'"):
        pb.eval(pb.Material(), np.zeros((5, 3), np.float32), np.zeros((3, 5), np.float32), layout="soa")


def test_empty_input():
    f = pb.eval(pb.Material(), np.zeros((0, 3)), np.zeros((0, 3)))
    assert f.shape == (0, 3)


@pytest.mark.parametrize("name, value, limit", [("roughness", 1e5, "10000"), ("sheen", 1e25, "1e+20"),
                                                ("base_color", (0.5, 1e21, 0.5), "1e+20")])
def test_parameters_beyond_float32_range_are_refused_not_nan(name, value, limit):
    wi = np.array([0.3, 0.2, np.sqrt(0.87)])
    material = pb.Material(**{name: value})
    assert np.all(np.isfinite(pb.reference.eval(material, wi, wi)))  # the float64 reference takes them
    for call in (lambda: pb.eval(material, wi, wi), lambda: pb.sample(material, wi, seed=1),
                 lambda: pb.pdf(material, wi, wi)):
        with pytest.raises(ValueError, match=f"{name}.*beyond what the float32 kernels represent \\(<= {re.escape(limit)}\\)"):
            call()


@pytest.mark.parametrize("isa", ISAS)
def test_largest_float32_parameters_stay_finite(isa):
    rng = seeded_rng("largest", isa)
    wi, wo = (w.astype(np.float32) for w in random_direction_pairs(rng, 20_000))
    material = pb.Material(roughness=1e4, base_color=(1e20, 1e20, 1e20), specular=1e20, sheen=1e20, clearcoat=1e20)
    assert np.all(np.isfinite(pb.eval(material, wi, wo, isa=isa)))
    s = pb.sample(material, wo, seed=3, isa=isa)
    assert all(np.all(np.isfinite(a)) for a in s[:3])
