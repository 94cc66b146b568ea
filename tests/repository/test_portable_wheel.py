"""The portable wheel (`make wheel`, docs/installing.md, "A portable wheel"): scripts/build-wheel.sh
builds it, auditwheel gives it a manylinux tag, its baseline code uses no
instruction beyond x86-64's SSE2 outside the AVX2/AVX-512 kernels, and a fresh
virtual environment that installs it (and numpy from PyPI, nothing else) imports
it from the venv, not this checkout, and evaluates the model on every
instruction set this CPU runs.

The build reuses scikit-build-core's build tree build/{wheel_tag}, so after
`make test`'s own build it only relinks what changed."""

from __future__ import annotations

import bisect
import collections
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest

import principled_brdf as pb

ROOT = Path(__file__).resolve().parents[2]
DIST = ROOT / "dist"
RAW = ROOT / "build" / "wheel-raw"  # scripts/build-wheel.sh's wheel before auditwheel
PY_TAG = f"cp{sys.version_info.major}{sys.version_info.minor}"


def run(command, timeout=900, **kwargs):
    result = subprocess.run(command, capture_output=True, text=True, timeout=timeout, check=False, **kwargs)
    assert result.returncode == 0, (f"{' '.join(map(str, command))} exited with {result.returncode}\n"
                                    f"stdout:\n{result.stdout[-4000:]}\nstderr:\n{result.stderr[-4000:]}")
    return result.stdout


@pytest.fixture(scope="module")
def wheel() -> Path:
    """scripts/build-wheel.sh (what `make wheel` runs) for this interpreter: the repaired wheel in dist/."""
    for tool in ("objdump", "readelf", "ar"):
        assert shutil.which(tool), f"{tool} (binutils) is needed to check the wheel's instructions"
    for module in ("auditwheel", "scikit_build_core", "pybind11"):
        assert subprocess.run([sys.executable, "-c", f"import {module}"], check=False).returncode == 0, \
            f"{module} is not installed for {sys.executable}: run `make deps` (scripts/install-deps.sh)"
    start = time.time()
    run(["bash", str(ROOT / "scripts" / "build-wheel.sh")], cwd=ROOT, env={**os.environ, "PYTHON": sys.executable})
    wheels = sorted(DIST.glob(f"principled_brdf-{pb.__version__}-{PY_TAG}-{PY_TAG}-*.whl"))
    assert len(wheels) == 1, f"expected one wheel for {PY_TAG} in {DIST}, found {wheels}"
    assert wheels[0].stat().st_mtime >= start - 1, f"{wheels[0]} was not written by this build"
    return wheels[0]


def test_the_wheel_is_manylinux_and_grafts_nothing(wheel):
    match = re.fullmatch(rf"principled_brdf-[^-]+-{PY_TAG}-{PY_TAG}-(manylinux_2_(\d+)_(\w+))\.whl", wheel.name)
    assert match, f"{wheel.name} has no manylinux tag"
    plat, _, machine = match.groups()
    assert machine == platform.machine()
    shown = " ".join(run([sys.executable, "-m", "auditwheel", "show", str(wheel)]).split())
    assert f'consistent with the following platform tag: "{plat}"' in shown, shown
    with zipfile.ZipFile(wheel) as z:
        names = z.namelist()
    assert not [n for n in names if ".libs/" in n], f"auditwheel grafted libraries: {names}"
    assert [n for n in names if re.fullmatch(r"principled_brdf/_core\..*\.so", n)], names
    assert "principled_brdf/__init__.py" in names and "principled_brdf/__main__.py" in names


