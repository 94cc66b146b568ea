"""A fuzz of every public entry point with hostile arguments (docs/bad-input.md).

Hypothesis draws shapes, dtypes, layouts, strides, misalignment, aliasing,
NaN/inf, values at and beyond the domains' edges and option values. Every call
must either

* return finite results, every element written (``out=`` buffers start as
  NaN), that agree with the float64 reference where one exists, or
* raise ``ValueError`` or ``TypeError`` whose message names an argument,

and nothing else: no other exception, no NaN for in-domain input, no crash.
Derandomised (the same examples every run) and bounded, so it stays fast.
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import principled_brdf as pb
from principled_brdf._validate import unit_length

FUZZ = settings(derandomize=True, max_examples=150, deadline=None, database=None,
                suppress_health_check=list(HealthCheck))
ISAS = pb.cpu_info()["available"]

# Names an error message may start with or mention.
ARGUMENT_NAMES = ("wi", "wo", "u", "out", "material", "model", "mode", "layout", "threads", "check", "cosine", "isa",
                  "seed", "specular_sampler", "n", "first", "samples", "cos_theta_o", "resolution", "light",
                  "light_intensity", "ambient", "leading shapes", "h", "w", "u1", "u2", "alpha", "alpha_x",
                  "alpha_y", "gamma", "p", "approximation", "correlated", "closed_forms", "params",
                  "energy_compensation", "wrt", "cotangent", "method",
                  "out[0]", "out[1]", "measured", "weights", "bounds", "fit", "init", "loss", "max_iterations",
                  "precision", "normal", "tangent", "frame", "theta", "phi", "theta_h", "phi_h", "theta_d", "phi_d",
                  "color", "linear", "exposure", "curve", "table", "brdf", "interpolation", "theta_o", "phi_d",
                  "angles", "channel", "lobes", "environment", "directions", "d", "path", "height",
                  *pb.PARAMETERS)


def assert_names_an_argument(error: Exception) -> None:
    message = str(error)
    assert any(re.search(rf"(^|[\s,(]){re.escape(name)}(\[|:|\s|,|$)", message) for name in ARGUMENT_NAMES), message


def outcome(call):
    """The call's result, or None after a ValueError/TypeError that names an argument."""
    try:
        return call()
    except (ValueError, TypeError) as error:
        assert_names_an_argument(error)
        return None


# ------------------------------------------------------------------ hostile arrays

def unit_vectors(rng, leading) -> np.ndarray:
    v = rng.normal(size=tuple(leading) + (3,))
    v[..., 2] = np.abs(v[..., 2]) + 0.05 * rng.random()
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def misaligned(array: np.ndarray) -> np.ndarray:
    raw = np.empty(array.nbytes + 1, np.uint8)
    view = raw[1:].view(array.dtype).reshape(array.shape)
    view[...] = array
    return view


def strided(array: np.ndarray) -> np.ndarray:
    bigger = np.repeat(array[None], 2, axis=0)
    return bigger[0] if array.ndim == 0 else np.stack([array, array], axis=-1)[..., 0]


def fortran(array: np.ndarray) -> np.ndarray:
    return np.asfortranarray(array)


FAULTS = ("none", "nan", "inf", "huge", "long", "short", "edge", "zero", "below")


def inject(array: np.ndarray, fault: str, rng) -> np.ndarray:
    """One element of a float (..., 3) array made hostile."""
    if fault == "none" or array.size == 0 or array.shape[-1] != 3:
        return array
    flat = array.reshape(-1, 3).copy()
    i = int(rng.integers(len(flat)))
    if fault == "nan":
        flat[i, int(rng.integers(3))] = np.nan
    elif fault == "inf":
        flat[i, int(rng.integers(3))] = -np.inf
    elif fault == "huge":
        flat[i] = (1e300, 0, 1e300)
    elif fault == "long":
        flat[i] *= 1.0 + 1e-3 * (1 + rng.random())
    elif fault == "short":
        flat[i] *= 1.0 - 1e-3 * (1 + rng.random())
    elif fault == "edge":  # at the tolerance, on either side once rounded to float32
        flat[i] *= 1.001 if rng.random() < 0.5 else 0.999
    elif fault == "zero":
        flat[i] = 0
    elif fault == "below":
        flat[i, 2] = -abs(flat[i, 2])
    return flat.reshape(array.shape)


DTYPES = ("float32", "float64", "float16", "int64", "bool", "object", "str", "complex", "timedelta", "list")
LAYOUT_FAULTS = ("contiguous", "contiguous", "misaligned", "strided", "fortran")


def convert(array: np.ndarray, dtype: str, layout: str):
    if dtype == "list":
        return array.tolist()
    if dtype == "str":
        return array.astype(str)
    if dtype == "timedelta":
        return array.astype(np.int64).astype("timedelta64[s]")
    if dtype == "object":
        return array.astype(object)
    converted = array.astype({"complex": np.complex64}.get(dtype, dtype))
    if layout == "misaligned" and converted.dtype.itemsize > 1:
        return misaligned(converted)
    if layout == "strided":
        return strided(converted)
    if layout == "fortran":
        return fortran(converted)
    return converted


@st.composite
def direction_argument(draw, leading, rng):
    """A direction argument of (about) ``leading`` shape, possibly hostile."""
    shape_kind = draw(st.sampled_from(("same", "same", "same", "single", "broadcast", "wrong")))
    if shape_kind == "single":
        shape = ()
    elif shape_kind == "broadcast" and leading:
        shape = (1,) + tuple(leading[1:])
    else:
        shape = tuple(leading)
    array = unit_vectors(rng, shape)
    if shape_kind == "wrong":
        array = array[..., : draw(st.sampled_from((0, 2)))]
    array = inject(array, draw(st.sampled_from(FAULTS)), rng)
    dtype = draw(st.sampled_from(DTYPES[:2] * 4 + DTYPES))
    return convert(array, dtype, draw(st.sampled_from(LAYOUT_FAULTS)))


