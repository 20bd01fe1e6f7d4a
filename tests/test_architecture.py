"""The structure, drawn again from the code: which package imports which (no circle), each step piece
defined once, and the ledger's arrays written only by ledger operations."""
from __future__ import annotations

import ast
from collections import defaultdict
from pathlib import Path

import infomarket
from infomarket.engine.world import LEDGER

PACKAGE = Path(infomarket.__file__).parent


def _module_name(path: Path) -> str:
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def _imports(path: Path) -> set[str]:
    """Every infomarket module this file imports, at the top or inside a function."""
    tree = ast.parse(path.read_text())
    here = _module_name(path).split(".")
    package = here if path.name == "__init__.py" else here[:-1]
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name.startswith("infomarket")}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[:len(package) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            if mod.startswith("infomarket"):
                out.add(mod)
                out |= {f"{mod}.{a.name}" for a in node.names}
    return out


def _unit(module: str) -> str | None:
    """The architectural unit of a module: its subpackage (infomarket.engine) or top-level module."""
    parts = module.split(".")
    if len(parts) < 2 or parts[0] != "infomarket":
        return None
    name = parts[1]
    if (PACKAGE / name).is_dir() or (PACKAGE / f"{name}.py").exists():
        return name
    return None


def package_graph() -> dict[str, set[str]]:
    graph: dict[str, set[str]] = defaultdict(set)
    for path in PACKAGE.rglob("*.py"):
        src = _unit(_module_name(path))
        if src is None:  # the package's own __init__: the public facade, imports everything
            continue
        for mod in _imports(path):
            dst = _unit(mod)
            if dst and dst != src:
                graph[src].add(dst)
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    found, state, stack = [], {}, []

    def visit(node):
        state[node] = 1
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                found.append(stack[stack.index(nxt):] + [nxt])
            elif nxt not in state:
                visit(nxt)
        stack.pop()
        state[node] = 2

    for node in sorted(graph):
        if node not in state:
            visit(node)
    return found


def test_the_cycle_finder_finds_a_cycle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == [["a", "b", "c", "a"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


def test_no_import_circle_between_packages():
    graph = package_graph()
    assert "ledger" in graph["engine"] and "config" in graph["engine"]  # the graph is really drawn
    assert _cycles(graph) == []


def test_the_ledger_and_config_do_not_import_the_engine():
    graph = package_graph()
    assert "engine" not in graph["ledger"]
    assert "engine" not in graph["config"]
    assert "engine" not in graph["state"] and "ledger" not in graph["state"]


STEP_PIECES = ("find_neighbours", "begin_communication", "install_table", "forage", "sense_sites",
               "behaviour_step", "move", "record_history")  # (those of a variant are defined in engine.step.variant)


def test_each_step_piece_is_defined_once():
    """Among the compiled parts (store.results has a ``move`` of its own, for files)."""
    from infomarket.generated import COMPILED_PARTS

    defined = defaultdict(list)
    for path in [p for part in COMPILED_PARTS for p in (PACKAGE / part).rglob("*.py")]:
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef) and node.name in STEP_PIECES:
                defined[node.name].append(str(path.relative_to(PACKAGE)))
    assert {k: v for k, v in defined.items() if len(v) != 1} == {}
    assert set(defined) == set(STEP_PIECES)
    assert all(v == ["engine/step.py"] for v in defined.values())


def test_no_step_piece_is_rebound_by_an_import():
    for path in PACKAGE.rglob("*.py"):
        assert "noqa: F811" not in path.read_text(), path


def _ledger_writes(tree: ast.AST) -> list[int]:
    """Lines that write a ledger array: ``w.balance[...] = ...`` or ``unlock(w.balance)``."""
    lines = []
    for node in ast.walk(tree):
        targets = []
        if isinstance(node, ast.Assign):
            targets = node.targets
        elif isinstance(node, ast.AugAssign):
            targets = [node.target]
        for t in targets:
            if isinstance(t, ast.Subscript) and isinstance(t.value, ast.Attribute) and t.value.attr in LEDGER:
                lines.append(node.lineno)
        if (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "unlock"
                and node.args and isinstance(node.args[0], ast.Attribute) and node.args[0].attr in LEDGER):
            lines.append(node.lineno)
    return lines


def test_only_ledger_operations_write_ledger_arrays():
    assert _ledger_writes(ast.parse("w.balance[i] += 1.0\nunlock(w.pot)[0] = 2\nw.pos[i] = 0")) == [1, 2]
    offenders = {}
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(PACKAGE)
        if rel.parts[0] == "ledger":
            continue
        lines = _ledger_writes(ast.parse(path.read_text()))
        if lines:
            offenders[str(rel)] = lines
    assert offenders == {}
    assert _ledger_writes(ast.parse((PACKAGE / "ledger" / "kernels.py").read_text()))  # where they are