# Instructions beyond the x86-64 baseline (SSE2): VEX/EVEX (AVX, AVX2, FMA, AVX-512: every
# mnemonic starting with v, ymm/zmm and mask registers), SSE3 to SSE4.2, POPCNT/LZCNT, BMI1/2, MOVBE.
BEYOND_BASELINE = re.compile(
    r"^(?:(?:lock|rep[a-z]*|notrack|bnd|data16|addr32|[c-gs]s|\{[a-z0-9]+\}) )*"
    r"(v[a-z0-9]+|lddqu|movddup|movs[hl]dup|h(add|sub)p[sd]|addsubp[sd]|pshufb|palignr|ph(add|sub)[a-z]*"
    r"|pabs[bwd]|psign[bwd]|pmaddubsw|pmulhrsw|ptest|pblend[a-z]*|blendv?p[sd]|round[ps][sd]|dpp[sd]|insertps"
    r"|extractps|pextr[bdq]|pinsr[bdq]|pm(in|ax)(sb|sd|uw|ud)|pmov[sz]x[a-z]*|pmulld|pmuldq|packusdw"
    r"|pcmp(eq|gt)q|pcmp[ei]str[im]|crc32[a-z]*|popcnt|lzcnt|tzcnt|andn|bextr|blsi|blsmsk|blsr|bzhi|pdep|pext"
    r"|rorx|sarx|shlx|shrx|mulx|movbe)\b|%[yz]mm\d|%k[0-7]\b")
INSTRUCTION = re.compile(r"^\s*([0-9a-f]+):\t(.*)$")


def beyond_baseline(instruction: str) -> bool:
    return bool(BEYOND_BASELINE.search(instruction))


def object_functions_beyond_baseline(obj: Path) -> collections.Counter:
    """Sizes of the functions of an object file that use instructions beyond the baseline."""
    flagged, current = set(), None
    for line in run(["objdump", "-d", "--no-show-raw-insn", str(obj)]).splitlines():
        label = re.match(r"^[0-9a-f]+ <(.+)>:$", line)
        if label:
            current = label.group(1)
            continue
        instruction = INSTRUCTION.match(line)
        if instruction and current and beyond_baseline(instruction.group(2)):
            flagged.add(current)
    sizes = {}
    for line in run(["nm", "-P", "-S", "--defined-only", str(obj)]).splitlines():
        fields = line.split()
        if len(fields) >= 4:
            sizes[fields[0]] = int(fields[3], 16)
    assert flagged <= set(sizes), f"{obj.name}: no size for {sorted(flagged - set(sizes))[:5]}"
    return collections.Counter(sizes[name] for name in flagged)


def library_functions_beyond_baseline(so: Path) -> tuple[collections.Counter, int, int]:
    """For a stripped shared object: the sizes of the functions (address ranges from the
    unwind tables) that use instructions beyond the baseline, how many such
    instructions lie outside every function, and how many functions there are."""
    ranges = sorted((int(a, 16), int(b, 16)) for a, b in re.findall(
        r"FDE cie=\w+ pc=([0-9a-f]+)\.\.([0-9a-f]+)", run(["readelf", "--debug-dump=frames", str(so)])))
    starts = [a for a, _ in ranges]
    flagged, outside = set(), 0
    for line in run(["objdump", "-d", "--no-show-raw-insn", str(so)]).splitlines():
        instruction = INSTRUCTION.match(line)
        if instruction and beyond_baseline(instruction.group(2)):
            address = int(instruction.group(1), 16)
            i = bisect.bisect_right(starts, address) - 1
            if i >= 0 and address < ranges[i][1]:
                flagged.add(ranges[i])
            else:
                outside += 1
    return collections.Counter(b - a for a, b in flagged), outside, len(ranges)