PARAMETER_VALUES = {
    "good": lambda rng, info, n: rng.random(3) if info.slots == 3 else float(rng.random()),
    "per_element": lambda rng, info, n: rng.random((n, 3) if info.slots == 3 else (n,)),
    "edge": lambda rng, info, n: np.full(3, info.lower) if info.slots == 3 else info.upper if np.isfinite(info.upper) else 1e4,
    "nan": lambda rng, info, n: np.nan,
    "negative": lambda rng, info, n: -1e-9,
    "above": lambda rng, info, n: 1.0 + 1e-9 if np.isfinite(info.upper) else 1e30,
    "string": lambda rng, info, n: "0.5",
    "wrong_shape": lambda rng, info, n: rng.random((n + 1,)),
    "float32_array": lambda rng, info, n: misaligned(rng.random((n, 3) if info.slots == 3 else (n,)).astype(np.float32)),
}


@st.composite
def material_argument(draw, n, rng):
    kwargs = {}
    for name in draw(st.lists(st.sampled_from(list(pb.PARAMETERS)), max_size=4, unique=True)):
        kind = draw(st.sampled_from(("good", "good", "per_element", "edge") + tuple(PARAMETER_VALUES)))
        kwargs[name] = PARAMETER_VALUES[kind](rng, pb.PARAMETERS[name], n)
    return kwargs


OPTION_VALUES = {
    "model": ("disney2014", "disney2012", "disney2015", "disney2015", None, 2014),
    "mode": ("radiance", "importance", "light", None),
    "threads": (None, 1, 2, 3, 0, -1, 2**31, 1.5, "2", True),
    "check": (True, True, True, False, np.True_, None, "no", np.array([True, False])),
    "cosine": (False, True, np.bool_(True), 1, np.array([True])),
    "isa": (None, *ISAS, "avx1024", 3),
    "layout": ("aos", "aos", "aos", "soa", "AOS", None),
    "specular_sampler": ("visible", "distribution", "best"),
    "seed": (0, 7, 2**64 - 1, 2**64, -1, 1.0, None),
    "wrt": (None, "roughness", ["base_color", "sheen"], ("clearcoat_gloss", "metallic"), [], "gloss", ["roughness"] * 2, 3),
}


@st.composite
def options(draw, names):
    chosen = {}
    for name in names:
        if draw(st.booleans()):
            chosen[name] = draw(st.sampled_from(OPTION_VALUES[name]))
    return chosen


def rng_from(seed: int) -> np.random.Generator:
    return np.random.default_rng(seed)


LEADING = st.sampled_from([(0,), (1,), (5,), (17,), (2, 9), (40,), (3, 1, 4)])


def soa(argument, layout):
    """An aos argument moved to soa when the call asks for it (hostile ones included)."""
    if layout == "soa" and isinstance(argument, np.ndarray) and argument.ndim >= 1 and argument.dtype.kind == "f":
        return np.moveaxis(argument, -1, 0).copy()
    return argument


def float32_pairs(wi, wo, layout):
    """What the kernel read, as float32 (..., 3), for comparison with the reference."""
    to = lambda w: np.moveaxis(np.asarray(w, np.float32), 0, -1) if layout == "soa" else np.asarray(w, np.float32)  # noqa: E731
    return to(wi), to(wo)


def assert_matches_reference(actual, expected, wi, wo):
    """SIMD vs float64 on the same float32 inputs, where both directions are clear of the horizon."""
    actual, expected = np.broadcast_arrays(np.asarray(actual, np.float64), expected)
    clear = np.broadcast_to(((wi[..., 2] > 0.05) & (wo[..., 2] > 0.05))[..., None], expected.shape)
    scale = np.maximum(np.abs(expected), 1e-6 * max(1.0, float(np.abs(expected).max(initial=0.0))))
    error = np.where(clear, np.abs(actual - expected) / scale, 0.0)
    assert error.max(initial=0.0) <= 1e-3, error.max()


def draw_pair_call(data, leading, seed, option_names):
    """(options, layout, wi, wo, material) of a call on pairs, or None when the material was refused."""
    rng = rng_from(seed)
    opts = data.draw(options(option_names))
    layout = opts.get("layout", "aos")
    wi = soa(data.draw(direction_argument(leading, rng)), layout)
    wo = soa(data.draw(direction_argument(leading, rng)), layout)
    material = outcome(lambda: pb.Material(**data.draw(material_argument(int(np.prod(leading)), rng))))
    return None if material is None else (opts, layout, wi, wo, material)


# ------------------------------------------------------------------ the batched calls

@FUZZ
@given(data=st.data(), leading=LEADING, seed=st.integers(0, 2**32 - 1),
       entry=st.sampled_from(("eval", "eval_out", "eval_lobes", "pdf", "eval_grad", "eval_vjp")))
