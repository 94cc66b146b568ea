"""Types: the stubs of the compiled module match it, and mypy sees the package's
annotations (py.typed): a typical user script checks cleanly under --strict,
deliberate mistakes in one are caught, and the package itself checks.

mypy runs as a subprocess on the installed package, as a user's would. The
first run takes 20-30 s (numpy's stubs); its cache is kept in pytest's cache
directory, so later runs take a few seconds.
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
import textwrap
import types
from pathlib import Path

import numpy as np
import pytest

import principled_brdf as pb
from principled_brdf import _core

PACKAGE_DIR = Path(pb.__file__).parent
STUB = PACKAGE_DIR / "_core.pyi"


# --------------------------------------------------------------------------
# (a) _core.pyi against the compiled module


def _stub_tree() -> ast.Module:
    assert STUB.is_file(), f"{STUB} is not installed beside the compiled module"
    assert (PACKAGE_DIR / "py.typed").is_file(), "py.typed is not installed"
    return ast.parse(STUB.read_text())


def _aliases(tree: ast.Module) -> dict[str, ast.expr]:
    """The stub's private type aliases (``_Int: TypeAlias = ...``)."""
    return {node.target.id: node.value for node in tree.body
            if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name) and node.value is not None
            and ast.unparse(node.annotation) == "TypeAlias"}


def _public_stub_names(body: list[ast.stmt]) -> dict[str, ast.stmt]:
    names: dict[str, ast.stmt] = {}
    for node in body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names[node.name] = node
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            names[node.target.id] = node
        elif isinstance(node, ast.Assign):
            names.update({t.id: node for t in node.targets if isinstance(t, ast.Name)})
    return {name: node for name, node in names.items() if not name.startswith("_")}


def _public_runtime_names(module: types.ModuleType) -> set[str]:
    return {name for name in dir(module) if not name.startswith("_")}


def _microfacet_class(tree: ast.Module) -> ast.ClassDef:
    """The class the stub declares ``microfacet: Final[<class>]`` with."""
    annotation = _public_stub_names(tree.body)["microfacet"]
    assert isinstance(annotation, ast.AnnAssign)
    class_name = ast.unparse(annotation.annotation).removeprefix("Final[").removesuffix("]")
    (cls,) = [n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == class_name]
    return cls


def test_stub_covers_every_public_name_of_the_compiled_module():
    tree = _stub_tree()
    assert set(_public_stub_names(tree.body)) == _public_runtime_names(_core)
    assert isinstance(_core.microfacet, types.ModuleType)
    methods = {n.name for n in _microfacet_class(tree).body if isinstance(n, ast.FunctionDef)}
    assert methods == _public_runtime_names(_core.microfacet)


def _resolve(node: ast.expr, aliases: dict[str, ast.expr]) -> str:
    """The annotation with the stub's aliases substituted, as source text."""

    class Substitute(ast.NodeTransformer):
        def visit_Name(self, name: ast.Name) -> ast.AST:
            if name.id in aliases:
                return self.visit(ast.parse(ast.unparse(aliases[name.id]), mode="eval").body)
            return name

    return ast.unparse(Substitute().visit(ast.parse(ast.unparse(node), mode="eval").body))


def _kind(annotation: str) -> str | None:
    """What an annotation (pybind11's or the stub's) says a value is, coarsely;
    None for pybind11's ``object`` (py::object, anything)."""
    text = re.sub(r"\s*\|\s*None$", "", annotation.strip())
    if text == "object":
        return None
    if isinstance(getattr(_core, text.removeprefix("principled_brdf._core."), None), type):
        return text.removeprefix("principled_brdf._core.")  # one of the module's classes
    if re.match(r"(collections\.abc\.)?Sequence\b", text):
        return "sequence"
    if "SupportsInt" in text:
        return "int"
    if "SupportsFloat" in text:
        return "float"
    if text.startswith("tuple"):
        return "tuple"
    if text.startswith("dict") or text == "_CpuInfo":  # the stub's TypedDict of cpu_info
        return "dict"
    for dtype in ("float32", "float64", "int32", "int64", "bool"):
        if re.search(rf"\b(numpy|np)\.{dtype}_?\b", text):
            return f"{dtype} array"
    assert text in ("bool", "str", "int", "float", "None"), f"unexpected annotation {annotation!r}"
    return text


