"""The kernels' bits do not depend on the CPU's vendor: no instruction whose
result is implementation-defined appears in the compiled extension. x86's
rcpps/rsqrtps (and their scalar and VEX forms) return estimates that differ
between Intel and AMD, so a value refined from one would round by vendor;
AVX-512's rcp14/rsqrt14 are specified bit for bit and allowed. Together with
the recorded bits (test_kernel_bits_as_recorded.py) this is the proof of
"the same bits on every CPU with the same instruction set"."""

import platform
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from principled_brdf import _core

# the mnemonic as objdump prints it: rcpps, vrcpps, rsqrtss, vrsqrtps, ... (not rcp14ps, rsqrt14ps)
ESTIMATE = re.compile(r"\s(v?(?:rcp|rsqrt)(?:ps|ss))\s")


def disassembly() -> str:
    objdump = shutil.which("objdump")
    assert objdump, "objdump (Debian's binutils, installed with g++) is needed to read the extension"
    return subprocess.run([objdump, "-d", "--no-show-raw-insn", Path(_core.__file__)], check=True,
                          capture_output=True, text=True).stdout


@pytest.mark.skipif(platform.machine() not in ("x86_64", "AMD64"), reason="x86's estimate instructions")
def test_no_implementation_defined_estimate_in_the_extension():
    text = disassembly()
    assert "vfmadd" in text and "vdivps" in text, "the disassembly should show the kernels"
    found = sorted({match.group(1) for match in ESTIMATE.finditer(text)})
    assert not found, f"implementation-defined estimate instructions in {_core.__file__}: {found}"


def test_the_pattern_sees_what_it_forbids():
    for line in ["  4011a0:\tvrsqrtps %ymm0,%ymm1\n", "  4011a0:\trcpss  %xmm0,%xmm1\n",
                 "  4011a0:\tvrcpps %ymm2,%ymm3\n", "  4011a0:\trsqrtps %xmm0,%xmm1\n"]:
        assert ESTIMATE.search(line), line
    for line in ["  4011a0:\tvrsqrt14ps %zmm0,%zmm1\n", "  4011a0:\tvrcp14ps %zmm0,%zmm1\n",
                 "  4011a0:\tvdivps %ymm0,%ymm1,%ymm2\n"]:
        assert not ESTIMATE.search(line), line