def test_fuzz_evaluation(data, leading, seed, entry):
    names = {"pdf": ["threads", "check", "isa", "layout", "specular_sampler"],
             "eval_grad": ["model", "mode", "threads", "check", "cosine", "isa", "layout", "wrt"],
             "eval_vjp": ["model", "mode", "threads", "check", "cosine", "isa", "layout", "wrt"]}
    drawn = draw_pair_call(data, leading, seed,
                           names.get(entry, ["model", "mode", "threads", "check", "cosine", "isa", "layout"]))
    if drawn is None:
        return
    opts, layout, wi, wo, material = drawn
    out = None
    if entry == "eval_out":
        out_kind = data.draw(st.sampled_from(("fresh", "fresh", "alias_wi", "shifted", "misaligned", "float64",
                                              "readonly", "wrong_shape")))
        shape = tuple(leading) + (3,) if layout == "aos" else (3,) + tuple(leading)
        out = np.full(shape, np.nan, np.float32)
        if out_kind == "alias_wi" and isinstance(wi, np.ndarray) and wi.dtype == np.float32 and wi.shape == shape \
                and wi.flags.c_contiguous and wi.flags.aligned:
            out = wi
        elif out_kind == "shifted" and out.size:
            out = np.full(out.size + 1, np.nan, np.float32)[1:].reshape(shape)
            if isinstance(wi, np.ndarray) and wi.dtype == np.float32 and wi.shape == shape:
                base = np.empty(out.size + 1, np.float32)
                base[:-1] = np.asarray(wi).ravel()
                wi, out = base[:-1].reshape(shape), base[1:].reshape(shape)
                out[...] = np.nan
        elif out_kind == "misaligned":
            out = misaligned(out)
        elif out_kind == "float64":
            out = out.astype(np.float64)
        elif out_kind == "readonly":
            out.flags.writeable = False
        elif out_kind == "wrong_shape":
            out = out[..., :2]
    cotangent = soa(data.draw(direction_argument(leading, rng_from(seed + 1))), layout) if entry == "eval_vjp" else None
    wi_seen = np.array(wi, dtype=np.float32, copy=True) if isinstance(wi, np.ndarray) and wi.dtype.kind == "f" else None
    wo_seen = np.array(wo, dtype=np.float32, copy=True) if isinstance(wo, np.ndarray) and wo.dtype.kind == "f" else None

    call = {"eval": lambda: pb.eval(material, wi, wo, **opts),
            "eval_out": lambda: pb.eval(material, wi, wo, out=out, **opts),
            "eval_lobes": lambda: pb.eval_lobes(material, wi, wo, **opts),
            "pdf": lambda: pb.pdf(material, wi, wo, **opts),
            "eval_grad": lambda: pb.eval_grad(material, wi, wo, **opts),
            "eval_vjp": lambda: pb.eval_vjp(material, wi, wo, cotangent, **opts)}[entry]
    result = outcome(call)
    if result is None:
        return
    arrays = (list(result) if entry == "eval_lobes" else [result.value, result.jacobian] if entry == "eval_grad"
              else list(result.values()) if entry == "eval_vjp" else [result])
    for array in arrays:
        assert array.dtype == np.float32
        assert np.isfinite(array).all(), "non-finite output for accepted input"
    if entry == "eval_out":
        assert result is out
    if entry == "eval_vjp":
        assert_vjp_contracts_the_jacobian(result, material, wi, wo, cotangent, opts)
    if wi_seen is None or wo_seen is None or entry in ("pdf", "eval_vjp"):
        return
    a, b = float32_pairs(wi_seen, wo_seen, layout)
    if not (unit_length(a).all() and unit_length(b).all()):
        return  # check=False on non-unit directions: finite is all that is promised
    reference = pb.reference.eval_lobes if entry == "eval_lobes" else pb.reference.eval
    expected = reference(material, a, b, model=opts.get("model", "disney2014"), mode=opts.get("mode", "radiance"),
                         cosine=bool(opts.get("cosine", False)))
    for actual, wanted in zip(arrays, list(expected) if entry == "eval_lobes" else [expected]):  # eval_grad: its value
        actual = np.moveaxis(actual, 0, -1) if layout == "soa" else actual
        assert_matches_reference(actual, wanted, *np.broadcast_arrays(a, b))


def assert_vjp_contracts_the_jacobian(products, material, wi, wo, cotangent, opts):
    """An accepted eval_vjp equals Σ_c g_c ∂f_c/∂p from eval_grad of the same call, slot by slot."""
    gradient = pb.eval_grad(material, wi, wo, **opts)
    soa_layout = opts.get("layout", "aos") == "soa"
    jacobian = np.moveaxis(gradient.jacobian, (0, 1), (-2, -1)) if soa_layout else gradient.jacobian  # (..., 3, P)
    g = np.asarray(cotangent, np.float64)
    g = np.moveaxis(g, 0, -1) if soa_layout else g
    g = np.broadcast_to(g, jacobian.shape[:-1])
    expected = np.einsum("...c,...cp->...p", g, jacobian.astype(np.float64))
    magnitude = np.einsum("...c,...cp->...p", np.abs(g), np.abs(jacobian.astype(np.float64)))  # float32 rounding's scale
    for column, name in enumerate(gradient.names):
        actual = np.asarray(products[name], np.float64)
        error = np.abs(actual - expected[..., column])
        assert np.all(error <= 1e-5 * magnitude[..., column] + 1e-30), (name, error.max(), magnitude.max())


@FUZZ
@given(data=st.data(), leading=LEADING, seed=st.integers(0, 2**32 - 1), given_u=st.booleans())
def test_fuzz_sampling(data, leading, seed, given_u):
    rng = rng_from(seed)
    n = int(np.prod(leading))
    opts = data.draw(options(["model", "threads", "check", "isa", "layout", "specular_sampler", "seed"]))
    layout = opts.get("layout", "aos")
    wo = soa(data.draw(direction_argument(leading, rng)), layout)
    if given_u:
        u = rng.random(tuple(leading) + (3,))
        fault = data.draw(st.sampled_from(("none", "none", "one", "above", "below", "nan")))
        if fault != "none" and u.size:
            u.reshape(-1)[int(rng.integers(u.size))] = {"one": 1.0, "above": 1 + 1e-12, "below": -1e-300,
                                                       "nan": np.nan}[fault]
        opts["u"] = soa(convert(u, data.draw(st.sampled_from(("float32", "float64", "int64", "str"))),
                                data.draw(st.sampled_from(LAYOUT_FAULTS))), layout)
    material = outcome(lambda: pb.Material(**data.draw(material_argument(n, rng))))
    if material is None:
        return
    s = outcome(lambda: pb.sample(material, wo, **opts))
    if s is None:
        return
    for array in (s.wi, s.pdf, s.weight):
        assert np.isfinite(array).all(), "non-finite sample for accepted input"
    assert np.isin(s.lobe, (0, 1, 2)).all()
    assert (s.pdf >= 0).all() and (s.weight >= 0).all()