def _runtime_signature(function: object) -> ast.FunctionDef:
    """pybind11's signature, the first line of the docstring, parsed as a ``def``."""
    doc = getattr(function, "__doc__", None) or ""
    first = doc.strip().splitlines()[0]
    node = ast.parse(f"def {first}: ...").body[0]
    assert isinstance(node, ast.FunctionDef)
    return node


def _compare(runtime: ast.FunctionDef, stub: ast.FunctionDef, aliases: dict[str, ast.expr]) -> None:
    where = f"_core {stub.name}"
    for kind in ("posonlyargs", "args", "kwonlyargs"):
        assert [a.arg for a in getattr(stub.args, kind)] == [a.arg for a in getattr(runtime.args, kind)], \
            f"{where}: {kind}"
    assert len(stub.args.defaults) == len(runtime.args.defaults), f"{where}: parameters with defaults"
    assert [d is None for d in stub.args.kw_defaults] == [d is None for d in runtime.args.kw_defaults], where
    for stub_default, runtime_default in zip(stub.args.defaults, runtime.args.defaults):
        assert ast.unparse(stub_default) == ast.unparse(runtime_default), f"{where}: default"
    for stub_default, runtime_default in zip(stub.args.kw_defaults, runtime.args.kw_defaults):
        if stub_default is not None and runtime_default is not None:
            assert ast.unparse(stub_default) == ast.unparse(runtime_default), f"{where}: default"
    named = zip(stub.args.args + stub.args.kwonlyargs, runtime.args.args + runtime.args.kwonlyargs)
    for stub_arg, runtime_arg in named:
        assert runtime_arg.annotation is not None and stub_arg.annotation is not None
        expected = _kind(ast.unparse(runtime_arg.annotation))
        if expected is not None:
            assert _kind(_resolve(stub_arg.annotation, aliases)) == expected, f"{where}: {stub_arg.arg}"
    assert runtime.returns is not None and stub.returns is not None
    assert _kind(_resolve(stub.returns, aliases)) == _kind(ast.unparse(runtime.returns)), f"{where}: return"


def test_stub_signatures_match_pybind11s():
    tree = _stub_tree()
    aliases = _aliases(tree)
    functions = [(getattr(_core, name), node) for name, node in _public_stub_names(tree.body).items()
                 if isinstance(node, ast.FunctionDef)]
    functions += [(getattr(_core.microfacet, node.name), node) for node in _microfacet_class(tree).body
                  if isinstance(node, ast.FunctionDef)]
    compiled = [f for module in (_core, _core.microfacet) for f in vars(module).values()
                if isinstance(f, types.BuiltinFunctionType)]
    assert len(functions) == len(compiled)
    for function, node in functions:
        _compare(_runtime_signature(function), node, aliases)


def test_stub_classes_match_pybind11s():
    """The options classes: the constructor's keywords, and each field's type."""
    tree = _stub_tree()
    aliases = _aliases(tree)
    classes = [node for node in _public_stub_names(tree.body).values() if isinstance(node, ast.ClassDef)]
    assert {node.name for node in classes} == {name for name in _public_runtime_names(_core)
                                               if isinstance(getattr(_core, name), type)}
    for node in classes:
        runtime_class = getattr(_core, node.name)
        (init,) = [n for n in node.body if isinstance(n, ast.FunctionDef) and n.name == "__init__"]
        runtime_init = _runtime_signature(runtime_class.__init__)
        for signature in (init, runtime_init):
            assert signature.args.args[0].arg == "self"
            del signature.args.args[0]
        _compare(runtime_init, init, aliases)
        fields = {n.target.id: n.annotation for n in node.body
                  if isinstance(n, ast.AnnAssign) and isinstance(n.target, ast.Name)}
        properties = {name for name, value in vars(runtime_class).items() if isinstance(value, property)}
        assert set(fields) == properties, node.name
        for name, annotation in fields.items():
            # pybind11's getter signature has no name: "(self: ...) -> int"
            first = getattr(runtime_class, name).fget.__doc__.strip().splitlines()[0]
            getter = ast.parse(f"def {name}{first}: ...").body[0]
            assert isinstance(getter, ast.FunctionDef) and getter.returns is not None
            assert _kind(_resolve(annotation, aliases)) == _kind(ast.unparse(getter.returns)), f"{node.name}.{name}"


