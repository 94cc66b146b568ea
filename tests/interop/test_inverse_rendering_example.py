"""examples/inverse_rendering.py: a roughness and a base_color texture recovered
from rendered observations with PyTorch's Adam and with JAX, through the kernels."""

from __future__ import annotations

import importlib.util
import pathlib

import pytest

EXAMPLE = pathlib.Path(__file__).parents[2] / "examples" / "inverse_rendering.py"


@pytest.fixture(scope="module")
def example():
    spec = importlib.util.spec_from_file_location("inverse_rendering", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("framework", ["torch", "jax"])
def test_the_textures_are_recovered(example, framework):
    pytest.importorskip(framework)
    problem = example.problem(size=10, pairs=24, seed=3)
    recover = {"torch": example.recover_torch, "jax": example.recover_jax}[framework]
    roughness_error, color_error = example.errors(problem, *recover(problem, steps=300))
    assert roughness_error < 1e-3 and color_error < 1e-3