@FUZZ
@given(data=st.data(), seed=st.integers(0, 2**32 - 1))
def test_fuzz_albedo_and_uniforms(data, seed):
    rng = rng_from(seed)
    cos = data.draw(st.sampled_from((0.5, 1.0, 0.0, -0.1, 1.5, np.nan, "0.5", np.array([0.2, 0.9]),
                                     np.array([[0.3], [0.7]]))))
    samples = data.draw(st.sampled_from((2, 64, 1, 0, 2**40, 3.0, None)))
    material = outcome(lambda: pb.Material(**data.draw(material_argument(2, rng))))
    if material is not None:
        result = outcome(lambda: pb.albedo(material, cos, samples=samples,
                                           **data.draw(options(["model", "threads", "seed", "specular_sampler"]))))
        if result is not None:
            assert np.isfinite(result.total).all() and np.isfinite(result.total_error).all()
    n = data.draw(st.sampled_from((0, 1, 5, -1, 2**62, 2.0, None)))
    first = data.draw(st.sampled_from((0, 7, 2**63 - 6, 2**63, -1, "0")))
    u = outcome(lambda: pb.random_uniforms(data.draw(st.sampled_from(OPTION_VALUES["seed"])), n, first))
    if u is not None:
        assert u.shape == (n, 3) and np.all((u >= 0) & (u < 1))


# ------------------------------------------------------------------ the float64 reference and the toolkit

@FUZZ
@given(data=st.data(), leading=LEADING, seed=st.integers(0, 2**32 - 1),
       entry=st.sampled_from(("eval", "eval_lobes", "pdf", "sample", "lobe_probabilities", "eval_grad")))
def test_fuzz_reference(data, leading, seed, entry):
    rng = rng_from(seed)
    n = int(np.prod(leading))
    wi = data.draw(direction_argument(leading, rng))
    wo = data.draw(direction_argument(leading, rng))
    material = outcome(lambda: pb.Material(**data.draw(material_argument(n, rng))))
    if material is None:
        return
    opts = data.draw(options(["model"] + (["cosine"] if entry.startswith("eval") else [])
                             + (["specular_sampler"] if entry in ("pdf", "sample") else [])))
    u = convert(rng.random(tuple(leading) + (3,)), data.draw(st.sampled_from(("float64", "float32", "str"))),
                data.draw(st.sampled_from(LAYOUT_FAULTS)))
    if entry == "lobe_probabilities":
        opts.pop("model", None)
    call = {"eval": lambda: pb.reference.eval(material, wi, wo, **opts),
            "eval_lobes": lambda: pb.reference.eval_lobes(material, wi, wo, **opts),
            "pdf": lambda: pb.reference.pdf(material, wi, wo, **opts),
            "sample": lambda: pb.reference.sample(material, wo, u, **opts),
            "lobe_probabilities": lambda: pb.reference.lobe_probabilities(material, wo),
            "eval_grad": lambda: pb.reference.eval_grad(material, wi, wo, **opts)}[entry]
    result = outcome(call)
    if result is not None:
        arrays = result[:2] if entry == "eval_grad" else result if isinstance(result, tuple) else [result]
        for array in arrays:
            assert np.isfinite(array).all()


# the toolkit's types: each constructor's parameters and each method's arguments
TOOLKIT_TYPES = {"GGX": ("alpha_x", "alpha_y"), "Beckmann": ("alpha_x", "alpha_y"), "BlinnPhong": ("alpha_x", "alpha_y"),
                 "StudentT": ("alpha_x", "alpha_y", "gamma"), "ExponentialPower": ("alpha_x", "alpha_y", "p"),
                 "GTR": ("alpha", "gamma")}
TOOLKIT_METHODS = {"d": ("h",), "pdf": ("h",), "sample": ("u1", "u2"), "lambda_": ("w",), "g1": ("w",),
                   "g2": ("wi", "wo"), "pdf_visible": ("h", "wo"), "sample_visible": ("wo", "u1", "u2"),
                   "g2_over_4cos": ("wi", "wo")}
TOOLKIT = {f"{type_name}.{method}": (parameters, TOOLKIT_METHODS[method])
           for type_name, parameters in TOOLKIT_TYPES.items() for method in TOOLKIT_METHODS
           if hasattr(getattr(pb.microfacet, type_name), method)}
KEYWORD_ONLY = {("StudentT", "gamma"), ("ExponentialPower", "p")}
# the options, good and bad: of the constructors, then of the methods
TOOLKIT_OPTIONS = {"Beckmann": ("approximation", (None, "walter", "karis", 1)),
                   "GTR": ("closed_forms", (True, False, 1, None)),
                   "g2": ("correlated", (True, False, "yes", None)),
                   "g2_over_4cos": ("approximation", (None, "karis", "hammon", "walter", 3))}
SCALAR_VALUES = (0.5, 1.0, 1e-6, 0.0, -0.5, 1.5, np.nan, np.inf, "a", None, 1e300)


def toolkit_value(data, rng, leading, type_name, argument):
    if argument in ("h", "w", "wi", "wo"):
        return data.draw(direction_argument(leading, rng))
    if data.draw(st.booleans()):
        values = rng.random(leading) * 0.98 + 0.01
        if (type_name, argument) == ("StudentT", "gamma"):
            values = 1.6 + 4.0 * values  # in its domain (3/2, 1e12]
        elif argument == "p":
            values = 0.1 + 4.0 * values  # in its domain [0.1, 10]
        return convert(values, data.draw(st.sampled_from(DTYPES[:4])), data.draw(st.sampled_from(LAYOUT_FAULTS)))
    value = data.draw(st.sampled_from(SCALAR_VALUES))
    if argument == "gamma" and isinstance(value, float) and value == 0.5:
        value = 2.0
    return value


