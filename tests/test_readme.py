"""The README's Python blocks run as written, in order, in one namespace (as a
reader pastes them into a notebook), and the outputs it prints are what they print."""

import os
import re

import numpy as np
import pytest

README = os.path.join(os.path.dirname(__file__), "..", "README.md")
EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "examples")


def python_blocks() -> list:
    with open(README, encoding="utf-8") as f:
        return re.findall(r"```python\n(.*?)```", f.read(), re.S)


def test_there_are_python_blocks():
    assert len(python_blocks()) >= 5


def test_every_python_block_runs_as_written(monkeypatch, tmp_path):
    pytest.importorskip("matplotlib")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    monkeypatch.syspath_prepend(EXAMPLES)  # the dask block imports examples/dask_scale_out.py
    monkeypatch.chdir(tmp_path)
    namespace = {}
    for i, block in enumerate(python_blocks()):
        try:
            exec(compile(block, f"README python block {i}", "exec"), namespace)
        except Exception as error:  # noqa: BLE001 - report which block failed
            raise AssertionError(f"README python block {i} fails: {error!r}\n{block}") from error
    import principled_brdf as pb

    # what the tour prints
    m = namespace["m"]
    shown = re.sub(r"\s+", " ", "Material(base_color=(0.9, 0.6, 0.2), metallic=1, subsurface=0, specular=0.5, "
                   "specular_tint=0, roughness=0.35, anisotropic=0, sheen=0, sheen_tint=0.5, clearcoat=0, "
                   "clearcoat_gloss=1)")
    assert re.sub(r"\s+", " ", repr(m)) == shown
    f = pb.eval(m, np.array([[0.3, 0.2, 0.9327379]], np.float32), np.array([[-0.1, 0.4, 0.9110434]], np.float32))
    np.testing.assert_allclose(f, [[0.0896414, 0.05976094, 0.01992031]], rtol=1e-6)
    assert set(pb.cpu_info()) == {"isa", "float_lanes", "available", "threads"}
