"""The API reference builds from the docstrings with warnings as errors (`make docs`,
docs/api/), and every public function and class of the package is in it."""

import importlib
import inspect
import pathlib
import posixpath
import subprocess
import sys
import types

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
# The modules the reference documents: the package's top level and its public submodules.
MODULES = ["principled_brdf", "principled_brdf.reference", "principled_brdf.microfacet", "principled_brdf.frames",
           "principled_brdf.measured", "principled_brdf.synthetic", "principled_brdf.presets",
           "principled_brdf.render", "principled_brdf.environment", "principled_brdf.procedural_environments",
           "principled_brdf.piecewise", "principled_brdf.plot", "principled_brdf.fitting",
           "principled_brdf.directional_albedo", "principled_brdf.explorer_app", "principled_brdf.torch", "principled_brdf.jax"]


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    pytest.importorskip("matplotlib")  # pb.plot and the explorer import it when documented
    out = tmp_path_factory.mktemp("docs")
    command = [sys.executable, "-m", "sphinx", "-b", "html", "-W", "--keep-going", "-q",
               "-d", str(out / "doctrees"), str(ROOT / "docs" / "api"), str(out / "html")]
    run = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, f"the API reference does not build cleanly:\n{run.stdout}\n{run.stderr}"
    return out / "html"


def documented_names(html: pathlib.Path) -> set:
    from sphinx.util.inventory import InventoryFile

    with open(html / "objects.inv", "rb") as f:
        inventory = InventoryFile.load(f, "", posixpath.join)
    items = inventory.items() if hasattr(inventory, "items") else inventory.data.items()
    return {name for _, entries in items for name in entries}


def test_the_api_reference_builds_without_warnings(built):
    assert (built / "index.html").exists()


def test_every_public_function_and_class_is_documented(built):
    names = documented_names(built)
    missing = []
    for module_name in MODULES:
        module = importlib.import_module(module_name)
        for name in module.__all__:
            member = getattr(module, name)
            if isinstance(member, types.ModuleType) or not callable(member):
                continue
            if not inspect.getdoc(member):
                missing.append(f"{module_name}.{name} (no docstring)")
            elif not any(documented == f"{module_name}.{name}" or documented.endswith(f".{name}")
                         for documented in names):
                missing.append(f"{module_name}.{name} (not in docs/api)")
    assert not missing, missing
