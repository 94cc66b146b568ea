"""docs/bad-input.md at the Python boundary: every bad input raises ValueError (TypeError for
types) naming the argument and, where there is one, the first offending element."""

from __future__ import annotations

import re

import numpy as np
import pytest

import principled_brdf as pb
from principled_brdf._validate import all_within
from conftest import TABLE_DOMAINS, random_directions, seeded_rng

EVALUATORS = {"eval": pb.reference.eval, "eval_lobes": pb.reference.eval_lobes}
DIRECTIONS = ("wi", "wo")

SCALAR_DOMAINS = {name: domain for name, domain in TABLE_DOMAINS.items() if name != "base_color"}
# (parameter, side) for every finite bound of docs/model.md, "The model"
DOMAIN_CASES = [(name, "below") for name in SCALAR_DOMAINS] + [
    (name, "above") for name, (_, hi) in SCALAR_DOMAINS.items() if np.isfinite(hi)
]


def good_directions(n=6):
    rng = seeded_rng("bad_input", n)
    return random_directions(rng, n), random_directions(rng, n)


_GOOD = object()


def call(evaluator, material=_GOOD, wi=_GOOD, wo=_GOOD, **kwargs):
    """Call ``evaluator`` with good defaults for whatever is not given."""
    good_wi, good_wo = good_directions()
    return EVALUATORS[evaluator](
        pb.Material() if material is _GOOD else material,
        good_wi if wi is _GOOD else wi,
        good_wo if wo is _GOOD else wo,
        **kwargs,
    )


def raises(exception, *fragments):
    """pytest.raises whose message must contain every fragment (literally)."""
    return pytest.raises(exception, match="(?s)" + "".join(f"(?=.*{re.escape(f)})" for f in fragments))


# --------------------------------------------------------------------------
# directions: shapes


@pytest.mark.parametrize("evaluator", EVALUATORS)
@pytest.mark.parametrize("argument", DIRECTIONS)
@pytest.mark.parametrize("shape", [(6, 2), (6, 4), (3, 6), (3, 1), (0,), (6, 3, 2)])
def test_direction_last_axis_not_3(evaluator, argument, shape):
    bad = np.ones(shape) / np.sqrt(shape[-1]) if shape[-1] else np.ones(shape)
    with raises(ValueError, argument, str(shape)):
        call(evaluator, **{argument: bad})


@pytest.mark.parametrize("argument", DIRECTIONS)
def test_direction_scalar(argument):
    with raises(ValueError, argument):
        call("eval", **{argument: 1.0})


@pytest.mark.parametrize("evaluator", EVALUATORS)
def test_direction_leading_shapes_do_not_broadcast(evaluator):
    wi, wo = good_directions(6)
    with raises(ValueError, "wi (6,)", "wo (5,)"):
        call(evaluator, wi=wi, wo=wo[:5])
    with raises(ValueError, "wi (2, 3)", "wo (3, 2)"):
        call(evaluator, wi=wi.reshape(2, 3, 3), wo=wo.reshape(3, 2, 3))


@pytest.mark.parametrize("evaluator", EVALUATORS)
def test_material_shape_does_not_broadcast_with_directions(evaluator):
    material = pb.Material(roughness=np.linspace(0.0, 1.0, 4))
    with raises(ValueError, "material (4,)", "wi (6,)"):
        call(evaluator, material=material)


# --------------------------------------------------------------------------
# directions: dtypes


@pytest.mark.parametrize("argument", DIRECTIONS)
@pytest.mark.parametrize(
    "value",
    [
        "0 0 1",
        b"\x00\x00\x01",
        None,
        np.array([["0", "0", "1"]]),
        np.array([[0, 0, 1]], dtype=object),
        np.array([[0, 0, 1 + 0j]]),
        [[0.0, 0.0, 1.0], [0.0, 1.0]],  # ragged
        [[0.0, 0.0, "1"]],
        {"x": 0, "y": 0, "z": 1},
    ],
    ids=["str", "bytes", "none", "str-array", "object-array", "complex", "ragged", "mixed-list", "dict"],
)
def test_direction_non_convertible_dtype(argument, value):
    with raises(TypeError, argument):
        call("eval", **{argument: value})


@pytest.mark.parametrize("dtype", [np.float32, np.float16, np.int32, np.int64])
def test_direction_convertible_dtypes_are_accepted(dtype):
    axis = np.array([[0, 0, 1]], dtype=dtype)
    assert np.all(np.isfinite(pb.reference.eval(pb.Material(), axis, axis)))


