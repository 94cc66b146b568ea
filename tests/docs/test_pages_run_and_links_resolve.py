"""The documentation runs and its links lead somewhere.

Every ```python block of README.md and docs/*.md runs as written, in order,
in one namespace per page (as a reader pastes a page into a notebook), in a
temporary folder that stays empty (examples write into their own temporary
folders), with matplotlib's Agg backend. A block whose first line starts with
``# not run`` is illustrative only and skipped; such blocks are rare.

Printed outputs are checked: a top-level expression followed directly by
comment lines shows its repr in them (``np.round(f, 4)`` then
``# array([[0.0896, ...]], dtype=float32)``), compared with whitespace
normalised, unless the expression's line says ``machine-dependent``. Outputs
are rounded so that every instruction set prints them.
"""

import ast
import pathlib
import re
import tempfile

import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
PAGES = sorted(DOCS.glob("*.md"))
NOT_RUN = "# not run"
MAX_NOT_RUN = 2  # per page


def fences(text: str) -> list:
    """(language, body) of every fenced block, indented ones included."""
    return re.findall(r"^[ \t]*```([^\n`]*)\n(.*?)^[ \t]*```[ \t]*$", text, re.S | re.M)


def python_blocks(path: pathlib.Path) -> list:
    return [body for language, body in fences(path.read_text(encoding="utf-8")) if language.strip() == "python"]


def shown_outputs(block: str) -> dict:
    """{statement index: the repr its comment lines show} for the block's top-level expressions."""
    tree = ast.parse(block)
    lines = block.splitlines()
    shown = {}
    for i, statement in enumerate(tree.body):
        end = tree.body[i + 1].lineno - 1 if i + 1 < len(tree.body) else len(lines)
        after = lines[statement.end_lineno:end]
        while after and not after[-1].strip():
            after.pop()
        own_line = lines[statement.end_lineno - 1]
        if (isinstance(statement, ast.Expr) and after and all(line.lstrip().startswith("#") for line in after)
                and "machine-dependent" not in own_line):
            shown[i] = " ".join(line.lstrip()[1:].strip() for line in after)
    return shown


def run_blocks(blocks: list, name: str) -> dict:
    """Runs the blocks in order in one namespace; checks the outputs they show. Returns the namespace."""
    namespace: dict = {"__name__": "__docs__"}
    for b, block in enumerate(blocks):
        if block.startswith(NOT_RUN):
            continue
        label = f"{name} python block {b}"
        tree = ast.parse(block, label)
        shown = shown_outputs(block)
        for i, statement in enumerate(tree.body):
            try:
                if i in shown:
                    value = eval(compile(ast.Expression(statement.value), label, "eval"), namespace)
                else:
                    exec(compile(ast.Module([statement], []), label, "exec"), namespace)
            except Exception as error:  # noqa: BLE001 - report which block and line failed
                raise AssertionError(f"{label}, line {statement.lineno} fails: {error!r}\n{block}") from error
            if i in shown:
                printed = " ".join(repr(value).split())
                assert printed == " ".join(shown[i].split()), (
                    f"{label}, line {statement.lineno} prints\n{printed}\nbut the page shows\n{shown[i]}")
    return namespace


@pytest.fixture
def page_sandbox(monkeypatch, tmp_path):
    """An empty working folder, examples/ importable, matplotlib headless; the folder must stay
    empty. The examples' temporary folders (tempfile.mkdtemp()) are made inside pytest's own."""
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    working, scratch = tmp_path / "working", tmp_path / "tmp"
    working.mkdir()
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    monkeypatch.chdir(working)
    yield working
    import matplotlib.pyplot as plt

    plt.close("all")
    assert not list(working.iterdir()), "an example wrote into the current folder"


def run_page(path: pathlib.Path) -> dict:
    return run_blocks(python_blocks(path), path.name)


@pytest.mark.parametrize("page", PAGES, ids=[p.name for p in PAGES])
def test_page_python_blocks_run_as_written(page, page_sandbox):
    run_page(page)


@pytest.mark.parametrize("page", [ROOT / "README.md", *PAGES], ids=["README.md", *[p.name for p in PAGES]])
def test_code_blocks_are_tested_or_marked(page):
    """Python is fenced as ```python (which runs), never as py/python3/pycon; blocks not run are rare."""
    text = page.read_text(encoding="utf-8")
    languages = [language.strip() for language, _ in fences(text)]
    assert not [x for x in languages if x.startswith("py") and x != "python"], languages
    indented = re.findall(r"^[ \t]+```python", text, re.M)
    assert not indented, "an indented python block would not run"
    not_run = [b for b in python_blocks(page) if b.startswith(NOT_RUN)]
    assert len(not_run) <= MAX_NOT_RUN


def slug(heading: str) -> str:
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces as hyphens."""
    text = re.sub(r"[`*_]", "", heading.strip().lower())
    return re.sub(r"[^\w\- ]", "", text).replace(" ", "-")


def anchors(path: pathlib.Path) -> set:
    text = re.sub(r"^[ \t]*```.*?^[ \t]*```", "", path.read_text(encoding="utf-8"), flags=re.S | re.M)
    return {slug(h) for h in re.findall(r"^#{1,6} (.+)$", text, re.M)}


@pytest.mark.parametrize("page", [ROOT / "README.md", *PAGES], ids=["README.md", *[p.name for p in PAGES]])
def test_links_lead_somewhere(page):
    """Every relative link names a file of the repository, and its #anchor a heading there."""
    text = re.sub(r"^[ \t]*```.*?^[ \t]*```", "", page.read_text(encoding="utf-8"), flags=re.S | re.M)
    for target in re.findall(r"\]\(([^)\s]+)\)", text):
        if re.match(r"[a-z]+:", target):
            continue
        file, _, anchor = target.partition("#")
        resolved = (page.parent / file).resolve() if file else page
        assert resolved.exists(), f"{page.name}: {target} does not exist"
        assert ROOT in resolved.parents or resolved == ROOT, f"{page.name}: {target} is outside the repository"
        if anchor and resolved.suffix == ".md":
            assert anchor in anchors(resolved), f"{page.name}: no heading for #{anchor} in {resolved.name}"


def test_every_page_is_listed_in_the_index_and_the_readme():
    index = (DOCS / "index.md").read_text(encoding="utf-8")
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    for page in PAGES:
        if page.name != "index.md":
            assert f"({page.name}" in index, f"docs/index.md does not list {page.name}"
            assert f"(docs/{page.name}" in readme, f"README.md does not link {page.name}"


# ---------------------------------------------------------------------------------------------
# The README: its blocks run the same way, and a few of the numbers its tour shows are
# checked on every instruction set.

README = ROOT / "README.md"


def test_the_readme_has_python_blocks():
    assert len(python_blocks(README)) >= 1


def test_every_readme_python_block_runs_as_written(page_sandbox):
    namespace = run_blocks(python_blocks(README), "README.md")
    import principled_brdf as pb

    # what the tour shows, rounded so that every instruction set prints it
    m, wi, wo = namespace["m"], namespace["wi"], namespace["wo"]
    np.testing.assert_array_equal(np.round(pb.eval(m, wi, wo), 4), np.float32([[0.0896, 0.0598, 0.0199]]))
    for isa in pb.cpu_info()["available"]:
        np.testing.assert_allclose(pb.eval(m, wi, wo, isa=isa), [[0.0896414, 0.05976094, 0.01992031]], rtol=1e-6)
    assert set(pb.cpu_info()) == {"isa", "float_lanes", "available", "threads"}