def test_only_the_avx_kernels_use_instructions_beyond_sse2(wheel, tmp_path):
    """The module is linked from CMake's per-ISA kernel objects (not LTO) and the bindings
    (LTO, compiled at link time): every function of the wheel's module that uses an
    instruction beyond SSE2 has the size of a distinct function of the AVX2/AVX-512
    kernel objects, and the baseline objects (batch, dispatch, thread pool, SSE2 kernel)
    use none, so nothing a pre-AVX CPU runs before the dispatch (or instead of it) needs AVX."""
    if platform.machine() != "x86_64":
        pytest.skip(f"the instruction check is for x86-64 (this is {platform.machine()})")
    with zipfile.ZipFile(wheel) as z:
        so_name = next(n for n in z.namelist() if re.fullmatch(r"principled_brdf/_core\..*\.so", n))
        so = Path(z.extract(so_name, tmp_path / "wheel"))
    raw = sorted(RAW.glob(f"principled_brdf-*-{PY_TAG}-{PY_TAG}-*.whl"))
    assert len(raw) == 1, f"expected build-wheel.sh's unrepaired wheel in {RAW}, found {raw}"
    tag = raw[0].name[:-len(".whl")].split("-", 2)[2]  # scikit-build-core's {wheel_tag}
    archive = ROOT / "build" / tag / "libprincipled_brdf_kernels.a"
    assert archive.is_file(), f"{archive}: the kernels' static library of this build is missing"
    objects = tmp_path / "objects"
    objects.mkdir()
    run(["ar", "x", str(archive)], cwd=objects)
    members = sorted(objects.glob("*.o"))
    kernels = [o for o in members if o.name.startswith(("kernel_avx2_", "kernel_avx512_"))]  # (their parts)
    assert [o.name for o in kernels if o.name.startswith("kernel_avx2_")], [o.name for o in members]
    for obj in members:
        if obj not in kernels:
            assert not object_functions_beyond_baseline(obj), f"{obj.name} uses instructions beyond SSE2"
    kernel_sizes = collections.Counter()
    for obj in kernels:
        sizes = object_functions_beyond_baseline(obj)
        assert sizes, f"{obj.name}: no AVX instruction found: the check would not see one"
        kernel_sizes += sizes
    so_sizes, outside, functions = library_functions_beyond_baseline(so)
    assert functions > 100 and outside == 0, (functions, outside)
    unexplained = so_sizes - kernel_sizes
    assert not unexplained, (f"{sum(unexplained.values())} functions of {so_name} use instructions beyond SSE2 "
                             f"and are not AVX kernel functions (sizes {sorted(unexplained)[:10]}): "
                             "a global -march/-mavx flag, or an inline function shared with a kernel file?")
    assert sum(so_sizes.values()) >= sum(kernel_sizes.values()) // 2  # the kernels are linked in


VENV_SCRIPT = """
import json, sys
import numpy as np
import principled_brdf as pb
wi, wo = np.load("wi.npy"), np.load("wo.npy")
materials = [pb.Material(), pb.Material(base_color=(0.9, 0.6, 0.2), metallic=1.0, roughness=0.35,
                                        anisotropic=0.5, clearcoat=1.0, sheen=0.5)]
info = pb.cpu_info()
print(json.dumps({
    "file": pb.__file__, "numpy": np.__file__, "prefix": sys.prefix, "info": info,
    "eval": {isa: [pb.eval(m, wi, wo, isa=isa).tolist() for m in materials] for isa in info["available"]},
    "reference": [pb.reference.eval(m, wi, wo).tolist() for m in materials],
    "sample": {isa: [[s.wi.tolist(), s.pdf.tolist(), s.weight.tolist()]
                     for s in (pb.sample(m, wo, seed=5, isa=isa) for m in materials)] for isa in info["available"]},
}))
"""