# --------------------------------------------------------------------------
# directions: NaN, inf, length


@pytest.mark.parametrize("evaluator", EVALUATORS)
@pytest.mark.parametrize("argument", DIRECTIONS)
@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_direction_not_finite(evaluator, argument, value):
    w = good_directions()[0]
    w[3, 1] = value
    with raises(ValueError, f"{argument}[3, 1]", "finite"):
        call(evaluator, **{argument: w})


@pytest.mark.parametrize("argument", DIRECTIONS)
def test_direction_not_finite_in_a_multidimensional_batch(argument):
    w = good_directions(24)[0].reshape(2, 4, 3, 3)
    w[1, 2, 0, 2] = np.nan
    with raises(ValueError, f"{argument}[1, 2, 0, 2]"):
        call("eval", **{argument: w})


@pytest.mark.parametrize("argument", DIRECTIONS)
@pytest.mark.parametrize("scale", [1.0011, 0.9989, 2.0, 0.5, 0.0, 1e200])
def test_direction_length_off_by_more_than_1e3(argument, scale):
    w = good_directions()[0]
    w[4] *= scale
    with raises(ValueError, f"{argument}[4]", "length"):
        call("eval", **{argument: w})


@pytest.mark.parametrize("argument", DIRECTIONS)
@pytest.mark.parametrize("scale", [1.0009, 0.9991, 1.0 + 1e-12])
def test_direction_length_within_1e3_is_accepted(argument, scale):
    w = good_directions()[0]
    w[4] *= scale
    f = call("eval", **{argument: w})
    assert f.shape == (6, 3) and np.all(np.isfinite(f)) and np.all(f >= 0.0)


def test_first_offending_direction_is_named_whatever_the_fault():
    w = good_directions()[0]
    w[2] *= 1.5  # length fault first
    w[4, 0] = np.nan  # NaN later
    with raises(ValueError, "wi[2]", "length"):
        call("eval", wi=w)
    w = good_directions()[0]
    w[2, 1] = np.inf  # NaN/inf fault first
    w[4] *= 1.5
    with raises(ValueError, "wi[2, 1]", "finite"):
        call("eval", wi=w)


def test_wi_is_checked_before_wo():
    wi, wo = good_directions()
    wi[5] *= 2.0
    wo[0] *= 2.0
    with raises(ValueError, "wi[5]"):
        call("eval", wi=wi, wo=wo)


# --------------------------------------------------------------------------
# parameters: NaN / inf, domains, dtypes, shapes


@pytest.mark.parametrize("name", list(SCALAR_DOMAINS))
@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_parameter_not_finite(name, value):
    with raises(ValueError, f"{name}[2]", "finite"):
        pb.Material(**{name: [0.5, 0.5, value, 0.5]})
    with raises(ValueError, name, "finite"):
        pb.Material(**{name: value})


@pytest.mark.parametrize("value", [np.nan, np.inf])
def test_base_color_not_finite(value):
    color = np.full((2, 3, 3), 0.5)
    color[1, 0, 2] = value
    with raises(ValueError, "base_color[1, 0, 2]", "finite"):
        pb.Material(base_color=color)


@pytest.mark.parametrize("name, side", DOMAIN_CASES)
def test_parameter_out_of_domain(name, side):
    lo, hi = SCALAR_DOMAINS[name]
    bad = lo - 1e-9 if side == "below" else hi + 1e-9
    values = np.array([lo, 0.5 * (lo + min(hi, 1.0)), bad, bad])
    with raises(ValueError, f"{name}[2]", repr(float(bad)), "domain"):
        pb.Material(**{name: values})
    # a uniform value is named without an index
    with raises(ValueError, f"{name}: ", "domain"):
        pb.Material(**{name: bad})
    # and replace() checks like the constructor
    with raises(ValueError, f"{name}[2]"):
        pb.Material().replace(**{name: values})


def test_base_color_out_of_domain():
    with raises(ValueError, "base_color[1]", "-0.25", "domain"):
        pb.Material(base_color=(0.5, -0.25, 0.1))
    color = np.full((4, 3), 0.5)
    color[3, 0] = -1e-12
    with raises(ValueError, "base_color[3, 0]"):
        pb.Material(base_color=color)


def test_first_offending_parameter_element_is_named_whatever_the_fault():
    with raises(ValueError, "roughness[1]", "domain"):
        pb.Material(roughness=[0.1, -1.0, np.nan])
    with raises(ValueError, "roughness[1]", "finite"):
        pb.Material(roughness=[0.1, np.nan, -1.0])


