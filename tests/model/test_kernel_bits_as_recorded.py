"""The kernels' bits on fixed inputs are those recorded in kernel_bits.json
(scripts/kernel_bits.py): a change meant to leave every output unchanged
(a refactoring of the model, the layout of its parts) is proven so on every
instruction set the machine has. A change that is meant to move bits
records them anew, and says why in its commit."""

import importlib.util
import json
from pathlib import Path

import pytest

import principled_brdf as pb

ROOT = Path(__file__).resolve().parents[2]
RECORDED = json.loads((Path(__file__).resolve().parents[1] / "kernel_bits.json").read_text())


def kernel_bits_module():
    spec = importlib.util.spec_from_file_location("kernel_bits", ROOT / "scripts" / "kernel_bits.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("isa", pb.cpu_info()["available"])
def test_kernel_outputs_have_the_recorded_bits(isa):
    if isa not in RECORDED:
        pytest.fail(f"no bits recorded for {isa}: run scripts/kernel_bits.py on a machine that has it")
    bits = kernel_bits_module().kernel_bits(isa)
    changed = sorted(key for key in RECORDED[isa] if bits.get(key) != RECORDED[isa][key])
    assert not changed, f"{isa}: outputs whose bits changed: {changed}"
    assert set(bits) == set(RECORDED[isa])
