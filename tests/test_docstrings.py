"""Docstring coverage of the public API, drawn from the source with ``ast`` (nothing is imported, so
numba compiles nothing and a module's import-time side effects do not matter).

What counts as public, and why:

* a module is public unless a part of its dotted path starts with ``_`` (``_numba_internals`` patches
  numba's internals and is nobody's API); the kernels generated at run time are written to the cache
  directory, not under ``src/``, and the templates they are made from are strings, so neither is counted;
* module-level functions and classes whose names do not start with ``_`` (also those defined under a
  module-level ``if``/``try``, such as an optional dependency's fallback);
* in a public class, methods and properties whose names do not start with ``_``; a property's setter or
  deleter shares the getter's docstring and is not counted again.  Dunder methods are left out,
  ``__init__`` included: the documentation site documents a constructor's arguments in the class
  docstring (Google style, ``Args:`` there), so a separate ``__init__`` docstring would say it twice;
* functions nested inside functions are implementation, not API.

Each kind must be at least ``THRESHOLD`` documented; a failure lists what is missing, by file and line.
And every docstring must read as Google style (``Args:``, ``Returns:``, ``Raises:``, ``Example:``), the one
style the API reference renders, checked with griffe, the parser the documentation site uses.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "infomarket"
THRESHOLD = 0.95


def _public_modules():
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        if any(p.startswith("_") for p in parts):
            continue
        yield path


def _top_level(body):
    """Statements at module level, looking into ``if``/``try``/``with`` blocks."""
    for node in body:
        if isinstance(node, ast.If):
            yield from _top_level(node.body)
            yield from _top_level(node.orelse)
        elif isinstance(node, ast.Try):
            for block in (node.body, node.orelse, node.finalbody, *(h.body for h in node.handlers)):
                yield from _top_level(block)
        elif isinstance(node, ast.With):
            yield from _top_level(node.body)
        else:
            yield node


def _is_accessor(node: ast.FunctionDef | ast.AsyncFunctionDef) -> bool:
    """``@x.setter`` / ``@x.deleter``: documented by the property's getter."""
    return any(isinstance(d, ast.Attribute) and d.attr in ("setter", "deleter") for d in node.decorator_list)


def public_definitions(path: Path):
    """``(kind, qualified name, line, has docstring)`` for each public definition in one file."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    functions = (ast.FunctionDef, ast.AsyncFunctionDef)

    def visit_class(node: ast.ClassDef, prefix: str):
        yield "classes", prefix + node.name, node.lineno, ast.get_docstring(node) is not None
        for child in _top_level(node.body):
            if getattr(child, "name", "_").startswith("_"):
                continue
            if isinstance(child, ast.ClassDef):
                yield from visit_class(child, f"{prefix}{node.name}.")
            elif isinstance(child, functions) and not _is_accessor(child):
                yield ("methods", f"{prefix}{node.name}.{child.name}", child.lineno,
                       ast.get_docstring(child) is not None)

    for node in _top_level(tree.body):
        if getattr(node, "name", "_").startswith("_"):
            continue
        if isinstance(node, ast.ClassDef):
            yield from visit_class(node, "")
        elif isinstance(node, functions):
            yield "functions", node.name, node.lineno, ast.get_docstring(node) is not None


def coverage():
    """kind -> (documented count, total count, list of undocumented 'file:line name')."""
    found: dict[str, tuple[int, int, list[str]]] = {k: (0, 0, []) for k in ("functions", "classes", "methods")}
    for path in _public_modules():
        rel = path.relative_to(PACKAGE.parent)
        for kind, name, line, documented in public_definitions(path):
            done, total, missing = found[kind]
            if not documented:
                missing.append(f"{rel}:{line} {name}")
            found[kind] = (done + documented, total + 1, missing)
    return found


def test_the_counter_sees_what_it_should(tmp_path):
    """The rule itself, on a hand-written module: 2 of 3 public functions, 1 of 1 public classes and 1 of 2
    public methods documented (private names, dunders, nested functions and a setter are not counted)."""
    src = tmp_path / "m.py"
    src.write_text('''
def a():
    """Doc."""
    def nested(): pass
def b(): pass
def _private(): pass
try:
    def c():
        """Doc."""
except ImportError:
    pass
class K:
    """Doc."""
    def __init__(self): pass
    def m(self): pass
    @property
    def p(self):
        """Doc."""
    @p.setter
    def p(self, v): pass
    def _hidden(self): pass
class _Hidden:
    def m(self): pass
''')
    rows = list(public_definitions(src))
    by_kind = {k: [(n, d) for kind, n, _, d in rows if kind == k] for k in ("functions", "classes", "methods")}
    assert by_kind["functions"] == [("a", True), ("b", False), ("c", True)]
    assert by_kind["classes"] == [("K", True)]
    assert by_kind["methods"] == [("K.m", False), ("K.p", True)]


@pytest.mark.parametrize("kind", ["functions", "classes", "methods"])
def test_public_api_is_documented(kind):
    done, total, missing = coverage()[kind]
    assert total > 0
    share = done / total
    print(f"{kind}: {done}/{total} documented ({share:.1%})")
    assert share >= THRESHOLD, (f"{kind}: only {done}/{total} ({share:.1%}) have a docstring, need "
                                f"{THRESHOLD:.0%}; undocumented:\n  " + "\n  ".join(missing))


def google_style_warnings(package: str, search_path: Path) -> list[str]:
    """What griffe (the reader of the documentation site's API pages) says while parsing every docstring of
    ``package`` as Google style: a section it cannot read, an argument the signature does not have, an
    argument with neither a type nor an annotation.  The site builds in strict mode, where each is an error."""
    griffe = pytest.importorskip("griffe")
    import logging

    said: list[str] = []

    class Collect(logging.Handler):
        def emit(self, record):
            said.append(record.getMessage())

    handler, logger = Collect(level=logging.WARNING), logging.getLogger("griffe")
    logger.addHandler(handler)
    try:
        root = griffe.load(package, search_paths=[str(search_path)], docstring_parser="google",
                           allow_inspection=False)

        def walk(obj):
            for member in obj.members.values():
                if member.is_alias:
                    continue
                if member.docstring:
                    _ = member.docstring.parsed  # parsing is what warns
                if member.is_module or member.is_class:
                    walk(member)

        if root.docstring:
            _ = root.docstring.parsed
        walk(root)
    finally:
        logger.removeHandler(handler)
    return said


def test_google_style_check_sees_a_bad_docstring(tmp_path):
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "__init__.py").write_text('''
def f(a: int) -> int:
    """Doc.

    Args:
        b: not an argument of f.
    """
    return a
''')
    assert any("'b' does not appear in the function signature" in w for w in google_style_warnings("pkg", tmp_path))


def test_docstrings_read_as_google_style():
    """One docstring style across the package, the one the API reference is rendered with."""
    warnings = google_style_warnings("infomarket", PACKAGE.parent)
    assert not warnings, "docstrings griffe cannot read as Google style:\n  " + "\n  ".join(warnings)


if __name__ == "__main__":  # a report: python tests/test_docstrings.py
    for kind, (done, total, missing) in coverage().items():
        print(f"{kind}: {done}/{total} ({done / total:.1%})" + "".join(f"\n  {m}" for m in missing))