@pytest.mark.parametrize("name", list(SCALAR_DOMAINS) + ["base_color"])
@pytest.mark.parametrize(
    "value",
    ["0.5", None, np.array(["0.5"]), np.array([0.5], dtype=object), 0.5 + 0.5j, np.array([0.5 + 0j]), [[0.5], [0.5, 0.5]]],
    ids=["str", "none", "str-array", "object-array", "complex", "complex-array", "ragged"],
)
def test_parameter_non_convertible_dtype(name, value):
    with raises(TypeError, name):
        pb.Material(**{name: value})


@pytest.mark.parametrize("shape", [(), (2,), (4,), (5, 2), (3, 1)])
def test_base_color_wrong_shape(shape):
    with raises(ValueError, "base_color", str(shape)):
        pb.Material(base_color=np.full(shape, 0.5))


def test_parameter_leading_shapes_do_not_broadcast():
    with raises(ValueError, "roughness (3,)", "metallic (4,)"):
        pb.Material(roughness=np.zeros(3), metallic=np.zeros(4))
    with raises(ValueError, "base_color (5,)", "sheen (4,)"):
        pb.Material(base_color=np.ones((5, 3)), sheen=np.zeros(4))


def test_unknown_parameter_name():
    with pytest.raises(TypeError, match="rougness"):
        pb.Material(rougness=0.5)
    with pytest.raises(TypeError, match="rougness"):
        pb.Material().replace(rougness=0.5)


# --------------------------------------------------------------------------
# model, material, mix


@pytest.mark.parametrize("evaluator", EVALUATORS)
@pytest.mark.parametrize("model", ["disney2016", "Disney2014", "disney", "", "disney2014 "])
def test_unknown_model(evaluator, model):
    with raises(ValueError, "model", repr(model), "disney2014", "disney2012"):
        call(evaluator, model=model)


@pytest.mark.parametrize("model", [None, 2014, b"disney2014"])
def test_model_of_the_wrong_type(model):
    with pytest.raises((ValueError, TypeError), match="model"):
        call("eval", model=model)


@pytest.mark.parametrize("evaluator", EVALUATORS)
@pytest.mark.parametrize(
    "material", [None, {"roughness": 0.5}, "Material()", 0.5, pb.Material], ids=["none", "dict", "str", "float", "class"]
)
def test_material_not_a_material(evaluator, material):
    wi, wo = good_directions()
    with raises(TypeError, "material"):
        EVALUATORS[evaluator](material, wi, wo)


@pytest.mark.parametrize("t", [1.5, -0.1, 1.0 + 1e-12, np.nan, np.inf])
def test_mix_t_outside_0_1(t):
    a, b = pb.Material(), pb.Material(roughness=1.0)
    with raises(ValueError, "t"):
        pb.Material.mix(a, b, t)


def test_mix_mask_outside_0_1_names_the_element():
    a, b = pb.Material(), pb.Material(roughness=1.0)
    mask = np.full((3, 4), 0.5)
    mask[2, 1] = 1.25
    with raises(ValueError, "t[2, 1]", "1.25", "domain"):
        pb.Material.mix(a, b, mask)
    mask[1, 3] = np.nan
    with raises(ValueError, "t[1, 3]", "finite"):
        pb.Material.mix(a, b, mask)


@pytest.mark.parametrize("t", ["0.5", None, 0.5j])
def test_mix_t_of_the_wrong_type(t):
    with raises(TypeError, "t"):
        pb.Material.mix(pb.Material(), pb.Material(), t)


def test_mix_arguments_not_materials():
    with raises(TypeError, "a:"):
        pb.Material.mix({"roughness": 0.1}, pb.Material(), 0.5)
    with raises(TypeError, "b:"):
        pb.Material.mix(pb.Material(), None, 0.5)


def test_mix_shapes_that_do_not_broadcast():
    a = pb.Material(roughness=np.zeros(3))
    b = pb.Material(roughness=np.zeros(4))
    with raises(ValueError, "a (3,)", "b (4,)"):
        pb.Material.mix(a, b, 0.5)
    with raises(ValueError, "a (3,)", "t (2,)"):
        pb.Material.mix(a, pb.Material(), np.array([0.0, 1.0]))


# --------------------------------------------------------------------------
# nothing is half-done