def toolkit_option(data, key):
    if key not in TOOLKIT_OPTIONS or not data.draw(st.booleans()):
        return {}
    name, values = TOOLKIT_OPTIONS[key]
    return {name: data.draw(st.sampled_from(values))}


@FUZZ
@given(data=st.data(), leading=LEADING, seed=st.integers(0, 2**32 - 1), name=st.sampled_from(sorted(TOOLKIT)))
def test_fuzz_toolkit(data, leading, seed, name):
    rng = rng_from(seed)
    type_name, method = name.split(".")
    parameters, arguments = TOOLKIT[name]
    positional, keywords = [], toolkit_option(data, type_name)
    for parameter in parameters:
        value = toolkit_value(data, rng, leading, type_name, parameter)
        if (type_name, parameter) in KEYWORD_ONLY:
            keywords[parameter] = value
        else:
            positional.append(value)
    values = [toolkit_value(data, rng, leading, type_name, argument) for argument in arguments]
    options = toolkit_option(data, method)
    distribution = outcome(lambda: getattr(pb.microfacet, type_name)(*positional, **keywords))
    if distribution is None:
        return
    result = outcome(lambda: getattr(distribution, method)(*values, **options))
    if result is not None:
        assert np.isfinite(result).all()


# ------------------------------------------------------------------ Material and render_sphere

@FUZZ
@given(data=st.data(), seed=st.integers(0, 2**32 - 1))
def test_fuzz_material_and_render(data, seed):
    rng = rng_from(seed)
    material = outcome(lambda: pb.Material(**data.draw(material_argument(3, rng))))
    if material is None:
        return
    resolution = data.draw(st.sampled_from((8, 2, 1, 0, None, 2.5, 10**9, "8")))
    kwargs = {}
    if data.draw(st.booleans()):
        kwargs["light"] = data.draw(st.sampled_from(((0, 0, 1), (0, 0, 0), (np.nan, 0, 1), (1, 2), "up",
                                                     (1e300, 0, 1e300))))
    if data.draw(st.booleans()):
        kwargs["ambient"] = data.draw(st.sampled_from((0.0, 0.1, -1.0, np.nan)))
    if data.draw(st.booleans()):
        kwargs["light_intensity"] = data.draw(st.sampled_from((3.0, 0.0, -1.0, np.inf)))
    if not material.is_uniform:
        return  # per-element materials need the image's shape; the batched calls cover them
    image = outcome(lambda: pb.render.render_sphere(material, resolution, **kwargs))
    if image is not None:
        assert image.shape == (resolution, resolution, 3) and np.isfinite(image).all()


@pytest.mark.parametrize("isa", ISAS)
def test_fuzz_sees_every_isa(isa):
    # the option draws include each available isa; make sure each one ran at least on good input
    wi = unit_vectors(rng_from(1), (33,)).astype(np.float32)
    assert np.isfinite(pb.eval(pb.Material(), wi, wi[::-1].copy(), isa=isa)).all()


# ------------------------------------------------------------------ the entry points added since

@FUZZ
@given(data=st.data(), leading=LEADING, seed=st.integers(0, 2**32 - 1),
       entry=st.sampled_from(("eval_pdf", "eval_pdf_out", "eval_grad_wrt", "eval_grad_out", "sample_n",
                              "compensated_eval", "compensated_sample")))
def test_fuzz_paired_outputs_counts_and_compensation(data, leading, seed, entry):
    drawn = draw_pair_call(data, leading, seed, ["model", "threads", "check", "isa", "layout"])
    if drawn is None:
        return
    opts, layout, wi, wo, material = drawn
    value_shape = tuple(leading) + (3,) if layout == "aos" else (3,) + tuple(leading)
    wrt = data.draw(st.sampled_from((None, "roughness", ["base_color", "sheen"], [], "albedo", ["metallic", 3])))
    width = len(pb._gradient.columns(wrt)) if outcome(lambda: pb._gradient.columns(wrt)) is not None else 13
    second_shape = {"eval_pdf_out": tuple(leading),
                    "eval_grad_out": tuple(leading) + (3, width) if layout == "aos" else (3, width) + tuple(leading)}
    out = None
    if entry in second_shape:
        kind = data.draw(st.sampled_from(("fresh", "fresh", "none_second", "overlap_wi", "same", "wrong_shape")))
        first, second = np.full(value_shape, np.nan, np.float32), np.full(second_shape[entry], np.nan, np.float32)
        if kind == "none_second":
            second = None
        elif kind == "overlap_wi" and isinstance(wi, np.ndarray) and wi.dtype == np.float32 and second.size:
            second = wi.reshape(-1)[: second.size].reshape(second.shape) if wi.size >= second.size else second
        elif kind == "same":
            second = first
        elif kind == "wrong_shape":
            second = second[..., :0] if second.ndim else second
        out = (first, second)
    wi_before = np.array(wi, copy=True) if isinstance(wi, np.ndarray) else None
    compensation = data.draw(st.sampled_from((True, True, False, 1, None)))
    call = {"eval_pdf": lambda: pb.eval_pdf(material, wi, wo, **opts),
            "eval_pdf_out": lambda: pb.eval_pdf(material, wi, wo, out=out, **opts),
            "eval_grad_wrt": lambda: pb.eval_grad(material, wi, wo, wrt=wrt, **opts),
            "eval_grad_out": lambda: pb.eval_grad(material, wi, wo, wrt=wrt, out=out, **opts),
            "sample_n": lambda: pb.sample(material, wo, n=data.draw(st.sampled_from((0, 1, 3, -1, 2.0, None))),
                                          seed=3, **opts),
            "compensated_eval": lambda: pb.eval(material, wi, wo, energy_compensation=compensation, **opts),
            "compensated_sample": lambda: pb.sample(material, wo, energy_compensation=compensation, seed=1,
                                                    **opts)}[entry]
    result = outcome(call)
    if wi_before is not None and entry.endswith("_out"):
        np.testing.assert_array_equal(np.asarray(wi), wi_before, err_msg="an input was overwritten")
    if result is None:
        return
    arrays = [result.wi, result.pdf, result.weight] if entry.startswith(("sample", "compensated_sample")) \
        else [result] if entry == "compensated_eval" else list(result[:2])
    for array in arrays:
        assert np.isfinite(array).all(), "non-finite output for accepted input"
    if out is not None:
        assert result[0] is out[0] and result[1] is out[1]


