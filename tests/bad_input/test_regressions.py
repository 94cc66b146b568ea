"""Hostile input (docs/bad-input.md): every element or an
error, the direction check decided once, aliasing, alignment, the edges of the
integer options, and finite float32 results over the whole parameter range.

Each test holds one behavior at the edge of what a caller can pass.
"""

from __future__ import annotations

import numpy as np
import pytest

import principled_brdf as pb
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
    params = pb._batch._params(pb.Material(), (n,))
    options = pb._core.EvalOptions(threads=1)
    wo = np.float32([0, 0, 1])
    with pytest.raises(ValueError, match="wi: array data is not aligned"):
        pb._core.batch_eval(wi=wi, wi_layout=0, wo=wo, wo_layout=2, params=params,
                            outputs=[np.empty((n, 3), np.float32)], out_layout=0, n=n, lobes=False, options=options)
    with pytest.raises(ValueError, match="out: array data is not aligned"):
        pb._core.batch_eval(wi=wi.copy(), wi_layout=0, wo=wo, wo_layout=2, params=params,
                            outputs=[misaligned(np.empty((n, 3), np.float32))], out_layout=0, n=n, lobes=False,
                            options=options)


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
