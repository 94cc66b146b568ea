"""Regressions of bad input (docs/bad-input.md): each defect found once, held by the test
that found it. Every call returns finite results, every element written, or raises a
ValueError/TypeError naming the argument (README "Bad input").

The kernels and their Python boundary: every element or an error, the direction check
decided once, aliasing, alignment, the edges of the integer options, and finite float32
results over the whole parameter range. The entry points beyond the kernels: pb.fit, MERL
files, the explorer and the command line.

Each test holds one behavior at the edge of what a caller can pass.
"""

from __future__ import annotations

import os
import threading

import numpy as np
import pytest

import principled_brdf as pb
from conftest import random_direction_pairs, seeded_rng
from principled_brdf._validate import DIRECTION_LENGTH2_BOUNDS, unit_length

ISAS = pb.cpu_info()["available"]
UP = np.float32([0, 0, 1])


def directions_at_length(rng, n, length):
    """Random upper-hemisphere float32 directions scaled to about ``length``."""
    v = rng.normal(size=(n, 3))
    v[:, 2] = np.abs(v[:, 2]) + 0.1
    return (v / np.linalg.norm(v, axis=1, keepdims=True) * length).astype(np.float32)


def misaligned(array: np.ndarray) -> np.ndarray:
    """A C-contiguous copy of ``array`` whose data starts one byte off alignment."""
    raw = np.empty(array.nbytes + 1, np.uint8)
    view = raw[1:].view(array.dtype).reshape(array.shape)
    view[...] = array
    assert view.flags.c_contiguous and not view.flags.aligned
    return view


# ------------------------------------------------------------------ the tolerance edge

@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("length", [1.001, 0.999])
def test_directions_at_the_tolerance_edge_are_decided_once(isa, length):
    # About half of these lie on each side of the edge: the call must raise,
    # naming the first one the rule rejects, and the rest must evaluate fully.
    rng = np.random.default_rng(3)
    wi = directions_at_length(rng, 100_000, length)
    passes = unit_length(wi)
    assert 0 < passes.sum() < len(wi)
    first_bad = int(np.flatnonzero(~passes)[0])
    for call in (lambda: pb.eval(pb.Material(), wi, UP, isa=isa),
                 lambda: pb.eval(pb.Material(), wi, UP, isa=isa, out=np.empty_like(wi)),
                 lambda: pb.eval_lobes(pb.Material(), wi, UP, isa=isa),
                 lambda: pb.pdf(pb.Material(), wi, UP, isa=isa),
                 lambda: pb.pdf(pb.Material(), UP, wi, isa=isa)):
        with pytest.raises(ValueError, match=rf"w[io]\[{first_bad}\]: length"):
            call()
    with pytest.raises(ValueError, match=rf"wo\[{first_bad}\]: length"):
        pb.sample(pb.Material(), wi, isa=isa)
    # The reference applies the same rule.
    with pytest.raises(ValueError, match=rf"wi\[{first_bad}\]: length"):
        pb.reference.eval(pb.Material(), wi, UP)

    good = wi[passes]
    for threads in (1, 2):
        out = np.full_like(good, np.nan)
        pb.eval(pb.Material(), good, UP, isa=isa, out=out, threads=threads)
        assert np.isfinite(out).all()
        s = pb.sample(pb.Material(), good, isa=isa, threads=threads)
        assert np.isfinite(s.wi).all() and np.isfinite(s.weight).all() and np.isfinite(s.pdf).all()
        assert np.isfinite(pb.pdf(pb.Material(), good, UP, isa=isa, threads=threads)).all()
    pb.reference.eval(pb.Material(), good[:100], UP)