@FUZZ
@given(data=st.data(), seed=st.integers(0, 2**32 - 1),
       entry=st.sampled_from(("frame", "to_local", "to_world", "spherical", "half_diff", "wiwo", "gamma22",
                              "srgb", "linear_srgb", "tone")))
def test_fuzz_frames_and_colors(data, seed, entry):
    rng = rng_from(seed)
    leading = data.draw(LEADING)
    vector = data.draw(direction_argument(leading, rng))
    scalar = data.draw(st.sampled_from(SCALAR_VALUES + (rng.random(leading) * 3,)))
    frame = data.draw(st.sampled_from(("good", "scaled", "nan", "2x2", "str")))
    frames = {"good": pb.frames.frame_from_normal([0.0, 0.6, 0.8]), "scaled": 2.0 * np.eye(3),
              "nan": np.full((3, 3), np.nan), "2x2": np.eye(2), "str": "eye"}[frame]
    tangent = data.draw(st.sampled_from((None, [1.0, 0.0, 0.0], [1e200, 0, 0], [0, 0, 1], [np.nan, 0, 0], "x")))
    color = data.draw(st.sampled_from((0.5, 1e300, -1.0, np.nan, [0.2, 0.4, 0.9], "red", np.inf,
                                       rng.random((4, 3)) * 1e3)))
    opposite = -vector if data.draw(st.booleans()) and isinstance(vector, np.ndarray) and vector.dtype.kind == "f" \
        else vector
    call = {"frame": lambda: pb.frames.frame_from_normal(vector, tangent=tangent),
            "to_local": lambda: pb.frames.to_local(vector, frames),
            "to_world": lambda: pb.frames.to_world(vector, frames),
            "spherical": lambda: pb.frames.spherical_to_direction(scalar, scalar),
            "half_diff": lambda: pb.frames.half_diff_to_wiwo(scalar, 0.3, scalar, 1.0),
            "wiwo": lambda: pb.frames.wiwo_to_half_diff(vector, opposite),
            "gamma22": lambda: pb.gamma22_to_linear(color),
            "srgb": lambda: pb.srgb_to_linear(color),
            "linear_srgb": lambda: pb.linear_to_srgb(color),
            "tone": lambda: pb.render.to_srgb8(color,
                                               exposure=data.draw(st.sampled_from((1.0, 0.0, -1.0, np.inf))),
                                               curve=data.draw(st.sampled_from(("filmic", "reinhard", "clip", "x"))))
            }[entry]
    result = outcome(call)
    if result is None:
        return
    for array in result if isinstance(result, tuple) else [result]:
        array = np.asarray(array)
        assert np.isfinite(array.astype(np.float64)).all(), f"{entry}: non-finite result for accepted input"
    if entry == "frame":
        rows = np.asarray(result)
        np.testing.assert_allclose(np.einsum("...ij,...kj->...ik", rows, rows), np.broadcast_to(np.eye(3), rows.shape),
                                   atol=1e-12)


MERL_TABLE = np.full((3,) + pb.measured.MERL_SHAPE, 0.1)


@FUZZ
@given(data=st.data(), seed=st.integers(0, 2**32 - 1),
       entry=st.sampled_from(("merl_eval", "merl_table", "save_merl", "fit")))
