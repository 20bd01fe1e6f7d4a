"""The structure, drawn again from the code: which module imports which (no circle between files, nor
between packages), function-local imports that say why, no private name taken from another package, each
step piece defined once, the ledger's arrays written only by ledger operations, and no file over 500 lines."""
from __future__ import annotations

import ast
import os
from collections import defaultdict
from pathlib import Path

import infomarket
from infomarket.engine.world import LEDGER

PACKAGE = Path(infomarket.__file__).parent
ROOT = "infomarket"  # the package's facade: Python imports it before any of its modules, so its imports
#                      of everything say nothing about layering (its edges are left out)


def _module_name(path: Path) -> str:
    rel = path.relative_to(PACKAGE.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


MODULES = {_module_name(p): p for p in PACKAGE.rglob("*.py")}


def _targets(module: str, is_package: bool, node: ast.Import | ast.ImportFrom) -> list[str]:
    """The project modules an import statement loads: ``from pkg import name`` is ``pkg.name`` when that
    is a module, else ``pkg`` (its ``__init__``)."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names if a.name.split(".")[0] == "infomarket"]
    if node.level:
        here = module.split(".")
        package = here if is_package else here[:-1]
        base = ".".join(package[:len(package) - node.level + 1] + ([node.module] if node.module else []))
    else:
        base = node.module or ""
    if base.split(".")[0] != "infomarket":
        return []
    return [f"{base}.{a.name}" if f"{base}.{a.name}" in MODULES else base for a in node.names]


def _imports(tree: ast.AST):
    """(import statement, inside a function?) for every import of ``tree``, ``if TYPE_CHECKING:`` aside."""
    def walk(node, local):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test):
                continue
            if isinstance(child, (ast.Import, ast.ImportFrom)):
                yield child, local
            yield from walk(child, local or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)))
    yield from walk(tree, False)


def file_graph(sources: dict[str, tuple[str, bool]] | None = None, with_root: bool = False) -> dict[str, set[str]]:
    """module -> the project modules it imports (at the top or inside a function), per file; the package
    root's own imports only ``with_root``."""
    sources = sources or {m: (p.read_text(), p.name == "__init__.py") for m, p in MODULES.items()}
    graph: dict[str, set[str]] = defaultdict(set)
    for module, (text, is_package) in sources.items():
        if module == ROOT and not with_root:
            continue
        for node, _ in _imports(ast.parse(text)):
            graph[module] |= {t for t in _targets(module, is_package, node) if t != module}
    return graph


def _explained(lines: list[str], node: ast.stmt) -> bool:
    """A comment on the import's own lines, or on the line above it (or above the block of imports and
    blank lines it belongs to)."""
    if any("#" in lines[i - 1] for i in range(node.lineno, node.end_lineno + 1)):
        return True
    j = node.lineno - 2
    while j >= 0 and "#" not in lines[j] and (not lines[j].strip()
                                              or lines[j].lstrip().startswith(("from ", "import "))):
        j -= 1
    return j >= 0 and (lines[j].lstrip().startswith("#") or (j == node.lineno - 2 and "#" in lines[j]))


def unexplained_local_imports(text: str, module: str = "infomarket.x", is_package: bool = False) -> list[str]:
    """Function-local imports of a project module with no comment saying why (as their source text)."""
    lines = text.splitlines()
    return [ast.unparse(node) for node, local in _imports(ast.parse(text))
            if local and _targets(module, is_package, node) and not _explained(lines, node)]


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one node (each a set of modules in a circle), sorted."""
    index, low, stack, on, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(found)


#: import circles allowed between files (none): modules -> why
KNOWN_CIRCLES: dict[tuple[str, ...], str] = {}

#: function-local imports of project modules allowed without a comment (none): file -> statements
UNEXPLAINED: dict[str, set[str]] = {}


def test_the_cycle_finder_finds_a_cycle():
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == [["a", "b", "c"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []
    assert _cycles({"a": {"b"}, "b": {"a"}, "c": {"d"}, "d": {"c", "a"}}) == [["a", "b"], ["c", "d"]]


def test_the_graph_sees_function_local_and_relative_imports():
    sources = {"infomarket.p.a": ("from . import b\n", False),
               "infomarket.p.b": ("def f():\n    from .a import g\n", False),
               "infomarket.p": ("from .a import x\n", True)}
    global MODULES
    saved, MODULES = MODULES, {m: None for m in sources}
    try:
        graph = file_graph(sources)
    finally:
        MODULES = saved
    assert graph == {"infomarket.p.a": {"infomarket.p.b"}, "infomarket.p.b": {"infomarket.p.a"},
                     "infomarket.p": {"infomarket.p.a"}}
    assert _cycles(graph) == [["infomarket.p.a", "infomarket.p.b"]]


def test_no_import_circle_between_files():
    graph = file_graph()
    assert "infomarket.engine.paths" in graph["infomarket.engine.step"]  # the graph is really drawn
    assert [c for c in _cycles(graph) if tuple(c) not in KNOWN_CIRCLES] == []


def test_no_import_circle_through_the_package_root():
    """A module that reads something through the root (``from . import __version__``) while the root
    imports it closes a circle through ``__init__.py``: the version is read from ``_version`` instead."""
    graph = file_graph(with_root=True)
    assert "infomarket.engine" in graph[ROOT]  # the root's edges are really drawn
    assert _cycles(graph) == []


def test_the_known_circles_are_still_there():
    """Once a branch removes its circle, take it out of KNOWN_CIRCLES (so it cannot come back unseen)."""
    found = {tuple(c) for c in _cycles(file_graph())}
    assert [c for c in KNOWN_CIRCLES if c not in found] == []


def test_the_why_comment_finder():
    text = ("def f():\n    from .a import b  # a imports this module\n"
            "def g():\n    # a imports this module\n    from .a import b\n\n    from .c import d\n"
            "def h():\n    from .a import b\n    import numpy\n"
            "def k():\n    x = 1\n    from .c import d\n")
    assert unexplained_local_imports(text) == ["from .a import b", "from .c import d"]


def test_function_local_imports_of_project_modules_say_why():
    found = {}
    for module, path in sorted(MODULES.items()):
        rel = str(path.relative_to(PACKAGE))
        bad = [s for s in unexplained_local_imports(path.read_text(), module, path.name == "__init__.py")
               if s not in UNEXPLAINED.get(rel, set())]
        if bad:
            found[rel] = bad
    assert found == {}


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
    for module, targets in file_graph().items():
        src = _unit(module)
        graph[src] |= {dst for dst in map(_unit, targets) if dst and dst != src}
    return graph


def test_no_import_circle_between_packages():
    graph = package_graph()
    assert "ledger" in graph["engine"] and "config" in graph["engine"]  # the graph is really drawn
    assert _cycles(graph) == []


def test_the_ledger_and_config_do_not_import_the_engine():
    graph = package_graph()
    assert "engine" not in graph["ledger"]
    assert "engine" not in graph["config"]
    assert "engine" not in graph["state"] and "ledger" not in graph["state"]


def test_the_attack_search_does_not_stand_on_the_rl_layer():
    """The runs, observation and optimiser both use live in ``agents``; rl and search each import it."""
    graph = package_graph()
    assert "agents" in graph["search"] and "agents" in graph["rl"]
    assert "rl" not in graph["search"] and "rl" not in graph["agents"]


STUDIES = ("analysis", "search", "defence")


def test_no_study_imports_another_studys_report_or_command_line():
    """Each study writes its report and reads its options through ``analysis`` (``study``, ``formats``):
    a study's own report and CLI modules are imported only from inside its package."""
    def own_only(module: str) -> bool:
        leaf = module.split(".")[-1]
        return _unit(module) in STUDIES and (leaf in ("report", "cli") or leaf.endswith(("_report", "_cli")))

    graph = file_graph()
    crossing = sorted((src, dst) for src, targets in graph.items() for dst in targets
                      if own_only(dst) and _unit(src) != _unit(dst) and _unit(src) in STUDIES)
    assert crossing == []
    assert "infomarket.analysis.study" in graph["infomarket.defence.cli"]  # the graph is really drawn


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


def _njit_inlined_by_numba(source: str) -> list[str]:
    """Functions of ``source`` decorated ``@njit(inline="always")`` (or ``'always'``)."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            for d in node.decorator_list:
                if (isinstance(d, ast.Call) and ast.unparse(d.func).split(".")[-1] == "njit"
                        and any(k.arg == "inline" and ast.unparse(k.value).strip("'\"") == "always"
                                for k in d.keywords)):
                    found.append(node.name)
    return found


def test_the_inlined_finder():
    assert _njit_inlined_by_numba("@njit(inline='always')\ndef f(w):\n    pass\n\n@njit(forceinline=True)\ndef g(w):\n"
                                  "    pass\n\n@numba.njit(inline=\"always\")\ndef h(w):\n    pass\n") == ["f", "h"]


def test_compiled_helpers_are_inlined_by_llvm_not_by_numba():
    """``@njit(forceinline=True)``: numba types a helper once per process and LLVM inlines its machine code
    into each kernel; ``inline="always"`` made numba type it again inside every kernel that calls it, and
    compiling took twice the CPU (docs/testing.md, "A fourth round").  The ``@overload``s and the generated
    dispatch functions stay inlined by numba, where it measured faster."""
    offenders = {m: names for m, p in MODULES.items() if (names := _njit_inlined_by_numba(p.read_text()))}
    assert not offenders, offenders


#: Most lines a source file of the project may hold, in any language: a longer one mixes jobs that want
#: modules of their own.
MAX_LINES = 500

#: The languages people write here (Python, Solidity, JavaScript, the viewer's HTML and CSS, TOML
#: declarations): every such file under src/, contracts/, tests/ and tools/ is held to MAX_LINES.
SOURCE_SUFFIXES = frozenset({".py", ".sol", ".js", ".mjs", ".css", ".html", ".toml"})

#: Files that are not held to it, by suffix, and why: no person writes them line by line. A file under
#: src/ or contracts/ with a suffix in neither set fails the test, so a new language cannot slip past it.
NOT_SOURCE = {
    ".json": "written by programs: the compiled contract (tools/solc/compile.js), npm's lockfiles, "
             "the conformance vectors the payment tests generate",
    ".typed": "py.typed, the empty PEP 561 marker",
}

#: Folders never walked into: installed packages (``make node`` and the artifact test write
#: ``node_modules`` under tools/ while the suite runs) and Python's byte code.
NOT_WALKED = frozenset({"node_modules", "__pycache__"})


def _project_files() -> list[Path]:
    """Every file under src/, contracts/, tests/ and tools/, never walking into ``NOT_WALKED``."""
    repo, found = PACKAGE.parent.parent, []
    for folder in ("src", "contracts", "tests", "tools"):
        for top, dirs, files in os.walk(repo / folder):
            dirs[:] = [d for d in dirs if d not in NOT_WALKED]
            found += [Path(top) / f for f in files]
    return found


def _source_files() -> list[Path]:
    return [p for p in _project_files() if p.suffix in SOURCE_SUFFIXES]


def test_every_file_of_the_package_and_the_contract_is_of_a_known_kind():
    repo = PACKAGE.parent.parent
    unknown = [str(p) for p in _project_files()
               if p.is_relative_to(repo / "src") or p.is_relative_to(repo / "contracts")
               if p.suffix not in SOURCE_SUFFIXES and p.suffix not in NOT_SOURCE]
    assert unknown == [], f"add these files' suffix to SOURCE_SUFFIXES (or NOT_SOURCE, with the reason): {unknown}"


def test_no_file_is_over_500_lines():
    files = _source_files()
    found = {p.suffix for p in files}
    # The files are really found, in every language the project is written in.
    assert PACKAGE / "evm" / "market.py" in files and Path(__file__) in files
    assert {".py", ".sol", ".js", ".css", ".html", ".toml"} <= found, found
    long = {str(p): n for p in files if (n := len(p.read_text().splitlines())) > MAX_LINES}
    assert long == {}, f"split these files (most {MAX_LINES} lines each): {long}"


def private_names_taken(text: str, module: str, is_package: bool = False) -> list[str]:
    """``module``'s uses of another package's private names (``_name``, not a dunder): imported from it, or
    read as an attribute of a module of it imported here.  A private module (``_numba_internals``) is a
    module, not a name, and may be imported."""
    def unit(name: str) -> str:
        return name.split(".")[1] if name.count(".") else ""

    def private(n: str) -> bool:
        return n.startswith("_") and not n.startswith("__")

    tree, found, modules = ast.parse(text), [], {}  # modules: local name -> the project module it is bound to
    for node, _ in _imports(tree):
        if isinstance(node, ast.Import):
            modules |= {a.asname or "infomarket": a.name if a.asname else "infomarket"
                        for a in node.names if a.name.split(".")[0] == "infomarket"}
            continue
        for alias, target in zip(node.names, _targets(module, is_package, node)):
            if target.endswith(f".{alias.name}"):  # the name is a module of the project
                modules[alias.asname or alias.name] = target
            elif private(alias.name) and unit(target) != unit(module):
                found.append(f"{target}.{alias.name}")
    for node in ast.walk(tree):
        if (isinstance(node, ast.Attribute) and private(node.attr) and isinstance(node.value, ast.Name)
                and node.value.id in modules and unit(modules[node.value.id]) != unit(module)):
            found.append(f"{modules[node.value.id]}.{node.attr}")
    return found


def test_the_private_name_finder():
    text = ("from ..search.report import _ci, json_ready\nfrom . import _helper\nfrom .. import _numba_internals\n"
            "from ..analysis import stats as st\nx = st._fmt_p(1) + st.fmt(2)\n")
    assert private_names_taken(text, "infomarket.defence.report") == [
        "infomarket.search.report._ci", "infomarket.analysis.stats._fmt_p"]
    assert private_names_taken(text, "infomarket.search.other") == ["infomarket.analysis.stats._fmt_p"]


def test_no_module_takes_a_private_name_of_another_package():
    taken = {m: names for m, p in MODULES.items()
             if (names := private_names_taken(p.read_text(), m, p.name == "__init__.py"))}
    assert taken == {}
