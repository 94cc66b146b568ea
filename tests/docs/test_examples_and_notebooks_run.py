"""The examples run: the notebooks execute without a cell error and draw their figures, and
the dask example gives pb.eval's bits and runs as a script.

The notebooks are executed with nbclient in a scratch directory (nothing lands in the
repository) by a kernel running *this* interpreter: a ``python3`` kernelspec pointing at
``sys.executable`` is written to a temporary Jupyter data directory that is searched first,
so a machine with only ``pip install ipykernel nbclient nbformat`` works, and a ``python3``
kernel registered elsewhere for another Python is not picked by mistake. The kernel runs
with ``MPLBACKEND=Agg``, so a notebook records its figures only if it selects the inline
backend itself (``%matplotlib inline``), as it must to show them wherever it is run.

The notebooks are stored with the outputs of one complete run (so that they read on a
repository page): every code cell executed once, in order, without an error, and the file
small enough to keep in git.
"""

from __future__ import annotations

import importlib.util
import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import principled_brdf as pb

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
NOTEBOOKS = ("tour.ipynb", "validation.ipynb", "fitting.ipynb")
CELL_TIMEOUT = 300  # seconds per cell
MAX_NOTEBOOK_BYTES = 1_500_000  # stored with outputs: figures at dpi 80-100 stay well below
# a code cell that makes a figure (matplotlib's constructors or a pb.plot picture) must show one
PLOTTING = re.compile(r"\bplt\.(subplots|subplot|figure|subplot_mosaic)\(|\bpb\.plot\.("
                      + "|".join(name for name in pb.plot.__all__
                                 if callable(getattr(pb.plot, name)) and name != "slice_directions")
                      + r")\(")


# --------------------------------------------------------------------------
# notebooks


@pytest.fixture(scope="module")
def python3_kernel(tmp_path_factory):
    """A Jupyter path whose ``python3`` kernel runs this interpreter; returns the kernel name."""
    import ipykernel  # noqa: F401  (a test dependency: fail, never skip)
    data_dir = tmp_path_factory.mktemp("jupyter")
    spec_dir = data_dir / "kernels" / "python3"
    spec_dir.mkdir(parents=True)
    spec = {
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "Python 3 (tests)",
        "language": "python",
        "metadata": {"debugger": False},
    }
    (spec_dir / "kernel.json").write_text(json.dumps(spec))
    with pytest.MonkeyPatch.context() as patch:
        # JUPYTER_PATH comes first in the kernelspec search; the kernel inherits the environment
        patch.setenv("JUPYTER_PATH", os.pathsep.join(filter(None, [str(data_dir), os.environ.get("JUPYTER_PATH")])))
        patch.setenv("PYDEVD_DISABLE_FILE_VALIDATION", "1")
        patch.setenv("MPLBACKEND", "Agg")  # figures must not depend on the caller's backend
        yield "python3"


def _images(cell) -> int:
    return sum("image/png" in output.get("data", {}) for output in cell.get("outputs", []))


def _check_figures(name, notebook) -> None:
    """At least 4 images, and one from every code cell that makes a figure."""
    code = [(k, cell) for k, cell in enumerate(notebook.cells) if cell.cell_type == "code"]
    assert sum(_images(cell) for _, cell in code) >= 4, f"{name}: expected figures"
    blank = [k for k, cell in code if PLOTTING.search(cell.source) and not _images(cell)]
    assert not blank, f"{name}: cells {blank} make a figure but show no image (plt.show(), or %matplotlib inline)"


@pytest.mark.parametrize("name", NOTEBOOKS)
def test_notebook_is_stored_with_the_outputs_of_one_run(name):
    import nbformat
    path = EXAMPLES / name
    size = path.stat().st_size
    assert size <= MAX_NOTEBOOK_BYTES, f"{name}: {size:,} bytes; lower the figures' dpi or size"
    notebook = nbformat.read(path, as_version=4)
    code = [cell for cell in notebook.cells if cell.cell_type == "code"]
    counts = [cell.get("execution_count") for cell in code]
    assert counts == list(range(1, len(code) + 1)), \
        f"{name}: execution counts {counts}: store it executed once from the top (Restart & Run All)"
    errors = [output for cell in code for output in cell.get("outputs", []) if output.output_type == "error"]
    assert not errors, f"{name}: stored with an error: {errors[0].get('ename')}: {errors[0].get('evalue')}"
    _check_figures(name, notebook)


@pytest.mark.parametrize("name", NOTEBOOKS)
def test_notebook_runs(name, python3_kernel, tmp_path):
    import nbformat
    import nbclient
    import matplotlib  # noqa: F401  (a test dependency: fail, never skip)
    import scipy  # noqa: F401  (a test dependency: fail, never skip)
    from jupyter_client.kernelspec import KernelSpecManager

    spec = KernelSpecManager().get_kernel_spec(python3_kernel)
    assert spec.argv[0] == sys.executable, f"the python3 kernelspec found is {spec.resource_dir}"

    notebook = nbformat.read(EXAMPLES / name, as_version=4)
    assert notebook.metadata.kernelspec.name == "python3"
    for cell in notebook.cells:  # the stored outputs are replaced, not added to
        if cell.cell_type == "code":
            cell.outputs, cell.execution_count = [], None
    client = nbclient.NotebookClient(notebook, timeout=CELL_TIMEOUT, kernel_name=python3_kernel,
                                     resources={"metadata": {"path": str(tmp_path)}})
    start = time.perf_counter()
    client.execute()  # raises CellExecutionError (with the traceback) on a cell error
    seconds = time.perf_counter() - start
    print(f"{name}: {seconds:.1f} s")

    for cell in notebook.cells:
        for output in cell.get("outputs", []):
            assert output.output_type != "error", f"{name}: {output.get('ename')}: {output.get('evalue')}"
    _check_figures(name, notebook)


