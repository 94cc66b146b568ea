"""The README's Python blocks run as written, in order, in one namespace (as a
reader pastes them into a notebook), in a temporary folder, and the outputs it
shows are what they print (tests/test_docs.py runs docs/*.md the same way)."""

import pathlib

import numpy as np

from test_pages_run_and_links_resolve import page_sandbox, python_blocks, run_blocks  # noqa: F401 - page_sandbox is a fixture

README = pathlib.Path(__file__).resolve().parents[2] / "README.md"


def test_there_are_python_blocks():
    assert len(python_blocks(README)) >= 1


def test_every_python_block_runs_as_written(page_sandbox):
    namespace = run_blocks(python_blocks(README), "README.md")
    import principled_brdf as pb

    # what the tour shows, rounded so that every instruction set prints it
    m, wi, wo = namespace["m"], namespace["wi"], namespace["wo"]
    np.testing.assert_array_equal(np.round(pb.eval(m, wi, wo), 4), np.float32([[0.0896, 0.0598, 0.0199]]))
    for isa in pb.cpu_info()["available"]:
        np.testing.assert_allclose(pb.eval(m, wi, wo, isa=isa), [[0.0896414, 0.05976094, 0.01992031]], rtol=1e-6)
    assert set(pb.cpu_info()) == {"isa", "float_lanes", "available", "threads"}
