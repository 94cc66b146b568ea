"""The package is built in layers: no module of principled_brdf imports, directly
or through others, a module that imports it back, and no public name of the
package is a function that hides a submodule of the same name.

Imports are read from the source with ``ast``, at module level and inside
functions and methods alike (a lazy import is still an edge of the graph);
imports under ``if TYPE_CHECKING:`` are left out, as they never run.
"""

from __future__ import annotations

import ast
import inspect
import pathlib

import principled_brdf as pb

PACKAGE = "principled_brdf"
PACKAGE_DIR = pathlib.Path(__file__).resolve().parents[2] / "python" / PACKAGE


def module_files() -> dict[str, pathlib.Path]:
    """Every Python module of the package by its dotted name (a package by its ``__init__.py``)."""
    modules = {}
    for path in sorted(PACKAGE_DIR.rglob("*.py")):
        parts = path.relative_to(PACKAGE_DIR).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        modules[".".join((PACKAGE,) + parts)] = path
    return modules


def extension_modules() -> set[str]:
    """The compiled submodules (``_core``): imported by name, importing nothing of the package.
    Found where the package was imported from (an installed wheel keeps them there, not in
    the source tree)."""
    installed = pathlib.Path(pb.__file__).resolve().parent
    return {".".join((PACKAGE,) + path.relative_to(installed).parts[:-1] + (path.name.split(".")[0],))
            for suffix in ("*.so", "*.pyd") for path in installed.rglob(suffix)}


def _is_type_checking(test: ast.expr) -> bool:
    """``TYPE_CHECKING`` or ``typing.TYPE_CHECKING``."""
    return (isinstance(test, ast.Name) and test.id == "TYPE_CHECKING") or (
        isinstance(test, ast.Attribute) and test.attr == "TYPE_CHECKING")


def _runtime_nodes(tree: ast.AST):
    """Every node that can run: the whole tree but the bodies of ``if TYPE_CHECKING:``
    (their ``else:`` runs)."""
    stack = [tree]
    while stack:
        node = stack.pop()
        yield node
        if isinstance(node, ast.If) and _is_type_checking(node.test):
            stack.extend(node.orelse)
            continue
        stack.extend(ast.iter_child_nodes(node))


def _package_of(module: str, path: pathlib.Path) -> str:
    """The package a relative import in ``module`` starts from."""
    return module if path.name == "__init__.py" else module.rpartition(".")[0]


