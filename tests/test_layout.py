"""The package's layout rules, read from the source's syntax trees.

- no private name (``_x``, or a module ``_x``) imported from another package;
- no import circle between modules (imports inside functions count; ``TYPE_CHECKING``
  blocks do not, since they never run);
- the reports render: no module of ``stewartid.reports`` fits an estimator;
- every gallery example imports from ``stewartid`` and at most one subpackage.
"""

from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

SOURCE = Path(__file__).resolve().parents[1] / "src"


def _modules() -> dict[str, tuple[Path, bool]]:
    """Dotted module name -> (file, is a package's ``__init__``)."""
    found = {}
    for path in sorted((SOURCE / "stewartid").rglob("*.py")):
        parts = list(path.relative_to(SOURCE).with_suffix("").parts)
        package = parts[-1] == "__init__"
        found[".".join(parts[:-1] if package else parts)] = (path, package)
    return found


MODULES = _modules()


def _type_checking_nodes(tree: ast.AST) -> set[int]:
    skipped = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            skipped.update(id(inner) for child in node.body for inner in ast.walk(child))
    return skipped


def _imports(module: str) -> list[tuple[str, str, int]]:
    """(imported module, imported name or '', line) of every stewartid import in ``module``."""
    path, package = MODULES[module]
    tree = ast.parse(path.read_text(encoding="utf-8"))
    skipped = _type_checking_nodes(tree)
    found = []
    for node in ast.walk(tree):
        if id(node) in skipped:
            continue
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = module.split(".") if package else module.split(".")[:-1]
                base = base[:len(base) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if target.split(".")[0] == "stewartid":
                found += [(target, alias.name, node.lineno) for alias in node.names]
        elif isinstance(node, ast.Import):
            found += [(alias.name, "", node.lineno) for alias in node.names
                      if alias.name.split(".")[0] == "stewartid"]
    return found


def _package_of(module: str) -> str:
    return module if MODULES[module][1] else module.rpartition(".")[0]


def _private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _edges() -> dict[str, set[str]]:
    edges = defaultdict(set)
    for module in MODULES:
        for target, name, _ in _imports(module):
            if f"{target}.{name}" in MODULES:
                edges[module].add(f"{target}.{name}")
            elif target in MODULES:
                edges[module].add(target)
    for module in edges:
        edges[module].discard(module)
    return edges


def _circles(edges: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan, iterative)."""
    index, low, stack, on_stack, circles = {}, {}, [], set(), []
    for root in MODULES:
        if root in index:
            continue
        work = [(root, iter(sorted(edges.get(root, ()))))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            for child in children:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(edges.get(child, ())))))
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
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
                        circles.append(sorted(component))
    return circles


def test_the_rules_see_the_whole_package():
    assert len(MODULES) > 50
    assert "stewartid.model.kinematics" in MODULES


def test_no_private_name_crosses_a_package():
    crossings = []
    for module in MODULES:
        for target, name, line in _imports(module):
            owner = target if target in MODULES and MODULES[target][1] else \
                target.rpartition(".")[0]
            if f"{target}.{name}" in MODULES and MODULES[f"{target}.{name}"][1]:
                owner = f"{target}.{name}"
            hidden = _private(name) or any(_private(part) for part in target.split("."))
            if hidden and owner != _package_of(module):
                crossings.append(f"{module}:{line} imports {target}.{name}")
    assert crossings == []


def test_no_import_circle():
    assert _circles(_edges()) == []


def test_the_circle_finder_finds_a_circle():
    assert _circles({"stewartid.errors": {"stewartid.files"},
                     "stewartid.files": {"stewartid.errors"}}) == [
        ["stewartid.errors", "stewartid.files"]]


def test_the_reports_fit_nothing():
    """Reports render a comparison; fitting is the library's (``stewartid.comparison``)."""
    fits = []
    for module, (path, _) in MODULES.items():
        if not module.startswith("stewartid.reports"):
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) \
                    and node.func.attr in {"fit", "fit_predict"}:
                fits.append(f"{module}:{node.lineno}")
    assert fits == []


def test_the_gallery_uses_the_top_level_api():
    """Each example imports ``stewartid`` and at most one of its subpackages."""
    examples = SOURCE.parent / "examples"
    for path in sorted(examples.glob("*.py")):
        packages = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.module and \
                    node.module.startswith("stewartid"):
                packages.add(".".join(node.module.split(".")[:2]))
            elif isinstance(node, ast.Import):
                packages.update(".".join(a.name.split(".")[:2]) for a in node.names
                                if a.name.startswith("stewartid"))
        assert len(packages - {"stewartid"}) <= 1, f"{path.name}: {sorted(packages)}"


def test_the_layout_page_lists_every_module_in_its_package():
    """docs/layout.md's tree holds every module, indented under its package (so the page a
    reader learns the package from stays true when a module is added)."""
    page = (SOURCE.parent / "docs" / "layout.md").read_text()
    tree = page.split("```text", 1)[1].split("```", 1)[0].splitlines()
    listed, stack = set(), []
    for row in tree[2:]:  # below "stewartid/"
        depth = (len(row) - len(row.lstrip(" "))) // 4
        name = row.split()[0] if row.strip() else ""
        if not name:
            continue
        stack = stack[:depth - 1]
        if name.endswith("/"):
            stack.append(name[:-1])
        else:
            listed.add(".".join(["stewartid", *stack, name]))
    modules = {m for m, (_, package) in MODULES.items() if not package
               and m.rsplit(".", 1)[1] != "__main__"}
    assert not sorted(modules - listed), "add them to docs/layout.md"
