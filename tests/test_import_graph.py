"""The package's import graph has no cycle: built from the source, function-local imports
included, so a lower layer that reaches back up (even inside a function) fails here with the
circle named."""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "reliefkit"


def module_names(package: Path) -> dict[str, Path]:
    """Dotted name -> file of every module under ``package`` (a package is its __init__)."""
    out = {}
    for path in sorted(package.rglob("*.py")):
        parts = list(path.relative_to(package.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def import_graph(package: Path) -> dict[str, set[str]]:
    """Module -> the package's own modules it imports anywhere in its source.

    ``from .a import b`` points at ``a.b`` when that is a module, else at ``a``; ``import
    a.b`` at ``a.b``; ``importlib.import_module("a.b")`` (a constant name) at ``a.b`` too.
    Importing ``a.b`` runs the package ``a`` first: it is a target too, unless it is a
    package of the importer's own (already running). Imports of other distributions are
    left out.
    """
    names = module_names(package)
    graph = {}
    for name, path in names.items():
        here = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
        targets = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets |= {alias.name for alias in node.names}
            elif isinstance(node, ast.ImportFrom):
                base = here[:len(here) - node.level + 1] if node.level else []
                source = ".".join([*base, *(node.module.split(".") if node.module else [])])
                subs = {f"{source}.{alias.name}" for alias in node.names} & names.keys()
                named = len(subs) < len(node.names)  # some names are the module's attributes
                targets |= subs | ({source} if named or not subs else set())
            elif _imports_by_name(node):
                targets.add(node.args[0].value)
        own = {".".join(here[:i]) for i in range(1, len(here) + 1)}
        parents = {".".join(t.split(".")[:i]) for t in targets
                   for i in range(1, t.count(".") + 1)}
        graph[name] = {t for t in targets | (parents - own) if t in names and t != name}
    return graph


def _imports_by_name(node: ast.AST) -> bool:
    """``import_module("a.b")`` or ``importlib.import_module("a.b")`` with a constant name."""
    if not isinstance(node, ast.Call) or not node.args:
        return False
    func = node.func
    called = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", None)
    first = node.args[0]
    return (called == "import_module" and isinstance(first, ast.Constant)
            and isinstance(first.value, str) and not first.value.startswith("."))


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components with more than one module (Tarjan), largest first."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(root: str) -> None:
        # iterative, so a deep package cannot hit the recursion limit
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, edges = work[-1]
            for nxt in edges:
                if nxt not in index:
                    index[nxt] = low[nxt] = len(index)
                    stack.append(nxt)
                    on_stack.add(nxt)
                    work.append((nxt, iter(sorted(graph[nxt]))))
                    break
                if nxt in on_stack:
                    low[node] = min(low[node], index[nxt])
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
                        found.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return sorted(found, key=len, reverse=True)


def a_circle(graph: dict[str, set[str]], component: list[str]) -> list[str]:
    """One concrete circle through ``component`` (a -> b -> ... -> a), for the message."""
    members = set(component)
    start = component[0]
    path, seen = [start], {start}
    while True:
        nxt = min(t for t in graph[path[-1]] if t in members)
        if nxt in seen:
            return [*path[path.index(nxt):], nxt]
        path.append(nxt)
        seen.add(nxt)


def test_the_package_has_no_import_cycle():
    graph = import_graph(PACKAGE)
    found = cycles(graph)
    assert not found, (f"{len(found)} import cycle(s); the largest has {len(found[0])} modules, "
                       f"e.g. {' -> '.join(a_circle(graph, found[0]))}")


def test_a_planted_cycle_is_found(tmp_path):
    pkg = tmp_path / "pkg"
    (pkg / "low").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "low" / "__init__.py").write_text("")
    (pkg / "low" / "table.py").write_text("def f():\n    from ..high import root\n")
    (pkg / "high.py").write_text("from . import low\nfrom .low import table\n")
    (pkg / "root.py").write_text("import pkg.low.table\n")
    (pkg / "plugins.py").write_text("import importlib\n\ndef load():\n"
                                    "    return importlib.import_module('pkg.alone')\n")
    (pkg / "tools").mkdir()  # a second circle, through a package's __init__
    (pkg / "tools" / "__init__.py").write_text("from ..plugins import load\n")
    (pkg / "tools" / "report.py").write_text("")
    (pkg / "alone.py").write_text("from .low import table\nfrom .tools import report\n")
    graph = import_graph(pkg)
    assert graph["pkg.high"] == {"pkg.low", "pkg.low.table"}  # `from . import low`: the module
    assert graph["pkg.low.table"] == {"pkg.high"}  # inside a function, an attribute of a module
    assert graph["pkg.plugins"] == {"pkg.alone"}  # by a constant name
    assert graph["pkg.alone"] == {"pkg.low", "pkg.low.table", "pkg.tools", "pkg.tools.report"}
    assert cycles(graph) == [["pkg.alone", "pkg.plugins", "pkg.tools"],
                             ["pkg.high", "pkg.low.table"]]
    assert a_circle(graph, ["pkg.high", "pkg.low.table"]) == ["pkg.high", "pkg.low.table",
                                                            "pkg.high"]