def test_a_fresh_venv_runs_the_wheel(wheel, tmp_path):
    venv = tmp_path / "venv"
    # Without its own pip (ensurepip takes longer than the rest): this process's pip installs into it.
    run([sys.executable, "-m", "venv", "--without-pip", str(venv)])
    python = venv / "bin" / "python"
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV", "PYTHONSTARTUP", "PRINCIPLED_BRDF_ISA")}
    env["PYTHONNOUSERSITE"] = "1"
    pip = [sys.executable, "-m", "pip", "--python", str(python), "--disable-pip-version-check"]
    assert subprocess.run([*pip, "--version"], capture_output=True, cwd=tmp_path, env=env, check=False).returncode == 0, \
        f"the pip of {sys.executable} is too old for --python (22.3 or later is needed)"
    run([*pip, "install", "-q", "--no-compile", str(wheel)], cwd=tmp_path, env=env)  # numpy from the index
    installed = {p["name"].lower() for p in json.loads(run([*pip, "list", "--format=json"], cwd=tmp_path, env=env))}
    assert installed - {"pip", "setuptools", "wheel"} == {"numpy", "principled-brdf"}, installed

    rng = np.random.default_rng(20240517)
    def directions(n):
        w = rng.normal(size=(n, 3))
        w[:, 2] = np.abs(w[:, 2]) + 0.05
        return (w / np.linalg.norm(w, axis=1, keepdims=True)).astype(np.float32)
    wi, wo = directions(64), directions(64)
    np.save(tmp_path / "wi.npy", wi)
    np.save(tmp_path / "wo.npy", wo)
    out = json.loads(run([str(python), "-c", VENV_SCRIPT], cwd=tmp_path, env=env))
    venv_root = venv.resolve()
    for key in ("file", "numpy"):
        assert Path(out[key]).resolve().is_relative_to(venv_root), f"{key} imported from {out[key]}, not the venv"
    assert not Path(out["file"]).resolve().is_relative_to(ROOT)
    assert out["info"]["available"] == pb.cpu_info()["available"]

    materials = [pb.Material(), pb.Material(base_color=(0.9, 0.6, 0.2), metallic=1.0, roughness=0.35,
                                            anisotropic=0.5, clearcoat=1.0, sheen=0.5)]
    expected = [pb.reference.eval(m, wi, wo) for m in materials]  # float64, by this process's package
    assert all(np.all(e > 0) and np.all(np.isfinite(e)) for e in expected)
    np.testing.assert_allclose(np.array(out["reference"]), np.array(expected), rtol=1e-9)
    for isa, values in out["eval"].items():
        np.testing.assert_allclose(np.array(values), np.array(expected), rtol=1e-4, atol=1e-7, err_msg=isa)
    for isa, draws in out["sample"].items():  # each draw's pdf and weight as this process's reference has them
        for m, (drawn, pdf, weight) in zip(materials, draws):
            drawn, pdf, weight = np.array(drawn), np.array(pdf), np.array(weight)
            valid = pdf > 0
            assert valid.mean() > 0.9 and np.isfinite(weight).all(), isa
            np.testing.assert_allclose(pdf[valid], pb.reference.pdf(m, drawn[valid], wo[valid]), rtol=1e-3, err_msg=isa)
            f = pb.reference.eval(m, drawn[valid], wo[valid], cosine=True)
            np.testing.assert_allclose(weight[valid], f / pdf[valid, None], rtol=2e-3, atol=1e-7, err_msg=isa)

    info = run([str(python), "-m", "principled_brdf", "info"], cwd=tmp_path, env=env)
    assert f"principled-brdf {pb.__version__}" in info, info
    assert f"instruction set: {out['info']['isa']}" in info, info
    assert "available: " + ", ".join(out["info"]["available"]) in info, info
    forced = run([str(python), "-m", "principled_brdf", "info"], cwd=tmp_path,
                 env={**env, "PRINCIPLED_BRDF_ISA": "sse2"})
    assert "instruction set: sse2" in forced, forced
    # the instruction set forced lower for the whole process (the dispatch override): its default is then SSE2
    lowered = json.loads(run([str(python), "-c", VENV_SCRIPT], cwd=tmp_path, env={**env, "PRINCIPLED_BRDF_ISA": "sse2"}))
    assert lowered["info"]["isa"] == "sse2"
    np.testing.assert_array_equal(np.array(lowered["eval"]["sse2"]), np.array(out["eval"]["sse2"]))