def test_fuzz_measured_and_fit(data, seed, entry, tmp_path_factory):
    rng = rng_from(seed)
    leading = data.draw(st.sampled_from([(1,), (5,), (2, 3)]))
    wi = data.draw(direction_argument(leading, rng))
    wo = data.draw(direction_argument(leading, rng))
    if entry == "merl_eval":
        interpolation = data.draw(st.sampled_from(("nearest", "linear", "cubic", None)))
        table = pb.measured.MerlBRDF(MERL_TABLE)
        result = outcome(lambda: table.eval(wi, wo, interpolation=interpolation))
    elif entry == "merl_table":
        table = MERL_TABLE.copy()
        table.reshape(-1)[int(rng.integers(table.size))] = data.draw(st.sampled_from((np.nan, np.inf, -1.0, 0.0)))
        result = outcome(lambda: pb.measured.MerlBRDF(data.draw(st.sampled_from((table, table[:2], "table")))).table)
        if result is not None:
            result = np.nan_to_num(result)  # NaN marks cells without data
    elif entry == "save_merl":
        bad = data.draw(st.sampled_from((0.5, -1.0, np.inf, np.nan)))
        path = tmp_path_factory.mktemp("merl") / "table.binary"
        result = outcome(lambda: pb.measured.save_merl(path, lambda a, b: np.where(a[:, :1] > 0.99, bad, 0.5)
                                                       * np.ones((len(a), 3))) or "written")
        if result is None and path.exists():
            pytest.fail("save_merl wrote a file for a call it refused")
        return
    else:
        n = 24
        wi_fit = unit_vectors(rng, (n,))
        wo_fit = unit_vectors(rng, (n,))
        measured = pb.reference.eval(pb.Material(roughness=0.4), wi_fit, wo_fit)
        fault = data.draw(st.sampled_from(("none", "nan_row", "zeros", "negative", "inf", "shape")))
        if fault == "nan_row":
            measured[:] = np.nan
        elif fault == "zeros":
            measured[:] = 0.0
        elif fault == "negative":
            measured[3, 1] = -1.0
        elif fault == "inf":
            measured[5, 2] = np.inf
        elif fault == "shape":
            measured = measured[:, :2]
        kwargs = {"fit": data.draw(st.sampled_from((["roughness"], ["roughness", "base_color"], "sheen", ["bogus"])))}
        if data.draw(st.booleans()):
            kwargs["loss"] = data.draw(st.sampled_from(("log", "relative", "linear", "l1")))
        if data.draw(st.booleans()):
            kwargs["bounds"] = data.draw(st.sampled_from(({"roughness": (0.1, 0.9)}, {"roughness": (0.5, 0.5)},
                                                          {"roughness": (0.9, 0.1)}, {"roughness": 0.5},
                                                          {"roughness": (np.nan, 1.0)}, {"bogus": (0, 1)})))
        if data.draw(st.booleans()):
            kwargs["max_iterations"] = data.draw(st.sampled_from((5, 0, -1, 2.5, "5")))
        if data.draw(st.booleans()):
            kwargs["weights"] = data.draw(st.sampled_from((np.ones(n), np.ones(n + 1), -np.ones(n), "w")))
        if data.draw(st.booleans()):
            kwargs["method"] = data.draw(st.sampled_from(("batched", "scipy", "newton")))
        if data.draw(st.booleans()):
            kwargs["precision"] = data.draw(st.sampled_from(("float32", "float64", "half")))
        if data.draw(st.booleans()):  # a batch: the faulty problem beside a clean one, which must still be fitted
            clean = pb.reference.eval(pb.Material(roughness=0.4), wi_fit, wo_fit)
            measured = np.stack([clean[:, :measured.shape[1]], measured]) if measured.ndim == 2 else measured
        fitted = outcome(lambda: pb.fit(wi_fit, wo_fit, measured, **kwargs))
        result = None if fitted is None else np.concatenate([np.ravel(getattr(fitted.material, name))
                                                             for name in pb.PARAMETERS])
        if fitted is not None and np.ndim(measured) == 3:
            assert np.ravel(fitted.success)[0] or kwargs.get("max_iterations") in (5,), "a clean problem failed"
    if result is not None:
        assert np.isfinite(np.asarray(result, dtype=np.float64)).all(), f"{entry}: non-finite result"


@FUZZ
@given(data=st.data(), entry=st.sampled_from(("brdf_slice", "polar_lobes", "lit_sphere", "albedo_curves")))
def test_fuzz_plot_arguments(data, entry):
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    material = data.draw(st.sampled_from((pb.Material(), "gold", "nonsense", 3, None)))
    resolution = data.draw(st.sampled_from((8, 1, 0, -4, 2.5, 10**9, "8")))
    call = {"brdf_slice": lambda: pb.plot.brdf_slice(material, resolution=resolution,
                                                     phi_d=data.draw(st.sampled_from((90.0, np.nan, 400.0, "x")))),
            "polar_lobes": lambda: pb.plot.polar_lobes(material, data.draw(st.sampled_from((30.0, 95.0, np.nan, -1.0)))),
            "lit_sphere": lambda: pb.plot.lit_sphere(material, resolution=resolution),
            "albedo_curves": lambda: pb.plot.albedo_curves(material, samples=data.draw(st.sampled_from((64, 1, 0, 2**40))),
                                                           angles=data.draw(st.sampled_from(([0.0, 45.0], [np.nan],
                                                                                             [120.0], "a"))))}[entry]
    try:
        outcome(call)
    finally:
        plt.close("all")


ENVIRONMENT_MAP = pb.environment.Environment(np.random.default_rng(11).uniform(0.0, 3.0, size=(8, 16, 3)))
UNIFORM_FAULTS = {"good": lambda u: u, "nan": lambda u: np.where(u > 0.9, np.nan, u), "above": lambda u: u + 0.5,
                  "below": lambda u: u - 0.5, "ends": lambda u: np.round(u), "one_column": lambda u: u[..., :1],
                  "scalar": lambda u: 0.5, "str": lambda u: u.astype(str)}
RADIANCE_FAULTS = {"good": lambda r: r, "nan": lambda r: np.where(r > 0.5, np.nan, r), "negative": lambda r: r - 0.5,
                   "inf": lambda r: np.where(r > 0.5, np.inf, r), "flat": lambda r: r[..., 0], "wide": lambda r: np.repeat(r, 2, axis=-1),
                   "int": lambda r: (r > 0.5).astype(np.int64), "str": lambda r: r.astype(str)}


@FUZZ
@given(data=st.data(), seed=st.integers(0, 2**32 - 1),
       entry=st.sampled_from(("sample", "pdf", "call", "lookup", "studio_radiance", "outdoor_radiance", "callable",
                              "map_height")))