def imported_modules(module: str, path: pathlib.Path, modules: set[str]) -> set[str]:
    """The package's modules that ``module`` imports anywhere in its code."""
    found: set[str] = set()

    def add(name: str) -> None:
        # the module itself, else the nearest package of the package that holds the name
        while name and name not in modules:
            name = name.rpartition(".")[0]
        if name:
            found.add(name)

    for node in _runtime_nodes(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name == PACKAGE or alias.name.startswith(PACKAGE + "."):
                    add(alias.name)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = _package_of(module, path)
                for _ in range(node.level - 1):
                    base = base.rpartition(".")[0]
                source = f"{base}.{node.module}" if node.module else base
            else:
                source = node.module or ""
                if source != PACKAGE and not source.startswith(PACKAGE + "."):
                    continue
            for alias in node.names:
                submodule = f"{source}.{alias.name}"
                add(submodule if submodule in modules else source)  # `from . import x`: x when it is a module
    found.discard(module)
    return found


def import_graph() -> dict[str, set[str]]:
    files = module_files()
    known = set(files) | extension_modules()
    graph = {module: imported_modules(module, path, known) for module, path in files.items()}
    return graph | {module: set() for module in known - set(files)}


def strongly_connected(graph: dict[str, set[str]]) -> list[list[str]]:
    """Tarjan's strongly connected components, iteratively; only those that hold a cycle."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    components: list[list[str]] = []
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, edges = work[-1]
            for target in edges:
                if target not in index:
                    index[target] = low[target] = len(index)
                    stack.append(target)
                    on_stack.add(target)
                    work.append((target, iter(sorted(graph[target]))))
                    break
                if target in on_stack:
                    low[node] = min(low[node], index[target])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1:
                        components.append(sorted(component))
    return components


def a_cycle(graph: dict[str, set[str]], component: list[str]) -> list[str]:
    """One closed path through ``component``'s first module, shortest first (breadth-first)."""
    members = set(component)
    start = component[0]
    previous: dict[str, str] = {}
    frontier = [start]
    while frontier:
        following = []
        for node in frontier:
            for target in sorted(graph[node] & members):
                if target == start:
                    path = [node]
                    while path[-1] != start:
                        path.append(previous[path[-1]])
                    return [start] + path[::-1][1:] + [start]
                if target not in previous:
                    previous[target] = node
                    following.append(target)
        frontier = following
    raise AssertionError(f"no cycle through {start} in {component}")


def short(module: str) -> str:
    return module.removeprefix(PACKAGE + ".") if module != PACKAGE else "__init__"


def test_the_graph_sees_every_kind_of_import(tmp_path):
    package = tmp_path / "principled_brdf"
    package.mkdir()
    sources = {
        "__init__.py": "from . import a\n",
        "a.py": "from .b import thing\n",
        "b.py": "def f():\n    import principled_brdf.c\n",
        "c.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from . import a\nelse:\n    from . import d\n",
        "d.py": "class K:\n    def m(self):\n        from principled_brdf import e\n",
        "e.py": "from . import name_in_init\n",
    }
    for name, text in sources.items():
        (package / name).write_text(text)
    files = {f"{PACKAGE}.{name[:-3]}" if name != "__init__.py" else PACKAGE: package / name for name in sources}
    graph = {module: imported_modules(module, path, set(files)) for module, path in files.items()}
    assert graph == {
        PACKAGE: {f"{PACKAGE}.a"},
        f"{PACKAGE}.a": {f"{PACKAGE}.b"},
        f"{PACKAGE}.b": {f"{PACKAGE}.c"},
        f"{PACKAGE}.c": {f"{PACKAGE}.d"},
        f"{PACKAGE}.d": {f"{PACKAGE}.e"},
        f"{PACKAGE}.e": {PACKAGE},
    }
    assert strongly_connected(graph) == [sorted(graph)]
    assert a_cycle(graph, sorted(graph)) == [PACKAGE] + [f"{PACKAGE}.{m}" for m in "abcde"] + [PACKAGE]


def cycles_through(graph: dict[str, set[str]], component: list[str]) -> list[str]:
    """A shortest cycle through each module of ``component``, each cycle once."""
    seen: dict[frozenset[str], str] = {}
    for module in component:
        cycle = a_cycle(graph, [module] + [m for m in component if m != module])
        seen.setdefault(frozenset(zip(cycle, cycle[1:])), " -> ".join(short(m) for m in cycle))
    return list(seen.values())


def test_no_import_cycles_in_the_package():
    graph = import_graph()
    assert {f"{PACKAGE}.material", f"{PACKAGE}._core"} <= set(graph)  # the package was found
    components = strongly_connected(graph)
    report = []
    for component in components:
        report.append(f"modules that import each other: {', '.join(short(m) for m in component)}")
        report += [f"  {cycle}" for cycle in cycles_through(graph, component)]
    assert not components, "import cycles in the package (each closed path of imports once):\n" + "\n".join(report)


def test_no_public_function_hides_a_submodule():
    submodules = {module.rpartition(".")[2] for module in module_files() if module != PACKAGE}
    shadowed = sorted(name for name in dir(pb) if not name.startswith("_") and name in submodules
                      and (inspect.isfunction(getattr(pb, name)) or inspect.isbuiltin(getattr(pb, name))))
    assert not shadowed, f"pb.{', pb.'.join(shadowed)}: a function with the name of a module of the package"