def test_stub_constants_have_their_runtime_types():
    assert isinstance(_core.PARAM_SLOTS, int)
    for names in (_core.MODEL_NAMES, _core.LOBE_NAMES, _core.SAMPLED_LOBE_NAMES, _core.SAMPLER_NAMES):
        assert isinstance(names, tuple) and all(isinstance(n, str) for n in names)
    for name, first_slot, slots, defaults, lower, upper in _core.PARAMETER_TABLE:
        assert isinstance(name, str) and isinstance(first_slot, int) and isinstance(slots, int)
        assert isinstance(defaults, tuple) and all(isinstance(v, float) for v in defaults)
        assert isinstance(lower, float) and isinstance(upper, float)
    info = _core.cpu_info()
    assert set(info) == {"isa", "float_lanes", "available", "threads"}
    assert isinstance(info["available"], list)


def test_the_typing_literals_are_the_cpp_tables():
    """The names spelled out for type checkers (Literal types, the Lobes fields) are the C++ tables'."""
    from principled_brdf import _typing

    assert _typing.Model.__args__ == tuple(_core.MODEL_NAMES)
    assert _typing.SpecularSampler.__args__ == tuple(_core.SAMPLER_NAMES)
    assert _typing.Mode.__args__ == tuple(_core.MODE_NAMES)
    source = ast.parse((PACKAGE_DIR / "_results.py").read_text())
    (lobe_arrays,) = [n for n in ast.walk(source) if isinstance(n, ast.ClassDef) and n.name == "_LobeArrays"]
    fields = tuple(n.target.id for n in lobe_arrays.body if isinstance(n, ast.AnnAssign)
                   and isinstance(n.target, ast.Name))
    assert fields == tuple(_core.LOBE_NAMES) == pb.Lobes._fields


# --------------------------------------------------------------------------
# (b), (c) mypy