def test_the_rule_is_float64_squared_length_within_the_bounds():
    lowest, highest = DIRECTION_LENGTH2_BOUNDS
    assert lowest == (1 - 1e-3) * (1 - 1e-3) and highest == (1 + 1e-3) * (1 + 1e-3)
    # the largest float32 x with x² inside the upper bound, and the next one
    x = np.float32(np.sqrt(highest))
    while float(x) * float(x) > highest:
        x = np.nextafter(x, np.float32(0))
    inside, outside = x, np.nextafter(x, np.float32(2))
    for isa in ISAS:
        pb.eval(pb.Material(), np.float32([0, 0, inside]), UP, isa=isa)
        with pytest.raises(ValueError, match="wi: length"):
            pb.eval(pb.Material(), np.float32([0, 0, outside]), UP, isa=isa)
    pb.reference.eval(pb.Material(), np.float32([0, 0, inside]), UP)
    with pytest.raises(ValueError, match="wi: length"):
        pb.reference.eval(pb.Material(), np.float32([0, 0, outside]), UP)


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("n", [1, 7, 16, 17, 100, 1000])
def test_a_bad_direction_anywhere_is_found_and_named(isa, n):
    rng = np.random.default_rng(n)
    for position in sorted({0, n // 2, n - 1}):
        wi = directions_at_length(rng, n, 1.0)
        wi[position] *= 1.01
        with pytest.raises(ValueError, match=rf"wi\[{position}\]"):
            pb.eval(pb.Material(), wi, UP, isa=isa, out=np.empty_like(wi))
        with pytest.raises(ValueError, match=rf"wo\[{position}\]"):
            pb.sample(pb.Material(), wi, isa=isa)


def test_a_bad_direction_is_named_in_its_own_shape_when_broadcast():
    wo = directions_at_length(np.random.default_rng(1), 4, 1.0).reshape(4, 1, 3)
    wo[2, 0] *= 2
    wi = directions_at_length(np.random.default_rng(2), 5, 1.0)
    with pytest.raises(ValueError, match=r"wo\[2, 0\]: length 2"):
        pb.eval(pb.Material(), wi, wo)


def test_out_holds_partial_results_after_an_error_and_is_right_where_written():
    wi = directions_at_length(np.random.default_rng(5), 10_000, 1.0)
    wi[7000] = np.nan
    out = np.full_like(wi, -1.0)
    with pytest.raises(ValueError, match=r"wi\[7000\]"):
        pb.eval(pb.Material(), wi, UP, out=out, threads=1)
    written = out[:, 0] != -1.0
    assert written[:6000].all()  # the elements before the bad one's batch
    expected = pb.eval(pb.Material(), wi[written], UP)
    np.testing.assert_array_equal(out[written], expected)


# ------------------------------------------------------------------ disney2012 at high roughness

@pytest.mark.parametrize("model", ["disney2014", "disney2012"])
def test_high_roughness_at_the_normal_is_finite_and_matches_the_reference(model):
    material = pb.Material(roughness=200)
    wi, wo = np.float32([0.6, 0, 0.8]), np.float32([0, 0, 1])
    expected = pb.reference.eval(material, wi, wo, model=model)
    for isa in ISAS:
        for a, b in ((wi, wo), (wo, wi)):
            f = pb.eval(material, a, b, model=model, isa=isa)
            np.testing.assert_allclose(f, expected, rtol=1e-5)


def float32_range_materials(rng, n):
    """Per-element materials over the whole range the float32 kernels accept."""
    limits = pb._batch.FLOAT32_LIMITS

    def log_uniform(high, size):
        values = 10.0 ** rng.uniform(-8, np.log10(high), size)
        values[rng.random(size) < 0.1] = 0.0
        values[rng.random(size) < 0.1] = high
        return values

    unit = lambda: np.where(rng.random(n) < 0.2, rng.integers(0, 2, n), rng.random(n))  # noqa: E731
    return pb.Material(
        base_color=log_uniform(limits["base_color"], (n, 3)), metallic=unit(), subsurface=unit(),
        specular=log_uniform(limits["specular"], n), specular_tint=unit(), roughness=log_uniform(limits["roughness"], n),
        anisotropic=unit(), sheen=log_uniform(limits["sheen"], n), sheen_tint=unit(),
        clearcoat=log_uniform(limits["clearcoat"], n), clearcoat_gloss=unit())


@pytest.mark.parametrize("model", ["disney2014", "disney2012"])
def test_every_output_is_finite_over_the_whole_float32_parameter_range(model):
    rng = np.random.default_rng(12)
    n = 200_000
    material = float32_range_materials(rng, n)
    wi = directions_at_length(rng, n, 1.0)
    wo = directions_at_length(rng, n, 1.0)
    # a third of the pairs with one direction at the normal, where 2012's Smith term cancelled
    wi[: n // 6] = UP
    wo[n // 6: n // 3] = UP
    for isa in ISAS:
        assert np.isfinite(pb.eval(material, wi, wo, model=model, isa=isa)).all()
        assert np.isfinite(pb.eval(material, wi, wo, model=model, cosine=True, isa=isa)).all()
        for lobe in pb.eval_lobes(material, wi, wo, model=model, isa=isa):
            assert np.isfinite(lobe).all()
        for sampler in ("visible", "distribution"):
            assert np.isfinite(pb.pdf(material, wi, wo, specular_sampler=sampler, isa=isa)).all()
            s = pb.sample(material, wo, seed=4, model=model, specular_sampler=sampler, isa=isa)
            for array in (s.wi, s.pdf, s.weight):
                assert np.isfinite(array).all()


# ------------------------------------------------------------------ aliasing

@pytest.mark.parametrize("isa", ISAS)
def test_out_partly_overlapping_an_input_is_refused(isa):
    buffer = directions_at_length(np.random.default_rng(8), 1001, 1.0)
    wi, shifted = buffer[:-1], buffer[1:]
    for argument in ("wi", "wo"):
        kwargs = {"wi": wi, "wo": UP} if argument == "wi" else {"wi": UP, "wo": wi}
        with pytest.raises(ValueError, match=f"out: overlaps {argument}"):
            pb.eval(pb.Material(), **kwargs, out=shifted, isa=isa)
    single = buffer[:1].reshape(3)  # one vector for every element, inside out
    with pytest.raises(ValueError, match="out: overlaps wo"):
        pb.eval(pb.Material(), wi[:500], single, out=buffer[:500], isa=isa)


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("layout", ["aos", "soa"])
def test_out_that_is_an_input_computes_in_place(isa, layout):
    rng = np.random.default_rng(9)
    wi = directions_at_length(rng, 999, 1.0)
    wo = directions_at_length(rng, 999, 1.0)
    if layout == "soa":
        wi, wo = np.ascontiguousarray(wi.T), np.ascontiguousarray(wo.T)
    material = pb.Material(roughness=0.3, clearcoat=1.0, sheen=0.5)
    expected = pb.eval(material, wi, wo, layout=layout, isa=isa)
    in_place = wi.copy()
    result = pb.eval(material, in_place, wo, layout=layout, isa=isa, out=in_place)
    assert result is in_place
    np.testing.assert_array_equal(in_place, expected)


# ------------------------------------------------------------------ alignment

@pytest.mark.parametrize("isa", ISAS)
def test_misaligned_inputs_are_converted(isa):
    rng = np.random.default_rng(10)
    wi = directions_at_length(rng, 101, 1.0)
    wo = directions_at_length(rng, 101, 1.0)
    u = rng.random((101, 3)).astype(np.float32)
    m = pb.Material(roughness=0.4)
    np.testing.assert_array_equal(pb.eval(m, misaligned(wi), misaligned(wo), isa=isa), pb.eval(m, wi, wo, isa=isa))
    np.testing.assert_array_equal(pb.pdf(m, misaligned(wi), misaligned(wo), isa=isa), pb.pdf(m, wi, wo, isa=isa))
    s, t = pb.sample(m, misaligned(wo), u=misaligned(u), isa=isa), pb.sample(m, wo, u=u, isa=isa)
    np.testing.assert_array_equal(s.weight, t.weight)
    np.testing.assert_array_equal(pb.reference.eval(m, misaligned(wi), wo), pb.reference.eval(m, wi, wo))
    per_element = pb.Material(roughness=misaligned(rng.random(101).astype(np.float32)))
    pb.eval(per_element, wi, wo, isa=isa)


def test_misaligned_out_is_refused():
    wi = directions_at_length(np.random.default_rng(11), 10, 1.0)
    with pytest.raises(ValueError, match="out: array data is not aligned"):
        pb.eval(pb.Material(), wi, UP, out=misaligned(np.zeros_like(wi)))


# ------------------------------------------------------------------ integer options and flags

@pytest.mark.parametrize("threads", [2**31, 2**63, -1, 0])
def test_threads_out_of_range(threads):
    with pytest.raises(ValueError, match="threads"):
        pb.eval(pb.Material(), UP, UP, threads=threads)


def test_a_huge_thread_count_in_range_works():
    wi = directions_at_length(np.random.default_rng(1), 100_000, 1.0)
    np.testing.assert_array_equal(pb.eval(pb.Material(), wi, UP, threads=2**31 - 1), pb.eval(pb.Material(), wi, UP))


@pytest.mark.parametrize("first, n", [(2**63, 1), (2**63 - 1, 2), (2**64, 0), (2**62, 2**62)])
def test_random_uniforms_index_range(first, n):
    with pytest.raises(ValueError, match="first"):
        pb.random_uniforms(1, n, first)


def test_random_uniforms_at_the_end_of_the_index_range():
    u = pb.random_uniforms(1, 1, 2**63 - 2)
    assert u.shape == (1, 3) and np.all((u >= 0) & (u < 1))


@pytest.mark.parametrize("value", [np.array([1, 2], dtype="timedelta64[s]"), np.array(["2020-01-01"], dtype="datetime64[D]")])
def test_time_arrays_are_not_numbers(value):
    with pytest.raises(TypeError, match="wi"):
        pb.eval(pb.Material(), value, UP)
    with pytest.raises(TypeError, match="roughness"):
        pb.Material(roughness=value)


@pytest.mark.parametrize("option", ["cosine", "check"])
@pytest.mark.parametrize("value", [np.array([True, False]), "yes", None, 1.0])
def test_flags_take_booleans_only(option, value):
    with pytest.raises(TypeError, match=option):
        pb.eval(pb.Material(), UP, UP, **{option: value})


def test_beyond_float32_is_not_called_infinite():
    with pytest.raises(ValueError, match=r"wi\[0\]: 1e\+300 is beyond float32"):
        pb.eval(pb.Material(), np.array([1e300, 0, 1]), UP)


def test_render_sphere_names_its_own_arguments():
    with pytest.raises(ValueError, match="light"):
        pb.render.render_sphere(pb.Material(), 16, light=(0, 0, 0))
    with pytest.raises(ValueError, match="light"):
        pb.render.render_sphere(pb.Material(), 16, light=(np.nan, 0, 1))
    with pytest.raises(TypeError, match="resolution"):
        pb.render.render_sphere(pb.Material(), None)
    with pytest.raises(ValueError, match="resolution"):
        pb.render.render_sphere(pb.Material(), 10**9)
    with pytest.raises(ValueError, match="ambient"):
        pb.render.render_sphere(pb.Material(), 16, ambient=-1)


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("bad", [np.nan, np.inf, 1e30])
def test_unchecked_sampling_of_a_bad_view_gives_zeros_not_nan(isa, bad):
    wo = directions_at_length(np.random.default_rng(2), 50, 1.0)
    wo[[0, 17, 49], 1] = bad
    s = pb.sample(pb.Material(metallic=1.0, clearcoat=1.0), wo, check=False, isa=isa, seed=3)
    for array in (s.wi, s.pdf, s.weight):
        assert np.isfinite(array).all()
    assert (s.weight[[0, 17, 49]] == 0).all() and (s.pdf[[0, 17, 49]] == 0).all()
    f = pb.eval(pb.Material(), wo, wo[::-1], check=False, isa=isa)
    assert np.isfinite(f).all()


@pytest.mark.parametrize("u", [1 + 1e-12, -1e-300])
def test_uniforms_are_checked_as_given_by_both_paths(u):
    values = np.array([[0.5, u, 0.5]])
    with pytest.raises(ValueError, match=r"u\[0, 1\]"):
        pb.sample(pb.Material(), UP, u=values)
    with pytest.raises(ValueError, match=r"u\[0, 1\]"):
        pb.reference.sample(pb.Material(), UP, values)


@pytest.mark.parametrize("isa", ISAS)
def test_batches_the_fast_test_cannot_decide_give_the_same_bits(isa):
    # Directions the rule accepts but the kernels' narrowed fast test does not
    # (length² within 1e-6 of the bound) make a loop stop, be decided element
    # by element and resume: wherever they sit (the sampling pipeline's
    # prologue, loop and epilogue, tails, thread chunks), every element is
    # written and the bits are those of the unchecked call.
    rng = np.random.default_rng(21)
    n = 40_000  # two thread chunks of 20032
    wo = directions_at_length(rng, n, 1.0)
    wi = directions_at_length(rng, n, 1.0)
    edge = np.float32(np.sqrt(DIRECTION_LENGTH2_BOUNDS[1]) * (1 - 1e-7))
    for k in (0, 1, 15, 16, 17, 40, 63, 64, 100, 500, 1023, 20031, 20032, 20040, n - 17, n - 1):
        wo[k] *= edge
        wi[(k * 7) % n] *= edge
    assert unit_length(wo).all() and unit_length(wi).all()
    roughness, clearcoat = rng.random(n), rng.random(n)
    materials = {"uniform": lambda start: pb.Material(clearcoat=0.7, sheen=0.3, roughness=0.4),
                 "per element": lambda start: pb.Material(roughness=roughness[start:], clearcoat=clearcoat[start:])}
    for make in materials.values():
        for threads in (1, 2):
            material = make(0)
            checked, unchecked = (pb.eval(material, wi, wo, isa=isa, threads=threads, check=c) for c in (True, False))
            np.testing.assert_array_equal(checked, unchecked)
            checked, unchecked = (pb.pdf(material, wi, wo, isa=isa, threads=threads, check=c) for c in (True, False))
            np.testing.assert_array_equal(checked, unchecked)
            for start in (0, 3, 8):
                a, b = (pb.sample(make(start), wo[start:], seed=5, isa=isa, threads=threads, check=c)
                        for c in (True, False))
                for x, y in zip(a, b):
                    np.testing.assert_array_equal(x, y)


def test_the_kernels_never_see_misaligned_data():
    # The Python side copies misaligned inputs; the bindings refuse any that
    # would still reach them, rather than hand the kernels a float* off alignment.
    n = 8
    wi = misaligned(np.tile(np.float32([0, 0, 1]), (n, 1)))
    params = pb._batch._parameter_views(pb.Material(), 1)  # (uniform: numbers)
    options = pb._core.EvalOptions(threads=1)
    wo = np.float32([0, 0, 1])
    with pytest.raises(ValueError, match="wi: array data is not aligned"):
        pb._core.batch_eval(wi=wi, wi_layout=0, wo=wo, wo_layout=2, params=params,
                            outputs=[np.empty((n, 3), np.float32)], out_layout=0, n=n, lobes=False, options=options)
    with pytest.raises(ValueError, match="out: array data is not aligned"):
        pb._core.batch_eval(wi=wi.copy(), wi_layout=0, wo=wo, wo_layout=2, params=params,
                            outputs=[misaligned(np.empty((n, 3), np.float32))], out_layout=0, n=n, lobes=False,
                            options=options)



def test_segments_reaching_past_an_input_are_refused():
    # a call in segments reads each input at its own offsets: the bindings
    # check that every segment's elements lie within the array, whatever the caller passed
    count, length = 4, 8
    n = count * length
    params = pb._batch._parameter_views(pb.Material(), 1)
    options = pb._core.EvalOptions(threads=1)
    wi = np.tile(np.float32([0, 0, 1]), (length, 1))
    wo = np.float32([0, 0, 1])
    out = [np.empty((n, 3), np.float32)]

    def call(offsets, single=False):
        tables = [offsets if k == 0 else None for k in range(3 + len(pb.PARAMETERS))]
        pb._core.batch_eval(wi=wi, wi_layout=2 if single else 0, wo=wo, wo_layout=2, params=params, outputs=out,
                            out_layout=0, n=n, lobes=False, options=options,
                            segments=(count, length, tables, [False] * len(pb.PARAMETERS)))

    call(np.zeros(count, np.int64))  # every segment reads the same rows
    with pytest.raises(ValueError, match="wi: a segment reaches past the array"):
        call(np.array([0, 0, 0, 3], np.int64))
    with pytest.raises(ValueError, match="segments: negative offset"):
        call(np.array([0, -3, 0, 0], np.int64))
    call(np.array([0, 3, 6, 3 * length - 3], np.int64), single=True)  # one vector a segment: 3 floats
    with pytest.raises(ValueError, match="wi: a segment reaches past the array"):
        call(np.array([0, 3, 6, 3 * length - 2], np.int64), single=True)
    with pytest.raises(ValueError, match="count \\* length == n"):
        pb._core.batch_eval(wi=wi, wi_layout=0, wo=wo, wo_layout=2, params=params, outputs=out, out_layout=0, n=n,
                            lobes=False, options=options, segments=(count, length + 1, [None] * 14, [False] * 11))

# ------------------------------------------------------------------ tiny colors, long vectors, frames, helpers

SUBNORMAL_COLORS = [(1e-39,) * 3, (1e-45, 0.0, 0.0), (0.0, 1e-40, 3e-39), (2e-38, 0.0, 0.0)]


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("model", ["disney2014", "disney2012"])
@pytest.mark.parametrize("base_color", SUBNORMAL_COLORS)
def test_a_color_of_subnormal_luminance_is_finite_and_matches_the_reference(isa, model, base_color):
    m = pb.Material(base_color=base_color, specular_tint=1.0, sheen=1.0, sheen_tint=1.0)
    rng = np.random.default_rng(31)
    wi, wo = directions_at_length(rng, 64, 1.0), directions_at_length(rng, 64, 1.0)
    f = pb.eval(m, wi, wo, model=model, isa=isa)
    reference = pb.reference.eval(m, wi, wo, model=model)
    assert np.isfinite(f).all() and np.isfinite(reference).all()
    np.testing.assert_allclose(f, reference, rtol=1e-4, atol=1e-30)
    assert np.isfinite(pb.pdf(m, wi, wo, model=model, isa=isa)).all()
    value, pdf = pb.eval_pdf(m, wi, wo, model=model, isa=isa)
    assert np.isfinite(value).all() and (pdf > 0).all()
    for lobe in pb.eval_lobes(m, wi, wo, model=model, isa=isa):
        assert np.isfinite(lobe).all()
    gradient = pb.eval_grad(m, wi, wo, model=model, isa=isa)
    assert np.isfinite(gradient.jacobian).all()
    s = pb.sample(m, wo, seed=5, model=model, isa=isa)
    assert np.isfinite(s.weight).all() and np.isfinite(s.pdf).all() and (s.pdf > 0).mean() > 0.5


def test_the_reference_takes_a_subnormal_color_as_untinted():
    rng = np.random.default_rng(32)
    wi, wo = directions_at_length(rng, 16, 1.0), directions_at_length(rng, 16, 1.0)
    tinted = dict(specular_tint=1.0, sheen=1.0, sheen_tint=1.0)
    for base_color in [(1e-310, 0.0, 0.0), (0.0, 0.0, 1e-39)]:
        f = pb.reference.eval(pb.Material(base_color=base_color, **tinted), wi, wo)
        black = pb.reference.eval(pb.Material(base_color=(0.0, 0.0, 0.0), **tinted), wi, wo)
        assert np.isfinite(f).all()
        np.testing.assert_allclose(f, black, rtol=1e-12, atol=1e-300)


@pytest.mark.parametrize("isa", ISAS)
@pytest.mark.parametrize("model", ["disney2014", "disney2012"])
def test_unchecked_long_vectors_give_zeros_not_nan(isa, model):
    m = pb.Material(roughness=1e4, subsurface=0.5, sheen=1.0, clearcoat=1.0)
    long = np.float32([[1e19, 0, 1], [1e12, 0, 1], [3.0, 0.0, 1.0], [0, 2.7, 0.1]])
    up = np.broadcast_to(UP, long.shape)
    for wi, wo in [(long, up), (up, long)]:
        f = pb.eval(m, wi, wo, model=model, isa=isa, check=False)
        assert np.isfinite(f).all() and (f == 0).all()
        assert (pb.pdf(m, wi, wo, model=model, isa=isa, check=False) == 0).all()
        gradient = pb.eval_grad(m, wi, wo, model=model, isa=isa, check=False)
        assert np.isfinite(gradient.jacobian).all() and (gradient.jacobian == 0).all()
    # within the bound, a non-unit pair is evaluated as given, the same on every instruction set
    wi, wo = np.float32([[1.5, 0.0, 1.0]]), np.float32([[0.0, 0.5, 1.5]])
    f = pb.eval(m, wi, wo, model=model, isa=isa, check=False)
    assert (f > 0).all()
    np.testing.assert_allclose(f, pb.eval(m, wi, wo, model=model, isa="sse2", check=False), rtol=1e-5)


def test_a_huge_tangent_gives_an_orthonormal_frame():
    frame = pb.frames.frame_from_normal([0, 0, 1], tangent=[1e200, 0, 0])
    np.testing.assert_allclose(frame, np.eye(3), atol=1e-15)
    frame = pb.frames.frame_from_normal([0, 0, 1], tangent=[1e-300, 1e-300, 0])
    np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-15)


def test_a_normal_within_the_tolerance_is_normalised():
    frame = pb.frames.frame_from_normal([0.0, 0.0009, 1.0009])
    np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-14)
    frame = pb.frames.frame_from_normal([0.0, 0.0, 1.0009], tangent=[1.0, 0.0, 0.3])
    np.testing.assert_allclose(frame @ frame.T, np.eye(3), atol=1e-14)


@pytest.mark.parametrize("tangent, message", [([0, 0, 2], r"tangent: zero or parallel"),
                                              ([np.nan, 0, 0], r"tangent\[0\]: nan"),
                                              ([[1, 0, 0], [0, 0, 0]], r"tangent\[1\]: zero or parallel")])
def test_bad_tangents_are_named(tangent, message):
    with pytest.raises(ValueError, match=message):
        pb.frames.frame_from_normal([0, 0, 1], tangent=tangent)


@pytest.mark.parametrize("convert", [pb.frames.to_local, pb.frames.to_world])
def test_frames_and_vectors_are_checked(convert):
    good = pb.frames.frame_from_normal([[0, 0, 1], [0, 1, 0]])
    np.testing.assert_allclose(convert([0, 0, 1], good)[0], [0, 0, 1], atol=1e-15)
    with pytest.raises(ValueError, match=r"frame\[1\]: rows not orthonormal"):
        convert([0, 0, 1], np.stack([good[0], 2 * good[1]]))
    with pytest.raises(ValueError, match=r"frame\[1, 0\]: nan"):
        convert([0, 0, 1], np.where(np.arange(9).reshape(3, 3) == 3, np.nan, good[0]))
    with pytest.raises(ValueError, match=r"frame: expected shape"):
        convert([0, 0, 1], np.eye(2))
    with pytest.raises(ValueError, match=r"w\[1\]: inf"):
        convert([0, np.inf, 1], good[0])


def test_angle_helpers_refuse_nan_and_opposite_directions():
    with pytest.raises(ValueError, match=r"theta: nan"):
        pb.frames.spherical_to_direction(np.nan)
    with pytest.raises(ValueError, match=r"phi\[1\]: inf"):
        pb.frames.spherical_to_direction(0.5, [0.0, np.inf])
    with pytest.raises(ValueError, match=r"theta_d: nan"):
        pb.frames.half_diff_to_wiwo(0.1, 0.0, np.nan, 0.0)
    w = np.array([[0.6, 0.0, 0.8], [0.0, 0.6, 0.8]])
    with pytest.raises(ValueError, match=r"wi\[1\], wo\[1\]: opposite directions"):
        pb.frames.wiwo_to_half_diff(w, np.array([[0.0, 0.0, 1.0], -w[1]]))


def test_display_colors_beyond_float64_are_refused():
    with pytest.raises(ValueError, match=r"color\[1\]: 1e\+300 \*\* 2.2 is beyond"):
        pb.gamma22_to_linear([0.5, 1e300])
    np.testing.assert_allclose(pb.gamma22_to_linear([0.5, 1e100]), [0.5 ** 2.2, 1e220])


def test_tone_mapping_takes_infinity_as_white_and_refuses_nan():
    pixels = np.array([[[np.inf, np.inf, np.inf], [np.inf, 0.0, 0.0], [0.5, 0.5, 0.5]]])
    srgb = pb.render.to_srgb8(pixels)
    assert (srgb[0, 0] == 255).all()
    assert srgb[0, 1, 0] == 255
    for curve in pb.render.TONE_CURVES:
        assert np.isfinite(pb.render.tone_map(pixels, curve=curve)).all()
    with pytest.raises(ValueError, match=r"linear\[0, 2, 1\]: nan"):
        pb.render.to_srgb8(np.where(np.arange(9).reshape(1, 3, 3) == 7, np.nan, pixels))


def test_linear_merl_lookups_at_cell_centres_ignore_neighbours_of_weight_zero():
    m = pb.Material(roughness=0.4)
    wi, wo = pb.measured.merl_pairs()
    table = pb.measured.MerlBRDF(pb.reference.eval(m, wi, wo).T.reshape((3,) + pb.measured.MERL_SHAPE))
    table.table[:, 40, 30, 90] = np.nan
    above = (wi[:, 2] > 0) & (wo[:, 2] > 0)
    linear = table.eval(wi[above], wo[above], interpolation="linear")
    nearest = table.eval(wi[above], wo[above], interpolation="nearest")
    missing = np.isnan(nearest).any(axis=1)
    assert missing.sum() == 1
    np.testing.assert_allclose(linear[~missing], nearest[~missing], rtol=1e-9)


def test_merl_tables_hold_brdf_values_or_nan():
    table = np.zeros((3,) + pb.measured.MERL_SHAPE)
    table[1, 2, 3, 4] = np.inf
    with pytest.raises(ValueError, match=r"table\[1, 2, 3, 4\]: inf is not a BRDF value"):
        pb.measured.MerlBRDF(table)
    with pytest.raises(ValueError, match=r"brdf\[5, 0\]: -1.0 is not a BRDF value"):
        pb.measured.save_merl("/nonexistent/never-written.binary",
                              lambda wi, wo: np.where(np.arange(len(wi))[:, None] == 5, -1.0, np.ones((len(wi), 3))))


# ------------------------------------------------------------------ empty calls, soa broadcasting, out= pairs

@pytest.mark.parametrize("layout", ["aos", "soa"])
def test_eval_grad_of_no_pairs(layout):
    empty = np.zeros((0, 3) if layout == "aos" else (3, 0), np.float32)
    gradient = pb.eval_grad(pb.Material(), empty, empty, layout=layout)
    assert gradient.value.shape == empty.shape
    assert gradient.jacobian.shape == ((0, 3, 13) if layout == "aos" else (3, 13, 0))
    assert pb.eval_grad(pb.Material(), empty, empty, wrt="roughness", layout=layout).jacobian.size == 0


def test_soa_arguments_of_lower_rank_broadcast_as_in_aos():
    rng = np.random.default_rng(40)
    a = directions_at_length(rng, 6, 1.0)
    b = directions_at_length(rng, 24, 1.0).reshape(4, 6, 3)
    roughness = rng.random(6)
    m = pb.Material(roughness=roughness)
    aos = pb.eval(m, a, b)
    soa = pb.eval(m, np.moveaxis(a, -1, 0), np.moveaxis(b, -1, 0), layout="soa")
    np.testing.assert_array_equal(np.moveaxis(soa, 0, -1), aos)
    np.testing.assert_array_equal(np.moveaxis(pb.eval(m, np.moveaxis(b, -1, 0), a[0][:, None], layout="soa"), 0, -1),
                                  pb.eval(m, b, a[0]))
    grad_aos = pb.eval_grad(m, a, b).jacobian
    grad_soa = pb.eval_grad(m, np.moveaxis(a, -1, 0), np.moveaxis(b, -1, 0), layout="soa").jacobian
    np.testing.assert_array_equal(np.moveaxis(grad_soa, (0, 1), (-2, -1)), grad_aos)
    u = rng.random((6, 3)).astype(np.float32)
    s_aos = pb.sample(m, b, u=u)
    s_soa = pb.sample(m, np.moveaxis(b, -1, 0), u=np.moveaxis(u, -1, 0), layout="soa")
    np.testing.assert_array_equal(np.moveaxis(s_soa.wi, 0, -1), s_aos.wi)
    s_n = pb.sample(pb.Material(), np.moveaxis(a, -1, 0), n=2, layout="soa", seed=1)
    np.testing.assert_array_equal(np.moveaxis(s_n.wi, 0, -1), pb.sample(pb.Material(), a, n=2, seed=1).wi)


def test_a_selected_jacobian_out_overlapping_wi_is_refused():
    rng = np.random.default_rng(41)
    buffer = np.empty(288, np.float32)
    wi = buffer[:192].reshape(64, 3)
    wi[...] = directions_at_length(rng, 64, 1.0)
    jacobian = buffer[96:].reshape(64, 3, 1)  # roughness's column only, over wi's second half
    before = wi.copy()
    with pytest.raises(ValueError, match=r"out\[1\]: overlaps wi"):
        pb.eval_grad(pb.Material(), wi, directions_at_length(rng, 64, 1.0), wrt="roughness",
                     out=(np.empty((64, 3), np.float32), jacobian))
    np.testing.assert_array_equal(wi, before)


@pytest.mark.parametrize("call", ["eval_grad", "eval_pdf"])
@pytest.mark.parametrize("missing", [0, 1])
def test_out_pairs_take_both_arrays(call, missing):
    wi = directions_at_length(np.random.default_rng(42), 8, 1.0)
    value = np.empty((8, 3), np.float32)
    second = np.empty((8, 3, 13) if call == "eval_grad" else (8,), np.float32)
    out = [value, second]
    out[missing] = None
    with pytest.raises(TypeError, match=rf"out\[{missing}\]: expected a float32 array, got None"):
        getattr(pb, call)(pb.Material(), wi, wi, out=tuple(out))


# =============================================================================================
# The entry points beyond the kernels: pb.fit, MERL files, the explorer and the command line.


def pairs(n, key="bad-entry"):
    return random_direction_pairs(seeded_rng(key), n, min_cos=0.05)


# ---------------------------------------------------------------------------------------------
# pb.fit


def test_fit_a_batch_with_a_problem_without_data_fits_the_others():
    wi, wo = pairs(400)
    truth = pb.Material(base_color=(0.6, 0.3, 0.2), roughness=0.4)
    measured = pb.reference.eval(truth, wi, wo)
    batch = np.stack([measured, np.full_like(measured, np.nan), measured])
    start = dict(roughness=0.7)
    result = pb.fit(wi, wo, batch, init=start, fit=["base_color", "roughness"])
    assert list(result.success) == [True, False, True]
    assert result.message[1].startswith("no data")
    assert result.cost[1] == 0.0 and result.iterations[1] == 0 and np.isnan(result.residuals[1]).all()
    np.testing.assert_array_equal(result.slots[1], np.asarray(pb.Material(**start).packed(()), float).reshape(-1)[:13])
    np.testing.assert_allclose(result.material.roughness[[0, 2]], 0.4, atol=1e-4)
    assert np.isfinite(result.slots).all() and np.isfinite(result.cost).all()
    single = pb.fit(wi, wo, np.full_like(measured, np.nan), fit=["roughness"])  # one problem, no data
    assert not single.success and single.message.startswith("no data") and single.cost == 0.0


@pytest.mark.parametrize("loss", ["relative", "log", "linear"])
def test_fit_a_black_texel_is_as_dark_as_the_model_allows(loss):
    wi, wo = pairs(400, "bad-entry-black")
    measured = pb.reference.eval(pb.Material(roughness=0.3), wi, wo)
    batch = np.stack([np.zeros_like(measured), measured])
    result = pb.fit(wi, wo, batch, loss=loss, fit=["base_color", "roughness", "specular", "metallic"])
    assert result.success.all() and np.isfinite(result.cost).all() and np.isfinite(result.residuals).all()
    black = pb.reference.eval(result.material[0], wi, wo)
    facing = (wi[:, 2] > 0.5) & (wo[:, 2] > 0.5)  # away from grazing, where Schlick's Fresnel keeps some specular
    assert black[facing].max() < 0.02 * measured[facing].mean()
    assert np.all(result.material.base_color[0] < 1e-3)
    np.testing.assert_allclose(result.material.roughness[1], 0.3, atol=1e-3)


@pytest.mark.parametrize("bounds, error, match", [
    ({"roughness": 0.3}, TypeError, r"bounds\['roughness'\]: expected a \(lower, upper\) pair"),
    ({"roughness": (0.1, 0.2, 0.3)}, ValueError, r"bounds\['roughness'\]: expected a \(lower, upper\) pair"),
    ({"roughness": ("a", "b")}, TypeError, r"bounds\['roughness'\]"),
    ({"roughness": (None, 1.0)}, TypeError, r"bounds\['roughness'\]"),
    ({"roughness": (float("nan"), 0.5)}, ValueError, r"bounds\['roughness'\].*NaN"),
    ({"roughness": (0.6, 0.5)}, ValueError, r"bounds\['roughness'\]"),
    ([("roughness", (0.0, 1.0))], TypeError, "bounds: expected a mapping"),
])
def test_fit_malformed_bounds_name_bounds(bounds, error, match):
    wi, wo = pairs(50)
    with pytest.raises(error, match=match):
        pb.fit(wi, wo, pb.reference.eval(pb.Material(), wi, wo), bounds=bounds)


def test_fit_equal_bounds_hold_the_parameter():
    wi, wo = pairs(400)
    truth = pb.Material(base_color=(0.6, 0.3, 0.2), roughness=0.4, metallic=0.3)
    measured = pb.reference.eval(truth, wi, wo)
    result = pb.fit(wi, wo, measured, init=dict(base_color=(0.6, 0.3, 0.2), metallic=0.6),
                    fit=["roughness", "metallic"], bounds={"roughness": (0.4, 0.4)})
    assert result.success and result.names == ("metallic",)
    assert result.material.roughness == 0.4 and result.material.metallic == pytest.approx(0.3, abs=1e-4)
    held = pb.fit(wi, wo, measured, fit=["roughness"], bounds={"roughness": (0.25, 0.25)})  # nothing left to fit
    assert held.success and held.names == () and held.material.roughness == 0.25 and held.iterations == 0
    assert held.message.startswith("nothing to fit") and np.isfinite(held.cost) and held.cost > 0


@pytest.mark.parametrize("value, error", [(0, ValueError), (-3, ValueError), (1.5, TypeError), (True, TypeError)])
def test_fit_max_iterations_is_a_positive_integer(value, error):
    wi, wo = pairs(50)
    with pytest.raises(error, match="max_iterations"):
        pb.fit(wi, wo, pb.reference.eval(pb.Material(), wi, wo), max_iterations=value)


@pytest.mark.parametrize("shape", [(7,), (50, 3), (2, 50), (1, 50, 1)])
def test_fit_wrongly_shaped_weights_name_weights(shape):
    wi, wo = pairs(50)
    with pytest.raises(ValueError, match=r"weights: expected shape \(50,\)"):
        pb.fit(wi, wo, pb.reference.eval(pb.Material(), wi, wo), weights=np.ones(shape))


def test_concurrent_fits_restore_the_blas_threads(monkeypatch):
    """Two fits by scipy (the method that limits BLAS to one thread) that overlap, the first one
    in leaving first: the BLAS limit afterwards is the one before."""
    threadpoolctl = pytest.importorskip("threadpoolctl")
    import scipy.optimize

    def blas_threads():
        return [info["num_threads"] for info in threadpoolctl.threadpool_info() if info["user_api"] == "blas"]

    if not blas_threads():
        pytest.skip("no BLAS that threadpoolctl controls")
    wi, wo = pairs(200)
    measured = pb.reference.eval(pb.Material(roughness=0.3), wi, wo)
    original = scipy.optimize.least_squares
    first_inside, second_inside, first_done = threading.Event(), threading.Event(), threading.Event()
    errors = []

    def least_squares(*args, **kwargs):  # runs inside the fit's BLAS limit
        if threading.current_thread().name == "first":
            first_inside.set()
            assert second_inside.wait(60)
        else:
            second_inside.set()
            assert first_done.wait(60)
        return original(*args, **kwargs)

    def run(name):
        try:
            pb.fit(wi, wo, measured, fit=["roughness"], max_iterations=5, method="scipy")
        except BaseException as error:  # reported below
            errors.append(error)
        finally:
            if name == "first":
                first_done.set()

    monkeypatch.setattr(scipy.optimize, "least_squares", least_squares)
    before = blas_threads()
    if max(before) < 2:
        pytest.skip("BLAS runs on one thread already")
    first = threading.Thread(target=run, args=("first",), name="first")
    first.start()
    assert first_inside.wait(60)
    second = threading.Thread(target=run, args=("second",), name="second")
    second.start()
    first.join(60)
    second.join(60)
    assert not errors, errors
    assert blas_threads() == before


# ---------------------------------------------------------------------------------------------
# MERL files

MERL_CELLS = 90 * 90 * 180


def write_merl(path, stored):
    with open(path, "wb") as f:
        np.asarray((90, 90, 180), dtype="<i4").tofile(f)
        np.asarray(stored, dtype="<f8").tofile(f)


def test_load_merl_from_a_file_descriptor_leaves_it_open(tmp_path):
    stored = np.full((3, 90, 90, 180), 1500.0)
    stored[1, 2, 3, 4] = -1.0  # no data
    path = tmp_path / "grey.binary"
    write_merl(path, stored)
    descriptor = os.open(path, os.O_RDONLY)
    try:
        table = pb.measured.load_merl(descriptor)
        os.fstat(descriptor)  # still open: an OSError (EBADF) otherwise
        assert os.lseek(descriptor, 0, os.SEEK_CUR) == path.stat().st_size
    finally:
        os.close(descriptor)
    assert np.isnan(table.table[1, 2, 3, 4]) and table.table[0, 0, 0, 0] == 1.0
    np.testing.assert_array_equal(pb.measured.load_merl(str(path)).table, table.table, strict=True)


@pytest.mark.parametrize("value", [np.inf, -np.inf, np.nan])
def test_load_merl_refuses_stored_values_that_are_not_finite(tmp_path, value):
    stored = np.full((3, 90, 90, 180), 1500.0)
    stored[2, 10, 20, 30] = value
    stored[0, 0, 0, 0] = -1.0  # no data, which is fine
    path = tmp_path / "bad.binary"
    write_merl(path, stored)
    cell = r"bad\.binary: channel 2 \(blue\), cell \(θh 10, θd 20, φd 30\)"
    with pytest.raises(ValueError, match=cell + ".*not finite"):
        pb.measured.load_merl(path)


@pytest.mark.parametrize("path", [1.5, True, None, ["x.binary"]])
def test_load_merl_path_of_the_wrong_type(path):
    with pytest.raises(TypeError, match="path: expected a path or an open file descriptor"):
        pb.measured.load_merl(path)


# ---------------------------------------------------------------------------------------------
# The explorer


@pytest.fixture(scope="module")
def explorer():
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    pytest.importorskip("ipywidgets")
    ex = pb.explorer(resolution=32)
    yield ex
    ex.close()


@pytest.mark.parametrize("control", ["roughness", "light_theta", "view_phi", "exposure"])
@pytest.mark.parametrize("value", [float("nan"), float("inf"), -float("inf")])
def test_explorer_refuses_values_that_are_not_finite_and_keeps_working(explorer, control, value):
    import traitlets

    explorer.reset()
    slider = explorer.sliders[control] if control in explorer.sliders else getattr(explorer, control)
    kept = slider.value
    with pytest.raises(ValueError, match=f"{control}: {value!r} is not a finite number") as error:
        slider.value = value
    assert isinstance(error.value, traitlets.TraitError)  # as the widgets' own refusals
    assert slider.value == kept
    before = explorer.images["sphere"].value
    explorer.sliders["metallic"].value = 0.9  # later changes draw as before
    assert explorer.images["sphere"].value != before
    assert explorer.material.metallic == 0.9


def test_explorer_refuses_values_beyond_what_the_pictures_take(explorer):
    explorer.reset()
    explorer.exposure.max = 1e6  # a wider range than the explorer's
    with pytest.raises(ValueError, match="exposure: 1000.0 is beyond 64"):
        explorer.exposure.value = 1e3
    explorer.sliders["specular"].max = 1e30
    with pytest.raises(ValueError, match="specular: 1e\\+30 is beyond 1e\\+20"):
        explorer.sliders["specular"].value = 1e30
    with pytest.raises(ValueError, match="material: specular"):
        explorer.set_material(pb.Material(specular=1e21))
    explorer.reset()
    assert explorer.refresh() == {} and explorer.material == pb.Material()


def test_explorer_after_close_ignores_changes():
    pytest.importorskip("matplotlib").use("Agg")
    pytest.importorskip("ipywidgets")
    ex = pb.explorer(resolution=16)
    ex.close()
    ex.sliders["roughness"].value = 0.9  # was a KeyError from the dropped figures
    ex.base_color.value = "#ff0000"
    ex.preset.value = "gold"
    ex.light_theta.value = 10.0
    assert ex.refresh() == {}
    ex.set_material("chrome")
    ex.reset()
    ex.close()  # twice: nothing more


# ---------------------------------------------------------------------------------------------
# The command line and pb.render



def exit_status(capsys, args):
    from principled_brdf.cli import main

    try:
        status = main(args)
    except SystemExit as stop:  # argparse's errors
        status = stop.code
    return status, capsys.readouterr().err


@pytest.mark.parametrize("args, option, message", [
    (["render", "--samples", "65536", "--resolution", "1024"], "--samples", "at most 16384 per pixel"),
    (["render", "--samples", "65537"], "--samples", "at most 65536 samples per pixel"),
    (["render", "--samples", "0"], "--samples", "positive integer"),
    (["render", "--resolution", "1"], "--resolution", "at least 2 pixels"),
    (["render", "--exposure", "1e300"], "--exposure", "at most 1e+20"),
    (["render", "--param", "roughness=1e5"], "--param", "roughness: 100000.0 is beyond 10000"),
    (["render", "--param", "specular=1e30"], "--param", "specular: 1e+30 is beyond 1e+20"),
    (["demo", "--repeats", "100000000"], "--repeats", "at most 100 repeats"),
    (["bench", "--repeats", "101"], "--repeats", "at most 100 repeats"),
    (["bench", "--repeats", "1e8"], "--repeats", "positive integer"),
    (["demo", "--pairs", str(1 << 27), "--repeats", "17"], "--repeats", "at most 16 repeats"),
    (["demo", "--resolution", "4"], "--resolution", "at least 8 pixels"),
    (["demo", "--resolution", "4096"], "--resolution", "at most 682 pixels per sphere"),
])
def test_cli_numeric_options_are_bounded(capsys, tmp_path, no_work, args, option, message):
    output = tmp_path / "x.png"
    status, err = exit_status(capsys, args + (["--output", str(output)] if args[0] == "render" else []))
    assert status == 2
    lines = [line for line in err.splitlines() if line.strip() and not line.startswith(("usage:", " "))]
    assert len(lines) == 1 and "error" in lines[0] and option in lines[0] and message in lines[0], err
    assert not output.exists()


def test_cli_light_of_extreme_magnitude_is_a_direction(capsys, tmp_path):
    for light in ("1e308,1e308,1e308", "5e-324,5e-324,5e-324"):
        output = tmp_path / "x.npy"
        status, err = exit_status(capsys, ["render", "--light", light, "--resolution", "8", "--samples", "2",
                                           "--environment", "sky", "--output", str(output)])
        assert status == 0, err
        expected = pb.render.render_sphere(pb.Material(), 8, light=(1.0, 1.0, 1.0), samples=2)
        np.testing.assert_array_equal(np.load(output), expected)


@pytest.mark.parametrize("kwargs, error, match", [
    (dict(resolution=1024, samples=65536), ValueError, "samples: 65536 per pixel over 1048576 pixels"),
    (dict(resolution=64, samples=1 << 17), ValueError, "samples: expected 1 to 65536"),
    (dict(resolution=64, samples=0), ValueError, "samples: expected 1 to 65536"),
    (dict(resolution=64, samples=-5, environment=None), ValueError, "samples: expected 1 to 65536"),
    (dict(resolution=64, samples=8.0), TypeError, "samples: expected an integer"),
])
def test_render_refuses_unbounded_samples(monkeypatch, kwargs, error, match):
    def sample(*args, **kwargs):  # the refused job would start here: fail now rather than run for hours
        raise AssertionError("the job started")

    monkeypatch.setattr(pb.render, "_sample", sample)
    with pytest.raises(error, match=match):
        pb.render.render_sphere(pb.Material(), **kwargs)
    if "environment" not in kwargs:
        with pytest.raises(error, match=match):
            pb.render.render_environment(pb.Material(), kwargs["resolution"], samples=kwargs["samples"])


def test_render_counts_every_sphere_of_a_batch(monkeypatch):
    def job(*args, **kwargs):
        raise AssertionError("the job started")

    monkeypatch.setattr(pb.render, "sphere_frames", job)
    batch = pb.Material(roughness=np.full((1 << 12, 1, 1), 0.5))  # 4096 spheres of 2048² pixels: 2^34 pixels
    with pytest.raises(ValueError, match="samples: 2 per pixel over 17179869184 pixels"):
        pb.render.render_sphere(batch, 2048, samples=2)


def test_render_light_of_extreme_magnitude():
    expected = pb.render.render_sphere(pb.Material(), 8, light=(1.0, 1.0, 1.0), samples=2)
    for light in ((1e308, 1e308, 1e308), (5e-324, 5e-324, 5e-324)):
        np.testing.assert_array_equal(pb.render.render_sphere(pb.Material(), 8, light=light, samples=2), expected)


@pytest.mark.parametrize("change, match", [
    (dict(weights=np.r_[np.ones(10), 1e300, np.ones(39)]), r"weights\[10\]: 1e\+300 is not a weight"),
    (dict(weights=np.r_[np.ones(3), np.nan, np.ones(46)]), r"weights\[3\]: nan is not a weight"),
    (dict(weights=np.r_[np.ones(3), -1.0, np.ones(46)]), r"weights\[3\]: -1.0 is not a weight"),
    (dict(scale=1e300), r"measured\[0, 0\]: .* is beyond 3.402823e\+38"),
])
def test_fit_values_whose_squares_overflow_are_refused(change, match):
    """The cost (half the sum of weighted squared residuals) of these was inf."""
    wi, wo = pairs(50)
    measured = pb.reference.eval(pb.Material(), wi, wo) * change.pop("scale", 1.0)
    with pytest.raises(ValueError, match=match):
        pb.fit(wi, wo, measured, loss="linear", **change)