# --------------------------------------------------------------------------
# dask


def _load_dask_example():
    import dask.array  # noqa: F401  (a test dependency: fail, never skip)
    spec = importlib.util.spec_from_file_location("dask_scale_out", EXAMPLES / "dask_scale_out.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _hemisphere(rng, n):
    cos_theta, phi = rng.random(n), 2 * np.pi * rng.random(n)
    sin_theta = np.sqrt(1 - cos_theta**2)
    return np.stack([sin_theta * np.cos(phi), sin_theta * np.sin(phi), cos_theta], axis=-1).astype(np.float32)


def _same_bits(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a.view(np.uint32), b.view(np.uint32))


@pytest.mark.parametrize("cosine", [False, True])
def test_dask_map_blocks_gives_the_bits_of_pb_eval(cosine):
    example = _load_dask_example()
    import dask.array as da

    rng = np.random.default_rng(31)
    n, chunk = 10_007, 4096  # chunks 4096, 4096, 1815: the last one ragged
    wi, wo = _hemisphere(rng, n), _hemisphere(rng, n)
    roughness = rng.uniform(0.0, 1.0, n).astype(np.float32)
    roughness[:7] = (0.0, 1.0, 0.001, 0.5, 0.0, 1.0, 0.25)
    base_color = rng.uniform(0.0, 1.0, (n, 3))
    material = pb.presets.get("car_paint")

    lazy = example.eval_dask(
        material, da.from_array(wi, chunks=(chunk, 3)), da.from_array(wo, chunks=(chunk, 3)),
        per_element={"roughness": da.from_array(roughness, chunks=3000),  # other chunks: rechunked to wi's
                     "base_color": da.from_array(base_color, chunks=(chunk, 3))},
        cosine=cosine)
    assert lazy.shape == (n, 3) and lazy.dtype == np.float32
    assert lazy.chunks == ((4096, 4096, 1815), (3,))
    expected = pb.eval(material.replace(roughness=roughness, base_color=base_color), wi, wo, cosine=cosine)
    assert _same_bits(lazy.compute(), expected)


def test_dask_with_one_view_direction_and_threads():
    example = _load_dask_example()
    import dask.array as da

    rng = np.random.default_rng(32)
    n = 5_001
    wi = _hemisphere(rng, n)
    wo = np.array([0.3, -0.2, np.sqrt(1 - 0.13)], np.float32)
    roughness = rng.uniform(0.0, 1.0, n)  # float64 in: converted per chunk exactly as pb.Material does
    material = pb.Material(base_color=(0.7, 0.4, 0.2), clearcoat=0.5, sheen=0.5)
    expected = pb.eval(material.replace(roughness=roughness), wi, wo)
    for threads in (1, None):
        lazy = example.eval_dask(material, da.from_array(wi, chunks=(1000, 3)), wo,
                                 per_element={"roughness": da.from_array(roughness, chunks=1000)}, threads=threads)
        assert _same_bits(lazy.compute(), expected)
    # the model option reaches the kernel
    lazy = example.eval_dask(material, da.from_array(wi, chunks=(2048, 3)), wo, model="disney2012")
    assert _same_bits(lazy.compute(), pb.eval(material, wi, wo, model="disney2012"))


def test_dask_tasks_serialise_to_worker_processes():
    """What a distributed cluster needs: tasks that pickle and run in another process."""
    example = _load_dask_example()
    import dask.array as da

    rng = np.random.default_rng(33)
    n = 3_000
    wi, wo = _hemisphere(rng, n), _hemisphere(rng, n)
    roughness = rng.uniform(0.0, 1.0, n).astype(np.float32)
    material = pb.presets.get("brushed_metal")
    lazy = example.eval_dask(material, da.from_array(wi, chunks=(1024, 3)), da.from_array(wo, chunks=(1024, 3)),
                             per_element={"roughness": da.from_array(roughness, chunks=1024)})
    result = lazy.compute(scheduler="processes", num_workers=2)
    assert _same_bits(result, pb.eval(material.replace(roughness=roughness), wi, wo))


def test_dask_rejects_bad_arguments():
    example = _load_dask_example()
    import dask.array as da

    wi = da.zeros((10, 3), chunks=(4, 3), dtype=np.float32)
    with pytest.raises(ValueError, match="per_element"):
        example.eval_dask(pb.Material(roughness=np.full(10, 0.5)), wi, wi)
    with pytest.raises(ValueError, match="roughness"):
        example.eval_dask(pb.Material(), wi, wi, per_element={"roughness": da.zeros(9, chunks=4)})
    with pytest.raises(TypeError, match="per_element"):
        example.eval_dask(pb.Material(), wi, wi, per_element={"shininess": da.zeros(10, chunks=4)})
    with pytest.raises(ValueError, match="wi"):
        example.eval_dask(pb.Material(), da.zeros((10, 2), chunks=4), wi)


def test_dask_example_runs_as_a_script(tmp_path):
    import dask.array  # noqa: F401  (a test dependency: fail, never skip)
    result = subprocess.run([sys.executable, str(EXAMPLES / "dask_scale_out.py"), "--n", "600000", "--chunk",
                             "131072"], capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "M pairs/s" in result.stdout
    assert "identical to pb.eval on the materialised arrays: True" in result.stdout
    assert list(tmp_path.iterdir()) == []