def test_failed_calls_leave_inputs_untouched():
    wi, wo = good_directions()
    wi_copy, wo_copy = wi.copy(), wo.copy()
    wo[5] *= 3.0
    wo_copy[5] *= 3.0
    with pytest.raises(ValueError):
        pb.reference.eval(pb.Material(), wi, wo)
    np.testing.assert_array_equal(wi, wi_copy)
    np.testing.assert_array_equal(wo, wo_copy)


EDGE_VALUES = (0.0, -0.0, 0.5, 1.0, -1.0, 2.0, 1e300, -1e300, np.inf, -np.inf, np.nan, 3.4028234663852886e38, 3.5e38)
BOUNDS = ((0.0, 1.0), (0.0, np.inf), (-np.inf, np.inf), (1.5, 100.0), (-3.4028234663852886e38, 3.4028234663852886e38))


@pytest.mark.parametrize("lower, upper", BOUNDS)
def test_the_checks_fast_path_accepts_exactly_what_the_elementwise_rule_accepts(lower, upper):
    # all_within (two reductions) decides every call that passes; it must agree with
    # "finite and lower <= x <= upper" element by element, infinite bounds included
    rng = np.random.default_rng(17)
    arrays = [np.array(EDGE_VALUES), np.empty(0), np.array([True, False]), np.arange(5, dtype=np.uint8)]
    arrays += [rng.choice(EDGE_VALUES, size=(4, 3)) for _ in range(200)]
    arrays += [np.full((2, 2), v) for v in EDGE_VALUES]
    for array in arrays:
        with np.errstate(over="ignore", invalid="ignore"):
            both = (array, array.astype(np.float32))  # in float32, 1e300 is infinite
        for values in both:
            with np.errstate(invalid="ignore"):
                expected = bool(np.all(np.isfinite(values) & (values >= lower) & (values <= upper)))
            assert all_within(values, lower, upper) == expected, (values, lower, upper)


# --------------------------------------------------------------------------
# environments (docs/rendering-and-plots.md, "Environments")


@pytest.mark.parametrize("environment, error, match", [
    ("garden", ValueError, r"environment: expected 'sky', 'studio', 'outdoor', a .exr or .hdr file.*got 'garden'"),
    ("map.png", ValueError, r"environment: expected 'sky'.*got 'map.png'"),
    ("missing.exr", FileNotFoundError, r"environment: no such file: 'missing.exr'"),
    (3.5, TypeError, r"environment: expected 'sky'.*got float"),
    (np.zeros((4, 8)), ValueError, r"environment: expected a latitude-longitude map of shape \(H, W, 3\)"),
    (np.zeros((1, 8, 3)), ValueError, r"H and W at least 2, got \(1, 8, 3\)"),
    (np.full((4, 8, 3), -1.0), ValueError, r"environment\[0, 0, 0\]: -1.0 is outside its domain"),
    (np.where(np.arange(96).reshape(4, 8, 3) == 50, np.nan, 1.0), ValueError,
     r"environment\[2, 0, 2\]: nan is not a finite number"),
    (np.full((4, 8, 3), 1e39), ValueError, r"environment\[0, 0, 0\]: 1e\+39 is outside its domain"),
    (np.array([[["a"] * 3] * 4] * 2), TypeError, r"environment: expected real numbers"),
])
def test_bad_environments_are_refused_naming_the_argument(environment, error, match, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(error, match=match):
        pb.render.render_sphere(pb.Material(), 8, environment=environment, samples=2)


def test_unreadable_map_files_name_the_argument(tmp_path):
    broken = tmp_path / "broken.hdr"
    broken.write_bytes(b"not an image")
    pytest.importorskip("cv2")
    with pytest.raises(ValueError, match=r"environment: .*broken.hdr.* is not a readable Radiance RGBE"):
        pb.render.render_sphere(pb.Material(), 8, environment=broken, samples=2)
    corrupt = tmp_path / "corrupt.exr"
    corrupt.write_bytes(b"not an exr")
    with pytest.raises(ValueError, match=r"environment: .*corrupt.exr.* is not a readable OpenEXR file"):
        pb.render.render_sphere(pb.Material(), 8, environment=corrupt, samples=2)
    with pytest.raises(ValueError, match=r"environment: .*gray.exr.* has no R, G, B channels \(it has Y\)"):
        import OpenEXR

        with OpenEXR.File({"type": OpenEXR.scanlineimage}, {"Y": np.ones((4, 8), np.float32)}) as exr:
            exr.write(str(tmp_path / "gray.exr"))
        pb.render.render_sphere(pb.Material(), 8, environment=tmp_path / "gray.exr", samples=2)