def test_fuzz_environments(data, seed, entry):
    """Environment maps, the built-in radiance functions and callable environments: hostile uniforms,
    directions, radiance and sizes are refused naming the argument; what is accepted is finite."""
    rng = rng_from(seed)
    leading = data.draw(LEADING)
    if entry == "sample":
        uniforms = UNIFORM_FAULTS[data.draw(st.sampled_from(list(UNIFORM_FAULTS)))](rng.random(tuple(leading) + (2,)))
        result = outcome(lambda: ENVIRONMENT_MAP.sample(uniforms))
    elif entry in ("pdf", "call", "lookup"):
        directions = data.draw(direction_argument(leading, rng))
        method = {"pdf": ENVIRONMENT_MAP.pdf, "call": ENVIRONMENT_MAP, "lookup": ENVIRONMENT_MAP.lookup}[entry]
        result = outcome(lambda: method(directions))
    elif entry in ("studio_radiance", "outdoor_radiance"):
        directions = data.draw(direction_argument(leading, rng))
        result = outcome(lambda: getattr(pb.procedural_environments, entry)(directions))
    elif entry == "callable":
        fault = RADIANCE_FAULTS[data.draw(st.sampled_from(list(RADIANCE_FAULTS)))]
        model = data.draw(st.sampled_from(("disney2014", "disney2015")))
        material = pb.Material(spec_trans=1.0) if model == "disney2015" else pb.Material()

        def environment(direction):
            return fault(np.random.default_rng(7).random(np.shape(direction)))

        result = outcome(lambda: pb.render.render_sphere(material, 4, model=model, environment=environment, samples=2))
    else:
        height = data.draw(st.sampled_from((1, 2.5, True, "8", pb.procedural_environments.MAX_HEIGHT + 1, 10**9)))
        result = outcome(lambda: pb.procedural_environments.studio(height))
        assert result is None, f"studio({height!r}) was accepted"
    if result is not None:
        for array in result if isinstance(result, tuple) else [result]:
            assert np.isfinite(np.asarray(array, dtype=np.float64)).all(), f"{entry}: non-finite result"


# ------------------------------------------------------------------ the PyTorch and JAX operations

INTEROP_FUZZ = settings(derandomize=True, max_examples=60, deadline=None, database=None,
                        suppress_health_check=list(HealthCheck))
INTEROP_OPTIONS = {"model": ("disney2014", "disney2012", "disney2015", "bogus"), "cosine": (False, True, 1),
                   "mode": ("radiance", "importance", "light")}


def framework_value(framework, value, kind):
    """``value`` as given, or a float numpy array made the framework's tensor/array (any float dtype)."""
    if kind == "as_given" or not isinstance(value, np.ndarray) or value.dtype.kind != "f":
        return value
    if framework == "torch":
        import torch

        return torch.tensor(np.array(value), dtype=getattr(torch, value.dtype.name))
    import jax.numpy as jnp

    return jnp.asarray(value)


@INTEROP_FUZZ
@given(data=st.data(), leading=LEADING, seed=st.integers(0, 2**32 - 1), framework=st.sampled_from(("torch", "jax")),
       cotangent_fault=st.sampled_from(("none", "none", "nan", "inf")))
def test_fuzz_torch_and_jax_eval(data, leading, seed, framework, cotangent_fault):
    """pbt.eval and pbj.eval with hostile materials, directions, dtypes and options, and their
    backward passes with hostile cotangents: a ValueError/TypeError naming an argument, or
    finite values that agree with the float64 reference and finite gradients."""
    module = pytest.importorskip(f"principled_brdf.{framework}")
    rng = rng_from(seed)
    kinds = ("as_given", "as_given", "framework")
    material = {name: framework_value(framework, value, data.draw(st.sampled_from(kinds)))
                for name, value in data.draw(material_argument(int(np.prod(leading)), rng)).items()}
    wi = framework_value(framework, data.draw(direction_argument(leading, rng)), data.draw(st.sampled_from(kinds)))
    wo = framework_value(framework, data.draw(direction_argument(leading, rng)), data.draw(st.sampled_from(kinds)))
    opts = {name: data.draw(st.sampled_from(values)) for name, values in INTEROP_OPTIONS.items()
            if data.draw(st.booleans())}
    result = outcome(lambda: module.eval(material, wi, wo, **opts))
    if result is None:
        return
    value = np.asarray(result, np.float64)
    assert np.isfinite(value).all(), "non-finite output for accepted input"
    as_numpy = lambda v: np.asarray(v, np.float64) if hasattr(v, "dtype") and v.dtype.kind != "f" else np.asarray(v)  # noqa: E731
    a, b = (np.asarray(np.asarray(w), np.float32) for w in (wi, wo))
    checked = pb.Material(**{name: as_numpy(v) for name, v in material.items()}, bright_base_color=True)
    expected = pb.reference.eval(checked, a, b, model=opts.get("model", "disney2014"), cosine=bool(opts.get("cosine")),
                                 mode=opts.get("mode", "radiance"))
    assert_matches_reference(value, expected, *np.broadcast_arrays(a, b))
    cotangent = inject(np.ones(value.shape), cotangent_fault, rng)
    gradients = outcome(lambda: framework_gradients(framework, module, material, wi, wo, opts, cotangent))
    if cotangent_fault != "none" and value.size:
        assert gradients is None, "a non-finite cotangent was accepted"
    for gradient in gradients or []:
        assert np.isfinite(np.asarray(gradient, np.float64)).all(), "non-finite gradient for accepted input"


def framework_gradients(framework, module, material, wi, wo, opts, cotangent):
    """The vector-Jacobian product of ``module.eval`` in every float input, for ``cotangent``."""
    if framework == "torch":
        import torch

        inputs = {name: v.detach().requires_grad_() if isinstance(v, torch.Tensor) else v
                  for name, v in (*material.items(), ("wi", wi), ("wo", wo))}
        f = module.eval({n: v for n, v in inputs.items() if n not in ("wi", "wo")}, inputs["wi"], inputs["wo"], **opts)
        leaves = [v for v in inputs.values() if isinstance(v, torch.Tensor)]
        if not leaves:
            return []
        return torch.autograd.grad(f, leaves, torch.tensor(cotangent, dtype=f.dtype), allow_unused=True)
    import jax

    names = [n for n, v in (*material.items(), ("wi", wi), ("wo", wo)) if isinstance(v, jax.Array)]
    arguments = {**material, "wi": wi, "wo": wo}

    def call(*differentiated):
        given = {**arguments, **dict(zip(names, differentiated))}
        return module.eval({n: v for n, v in given.items() if n not in ("wi", "wo")}, given["wi"], given["wo"], **opts)

    value, vjp = jax.vjp(call, *[arguments[n] for n in names])
    return jax.block_until_ready(vjp(jax.numpy.asarray(cotangent, value.dtype)))
