"""The documentation's whole scripts run as scripts.

A ```python block of README.md or docs/*.md with the line
``import principled_brdf as pb`` is a whole script: a reader can save it to a
file and run ``python3 file.py``. Blocks that continue a page (they use what
an earlier block of the page made) do not import the package again, and are
not scripts.

test_pages_run_and_links_resolve.py runs every block in one namespace per
page, as a notebook would; here each script runs alone, saved to a file, in a
fresh interpreter as ``__main__``, in an empty folder that must stay empty.
That is what the shared namespace cannot show: a script that reads a name
only an earlier block defines, or one that starts worker processes, which
import the script again (a dask ``LocalCluster`` of processes needs
``if __name__ == "__main__":``).
"""

from __future__ import annotations

import os
import pathlib
import re
import subprocess
import sys

import pytest

import principled_brdf as pb
from test_pages_run_and_links_resolve import NOT_RUN, PAGES, ROOT, python_blocks

SCRIPT_LINE = re.compile(r"^import principled_brdf as pb$", re.M)
TIMEOUT = 300  # seconds a script; together they take about 40 s on two cores
PACKAGE_PARENT = pathlib.Path(pb.__file__).resolve().parents[1]  # the scripts import the package under test


def scripts() -> list:
    """(page, block index, block) of every block that is a whole script."""
    return [(page, index, block)
            for page in [ROOT / "README.md", *PAGES]
            for index, block in enumerate(python_blocks(page))
            if not block.startswith(NOT_RUN) and SCRIPT_LINE.search(block)]


SCRIPTS = scripts()


def test_the_scripts_are_found():
    """The README's tour, a script on most pages, and the distributed page's cluster."""
    pages = {page.name for page, _, _ in SCRIPTS}
    assert len(SCRIPTS) >= 15, [f"{page.name} {index}" for page, index, _ in SCRIPTS]
    assert {"README.md", "distributed.md", "evaluating.md", "sampling.md", "model-2015.md"} <= pages
    cluster = [block for page, _, block in SCRIPTS if page.name == "distributed.md" and "LocalCluster(" in block]
    assert len(cluster) == 1
    assert 'if __name__ == "__main__":' in cluster[0]


def test_a_block_that_continues_a_page_is_no_script():
    blocks = python_blocks(ROOT / "docs" / "distributed.md")
    continuing = [block for block in blocks if not SCRIPT_LINE.search(block)]
    assert continuing and all("pbd." in block for block in continuing)  # the page's pbd, from its first block


@pytest.mark.parametrize("page, index, block", SCRIPTS,
                         ids=[f"{page.name}-block{index}" for page, index, _ in SCRIPTS])
def test_script_runs_alone(page, index, block, tmp_path):
    script = tmp_path / f"{page.stem}_{index}.py"
    script.write_text(block, encoding="utf-8")
    working, scratch = tmp_path / "working", tmp_path / "tmp"
    working.mkdir()
    scratch.mkdir()
    env = dict(os.environ, MPLBACKEND="Agg", TMPDIR=str(scratch),
               PYTHONPATH=os.pathsep.join(filter(None, [str(PACKAGE_PARENT), os.environ.get("PYTHONPATH")])))
    result = subprocess.run([sys.executable, str(script)], cwd=working, env=env, capture_output=True, text=True,
                            timeout=TIMEOUT)
    assert result.returncode == 0, (f"{page.name} python block {index}, run as a script, exits with "
                                    f"{result.returncode}:\n{result.stderr[-3000:]}\n{block}")
    assert not list(working.iterdir()), f"{page.name} python block {index} wrote into the current folder"