USER_SCRIPT = '''
from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

import principled_brdf as pb
from principled_brdf import _core

m = pb.Material(base_color=(0.9, 0.6, 0.2), metallic=1.0, roughness=0.35)
wi = np.array([[0.3, 0.2, 0.9327379]], np.float32)
wo = np.array([[-0.1, 0.4, 0.9110434]], np.float32)

f: NDArray[np.float32] = pb.eval(m, wi, wo)
f_cos: NDArray[np.float32] = pb.eval(m, wi, wo, cosine=True, model="disney2012", threads=1, check=True)
soa = pb.eval(m, wi.T, wo.T, layout="soa", out=np.empty((3, 1), np.float32))
lobes: pb.Lobes = pb.eval_lobes(m, wi, wo)
specular: NDArray[np.floating[Any]] = lobes.specular
total: NDArray[np.floating[Any]] = lobes.total()
ref: NDArray[np.float64] = pb.reference.eval(m, [0.3, 0.2, 0.9327379], [0.0, 0.0, 1.0])
ref_lobes: pb.Lobes = pb.reference.eval_lobes(m, wi, wo, cosine=True)

g: pb.Gradient = pb.eval_grad(m, wi, wo, wrt=["roughness", "metallic"])
names: tuple[str, ...] = g.names
jacobian: NDArray[np.floating[Any]] = g.jacobian
g64 = pb.reference.eval_grad(m, wi, wo, wrt="base_color")

s: pb.Sample = pb.sample(m, wo, seed=7)
lobe_index: NDArray[np.int32] = s.lobe
drawn, shares = pb.sample(m, wo, seed=7, with_lobes=True)
share: NDArray[np.floating[Any]] = shares.diffuse
s_u = pb.sample(m, wo, u=np.full((1, 3), 0.5), specular_sampler="distribution")
s64: pb.Sample = pb.reference.sample(m, wo, [0.5, 0.5, 0.5])
density: NDArray[np.float32] = pb.pdf(m, wi, wo)
vp: pb.ValuePdf = pb.eval_pdf(m, wi, wo)
p64: NDArray[np.float64] = pb.reference.pdf(m, wi, wo)
chances: NDArray[np.float64] = pb.reference.lobe_probabilities(m, wo)
u: NDArray[np.float32] = pb.random_uniforms(seed=1, n=4)
a: pb.Albedo = pb.albedo(m, [0.5, 1.0], samples=64, seed=3)
albedo_total: NDArray[np.float64] = a.total
info: dict[str, Any] = pb.cpu_info()

frame: NDArray[np.float64] = pb.frames.frame_from_normal([0.0, 0.6, 0.8])
local: NDArray[np.float64] = pb.frames.to_local(wi, frame)
world: NDArray[np.float64] = pb.frames.to_world(local, frame)
theta, phi = pb.frames.direction_to_spherical(local)
direction: NDArray[np.float64] = pb.frames.spherical_to_direction(theta, phi)
theta_h, phi_h, theta_d, phi_d = pb.frames.wiwo_to_half_diff(wi, wo)

ggx_distribution: pb.microfacet.GGX = pb.microfacet.GGX(alpha_x=0.3, alpha_y=0.1)
half: NDArray[np.float64] = ggx_distribution.sample(np.full(4, 0.5), np.full(4, 0.25))
d: NDArray[np.float64] = pb.microfacet.GTR(alpha=0.2, gamma=1.5).d(half)
g1: NDArray[np.float64] = pb.microfacet.GGX(0.3).g1(half)
g2: NDArray[np.float64] = ggx_distribution.g2(half, half, correlated=False)
lam: NDArray[np.float64] = pb.microfacet.StudentT(0.3, gamma=2.5).lambda_(half)
walter: pb.microfacet.Beckmann = pb.microfacet.Beckmann(0.3, approximation="walter")
approximation: str | None = walter.approximation
alpha_x: NDArray[np.float64] = ggx_distribution.alpha_x

measured = pb.reference.eval(pb.Material(roughness=0.4), wi, wo)
result: pb.FitResult = pb.fit(wi, wo, measured, fit=["roughness"], max_iterations=3, loss="linear")
fitted: pb.Material = result.material
summary: str = result.summary()

gold: pb.Material = pb.presets.get("gold")
preset_names: list[str] = pb.presets.names()
m2: pb.Material = pb.Material(**pb.presets.parameters("car_paint"))
textured = pb.Material(roughness=np.linspace(0.1, 1.0, 6).reshape(2, 3), base_color=np.full((2, 3, 3), 0.5))
part: pb.Material = textured[0, 1:]
flat: pb.Material = textured.reshape(-1)
mixed: pb.Material = pb.Material.mix(m, m.replace(roughness=0.1), np.array([0.0, 0.5]))
roughness: NDArray[np.float64] = m.roughness
shape: tuple[int, ...] = textured.shape
linear: NDArray[np.float64] = pb.srgb_to_linear(np.array([0, 128, 255], np.uint8))
table = pb.measured.MerlBRDF(np.zeros((3, 90, 90, 180)))
from_table: NDArray[np.float64] = table.eval(wi, wo, interpolation="linear")


def save(path: str) -> None:  # (not called: it writes a file)
    pb.measured.save_merl(path, lambda wi, wo: pb.reference.eval(m, wi, wo))


lanes: int = _core.float_lanes("sse2")
ggx: NDArray[np.float64] = _core.microfacet.ggx_d(np.array([[0.0, 0.0, 1.0]]), np.array([0.3]), np.array([0.3]))

# at run time, the annotations' dtypes are the results'
assert f.dtype == np.float32 and soa.shape == (3, 1) and specular.dtype == np.float32
assert ref.dtype == np.float64 and ref_lobes.specular.dtype == np.float64 and g64.value.dtype == np.float64
assert s.wi.dtype == np.float32 and lobe_index.dtype == np.int32 and s64.wi.dtype == np.float64
assert density.dtype == np.float32 and vp.value.dtype == np.float32 and vp.pdf.dtype == np.float32
assert p64.dtype == np.float64 and chances.dtype == np.float64 and u.dtype == np.float32
assert albedo_total.dtype == np.float64 and a.lobes.diffuse.dtype == np.float64
assert direction.dtype == np.float64 and half.dtype == np.float64 and g1.dtype == np.float64
assert d.dtype == np.float64 and g2.dtype == np.float64 and lam.dtype == np.float64 and approximation == "walter"
assert fitted.is_uniform and isinstance(summary, str) and ggx.dtype == np.float64
assert part.shape == (2,) and flat.shape == (6,) and from_table.dtype == np.float64
'''

