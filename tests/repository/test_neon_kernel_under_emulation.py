"""The NEON kernel against the float64 reference (docs/validation.md, "On ARM"):
scripts/check-neon.sh (what `make check-neon` runs) cross-compiles
cpp/check/neon_check.cpp with the kernels for aarch64 and runs it under qemu's
user-mode emulation; every check it prints must pass, and it must have run
checks of every model (a check that found nothing to check would pass too)."""

import os
import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
MODELS = ("disney2012", "disney2014", "disney2015", "disney2015_thin")


def test_neon_kernel_holds_to_the_reference_under_emulation():
    result = subprocess.run(["bash", str(ROOT / "scripts" / "check-neon.sh")], cwd=ROOT, capture_output=True,
                            text=True, timeout=3600, check=False, env={**os.environ})
    output = result.stdout + result.stderr
    failures = [line for line in output.splitlines() if line.startswith("FAIL")]
    summary = re.search(r"^(\d+) passed, (\d+) failed$", result.stdout, re.MULTILINE)
    assert result.returncode == 0 and not failures, "\n".join(failures) or output[-4000:]
    assert summary is not None and int(summary.group(2)) == 0, output[-4000:]
    assert int(summary.group(1)) > 300, summary.group(0)
    for model in MODELS:
        assert re.search(rf"^ok\s+{model}\b", result.stdout, re.MULTILINE), f"no check of {model} ran"
    assert "(active neon" in result.stdout, result.stdout[:400]
