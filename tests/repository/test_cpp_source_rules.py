"""Rules of the C++ sources that no output shows but the kernels' speed depends on."""

import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

# The model and everything the SIMD loops inline.
MODEL_AND_KERNELS = sorted(
    [*ROOT.glob("cpp/include/principled_brdf/model/*.hpp"), *ROOT.glob("cpp/src/kernel*.hpp"),
     ROOT / "cpp/src/simd_ops.hpp", ROOT / "cpp/src/counter_rng.hpp"])

# `const Type name = ...`, `const Type name(...)` or `const Type name{...}` as a
# statement: a local (or member) value of a class type, not a reference.
CONST_VALUE = re.compile(r"^\s+const (?!std::)([A-Z]\w*(?:<[^;&()=]*?>)?) (\w+)\s*(=|\(|\{)")


def test_the_sources_are_found():
    assert len(MODEL_AND_KERNELS) >= 15
    assert all(path.is_file() for path in MODEL_AND_KERNELS)


def test_no_const_values_in_the_model_and_the_kernels():
    """GCC 12 does not break a const aggregate built in place by an inlined call
    into registers (docs/model.md, "No const locals"): each one is memory
    traffic in the loops."""
    found = [f"{path.relative_to(ROOT)}:{number}: {line.strip()}"
             for path in MODEL_AND_KERNELS
             for number, line in enumerate(path.read_text().splitlines(), 1)
             if CONST_VALUE.match(line)]
    assert not found, "const locals:\n" + "\n".join(found)


def test_the_rule_sees_what_it_forbids():
    for line in ["    const Geometry<F> g = geometry_of(wi, wo);", "        const F one(1.0), zero(0.0);",
                 "    const Floats x{y};", "    const MaskOf<F> above = g.wi.z > F(0.0);"]:
        assert CONST_VALUE.match(line), line
    for line in ["    const Shading<Floats>& s = material.shading;", "    const std::int64_t n = 3;",
                 "PB_MODEL_INLINE Shading<F> shading_of(const F* p) {", "    const float x = 1.0f;"]:
        assert not CONST_VALUE.match(line), line


def test_the_model_twice_in_one_translation_unit_is_a_compile_error(tmp_path):
    """The model's files are `#pragma once`, which holds per translation unit:
    a second namespace including the model would get none of it. model.hpp
    turns that into an #error; the preprocessor alone shows it."""
    compiler = shutil.which("g++") or shutil.which("c++")
    if compiler is None:
        pytest.skip("no C++ compiler")

    def preprocess(source: str) -> subprocess.CompletedProcess:
        path = tmp_path / "tu.cpp"
        path.write_text(source)
        return subprocess.run([compiler, "-std=c++17", "-E", "-I", str(ROOT / "cpp/include"), "-I", str(ROOT / "cpp/src"),
                               str(path), "-o", str(tmp_path / "tu.ii")], capture_output=True, text=True, timeout=60)

    kernel = "#define PRINCIPLED_BRDF_ARCH xsimd::sse2\n#define PRINCIPLED_BRDF_ARCH_NS sse2\n#include \"kernel.hpp\"\n"
    if preprocess(kernel).returncode != 0:
        pytest.skip("kernel.hpp does not preprocess here (xsimd missing)")
    for source in ('#include "principled_brdf/model/f64.hpp"\n' + kernel,
                   kernel + '#include "principled_brdf/model/f64_family.hpp"\n',
                   '#include "principled_brdf/model/f64.hpp"\nnamespace other {\n'
                   '#include "principled_brdf/model/model.hpp"\n}\n'):
        result = preprocess(source)
        assert result.returncode != 0, source
        assert "is included a second time in this translation unit" in result.stderr, result.stderr
    family_twice = preprocess('#include "principled_brdf/model/f64_family.hpp"\nnamespace other {\n'
                              '#include "principled_brdf/model/distribution_family.hpp"\n}\n')
    assert family_twice.returncode != 0
    assert "distribution_family.hpp is already included in this translation unit" in family_twice.stderr
    once = '#include "principled_brdf/model/f64.hpp"\n#include "principled_brdf/model/f64_family.hpp"\n'
    assert preprocess(once + once).returncode == 0