# Each line marked ``# E: code`` must be reported with that error code, and no other line.
MISTAKES_SCRIPT = '''
import numpy as np
from numpy.typing import NDArray

import principled_brdf as pb
from principled_brdf import _core

m = pb.Material(roughness=0.3)
wi = np.array([[0.0, 0.0, 1.0]], np.float32)
pb.eval(m, "0, 0, 1", wi)  # E: arg-type
pb.eval(m, wi, wi, cosinus=True)  # E: call-arg
pb.eval(m, wi, wi, model="disney2099")  # E: arg-type
f64: NDArray[np.float64] = pb.eval(m, wi, wi)  # E: assignment
pb.sample(m, wi, seed=1).shares  # E: attr-defined
pb.Material(roughnes=0.3)  # E: call-arg
pb.Material(roughness="0.3")  # E: arg-type
pb.eval_grad(m, wi, wi, wrt=3)  # E: arg-type
pb.microfacet.GGX(alpha_x="0.3")  # E: arg-type
pb.microfacet.GTR(0.2, 1.5).lambda_(wi)  # E: attr-defined
pb.microfacet.GGX(0.3).g2(wi, wi, True)  # E: call-arg
pb.reference.sample(m, wi)  # E: call-arg

_core.reference_eval(wi, wi, wi, 0)  # E: call-arg
_core.microfacet.ggx_d(wi, 0.3)  # E: call-arg
_core.SampleOptions(seed=1, threads=0, isa=None)  # E: arg-type
options = _core.EvalOptions()
_core.batch_pdf(wi=wi, wi_layout=0, wo=wi, wo_layout=0, params=[], pdf=wi, n=1, options=options)  # E: arg-type
'''


def _mypy_config(cache_dir: Path) -> str:
    return textwrap.dedent(f"""\
        [mypy]
        strict = True
        cache_dir = {cache_dir}
        show_error_codes = True
        hide_error_context = True
        no_error_summary = True

        [mypy-principled_brdf.*]
        # numpy's functions return Any; the package's own results are annotated
        warn_return_any = False

        [mypy-scipy.*]
        ignore_missing_imports = True

        # optional dependencies without type information: ipywidgets, OpenEXR (compiled, no stubs)
        [mypy-ipywidgets.*,OpenEXR.*]
        ignore_missing_imports = True
        """)


@pytest.fixture(scope="module")
def mypy(request, tmp_path_factory):
    import mypy  # noqa: F401 - a test dependency (scripts/install-deps.sh): missing, the tests fail, not skip
    cache = getattr(request.config, "cache", None)  # None with -p no:cacheprovider
    cache_dir = cache.mkdir("mypy") if cache is not None else tmp_path_factory.mktemp("mypy_cache")
    work = tmp_path_factory.mktemp("typing")
    (work / "mypy.ini").write_text(_mypy_config(cache_dir))

    def run(*arguments: str) -> tuple[int, list[str]]:
        done = subprocess.run([sys.executable, "-m", "mypy", "--config-file", "mypy.ini", *arguments], cwd=work,
                              capture_output=True, text=True, timeout=600)
        assert "error: Cannot find implementation or library stub" not in done.stdout, done.stdout
        lines = [line for line in done.stdout.splitlines() if line.strip()]
        return done.returncode, lines

    run.work = work
    return run


def test_mypy_checks_the_package_itself(mypy):
    """mypy --strict (without warn_return_any) on the installed package, every module."""
    returncode, lines = mypy("-p", "principled_brdf")
    assert returncode == 0 and lines == [], "\n".join(lines)


def test_a_typical_user_script_type_checks_under_strict(mypy):
    (mypy.work / "user_script.py").write_text(USER_SCRIPT)
    returncode, lines = mypy("user_script.py")
    assert returncode == 0 and lines == [], "\n".join(lines)
    exec(compile(USER_SCRIPT, "user_script.py", "exec"), {"__name__": "user_script"})  # and it runs


def test_mypy_catches_mistakes_in_a_user_script(mypy):
    (mypy.work / "mistakes.py").write_text(MISTAKES_SCRIPT)
    returncode, lines = mypy("mistakes.py")
    expected = {number: line.rsplit("# E: ", 1)[1] for number, line in enumerate(MISTAKES_SCRIPT.splitlines(), 1)
                if "# E: " in line}
    reported: dict[int, set[str]] = {}
    for line in lines:
        if re.match(r"mistakes\.py:\d+: note: ", line):
            continue
        match = re.match(r"mistakes\.py:(\d+): error: .*\[([a-z-]+)\]$", line)
        assert match, f"unexpected mypy output: {line}"
        reported.setdefault(int(match.group(1)), set()).add(match.group(2))
    assert returncode == 1
    assert {number: {code} for number, code in expected.items()} == reported, "\n".join(lines)
