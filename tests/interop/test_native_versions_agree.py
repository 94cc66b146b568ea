"""The native PyTorch and JAX versions of the model that bench/interop_speed.py
times (bench/native_torch.py, bench/native_jax.py) compute the library's f and
derivatives: values against pb.reference.eval, jax.jacfwd's Jacobian and both
backward passes against pb.reference.eval_grad (bench/native_check.py)."""

from __future__ import annotations

import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "bench"))

import native_check  # noqa: E402


def test_native_torch_agrees_with_the_reference():
    native_check.check_torch(seed=11, n=256)


def test_native_jax_agrees_with_the_reference():
    native_check.check_jax(seed=11, n=256)
