"""The examples run: the notebooks execute without a cell error and draw their figures.

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

import json
import os
import re
import sys
import time
from pathlib import Path

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
