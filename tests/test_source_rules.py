"""Rules of the C++ sources that no output shows but the kernels' speed depends on."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

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
