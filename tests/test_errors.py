"""Every error infomarket raises on purpose is an ``InfomarketError`` (one root for callers to catch).

The source is read with ``ast``, not run: a ``raise`` of a built-in exception class anywhere in
``src/infomarket`` fails, as does an exception class that derives from a built-in one alone.  A leaf of
``infomarket.errors`` that also derives from the built-in (``ConfigError`` is a ``ValueError``,
``RuleError`` a ``TypeError``...) keeps ``except ValueError`` callers working.
"""
from __future__ import annotations

import ast
import builtins
import inspect
from pathlib import Path

import pytest

import infomarket.errors as errors
from infomarket.errors import EXIT_FAILED, EXIT_USAGE, InfomarketError, exit_code

SRC = Path(__file__).resolve().parents[1] / "src" / "infomarket"
BUILTIN_EXCEPTIONS = frozenset(name for name, obj in vars(builtins).items()
                               if isinstance(obj, type) and issubclass(obj, BaseException))
#: Not errors: SystemExit ends the program with a status, KeyboardInterrupt (runner.batch.BatchInterrupted)
#: carries Ctrl-C on; neither derives from Exception, so ``except Exception`` must not catch them.
NOT_ERRORS = frozenset({"SystemExit", "KeyboardInterrupt", "GeneratorExit"})

#: Files (relative to src/infomarket) that may still raise a built-in exception.  Each is in a folder that
#: another engineer owns; the replacement for every line is listed in issue 20, item 4.  Remove a file
#: once it is converted: the test fails for a listed file that no longer raises one, so the list only
#: shrinks, and when it is empty the whole package is under the root.
STILL_ALLOWED: frozenset = frozenset()


def _name(node: ast.expr) -> str | None:
    """``ValueError`` for ``ValueError``, ``ValueError(...)`` and ``builtins.ValueError(...)``."""
    if isinstance(node, ast.Call):
        node = node.func
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "builtins":
        return node.attr
    return None


class _Raises(ast.NodeVisitor):
    """Every ``raise`` of a built-in exception class, with the function it is in."""

    def __init__(self) -> None:
        self.found: list[tuple[int, str]] = []
        self.functions: list[str] = []

    def _function(self, node) -> None:
        self.functions.append(node.name)
        self.generic_visit(node)
        self.functions.pop()

    visit_FunctionDef = visit_AsyncFunctionDef = _function

    def visit_Raise(self, node: ast.Raise) -> None:
        name = None if node.exc is None else _name(node.exc)  # a bare ``raise`` re-raises: allowed
        if name in BUILTIN_EXCEPTIONS and name not in NOT_ERRORS:
            # a module's ``__getattr__`` must raise AttributeError: that is Python's protocol, not an error report
            if not (name == "AttributeError" and self.functions[-1:] == ["__getattr__"]):
                self.found.append((node.lineno, name))
        self.generic_visit(node)


def builtin_raises(source: str) -> list[tuple[int, str]]:
    v = _Raises()
    v.visit(ast.parse(source))
    return v.found


def classes_outside_the_root(source: str) -> list[tuple[int, str]]:
    """Exception classes whose bases are built-in exceptions only (so not under InfomarketError)."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ClassDef):
            names = [_name(b) for b in node.bases]
            if node.name == "InfomarketError" or any(n in NOT_ERRORS for n in names):
                continue  # the root itself; an interruption, not an error
            if any(n in BUILTIN_EXCEPTIONS for n in names) and all(n in BUILTIN_EXCEPTIONS for n in names):
                out.append((node.lineno, node.name))
    return out


def _sources() -> dict[str, str]:
    return {p.relative_to(SRC).as_posix(): p.read_text() for p in sorted(SRC.rglob("*.py"))}


def test_the_checks_see_what_they_look_for():
    found = builtin_raises("def f(x):\n"
                           "    if x: raise ValueError('bad')\n"
                           "    if x: raise builtins.TypeError\n"
                           "    try: pass\n"
                           "    except OSError as e: raise KeyError('k') from e\n"
                           "    raise\n")
    assert found == [(2, "ValueError"), (3, "TypeError"), (5, "KeyError")]
    assert builtin_raises("def f(e):\n"
                          "    raise ConfigError('x') from e\n"
                          "    raise e\n"
                          "    raise SystemExit(2)\n"
                          "def __getattr__(name):\n"
                          "    raise AttributeError(name)\n") == []
    assert builtin_raises("def g(name):\n    raise AttributeError(name)\n") == [(2, "AttributeError")]
    assert classes_outside_the_root("class A(ValueError): pass\n"
                                    "class B(InfomarketError, ValueError): pass\n"
                                    "class C(B): pass\n"
                                    "class D(KeyboardInterrupt): pass\n") == [(1, "A")]


def test_the_package_raises_no_builtin_exception():
    offenders = {f"{path}:{line}: raise {name}" for path, text in _sources().items() if path not in STILL_ALLOWED
                 for line, name in builtin_raises(text)}
    assert not offenders, ("raise an InfomarketError subclass (infomarket.errors) instead:\n"
                           + "\n".join(sorted(offenders)))


def test_the_still_allowed_list_only_names_files_that_need_it():
    sources = _sources()
    stale = sorted(path for path in STILL_ALLOWED if not builtin_raises(sources.get(path, "")))
    assert not stale, f"converted (or gone): remove from STILL_ALLOWED: {stale}"


def test_every_exception_class_of_the_package_is_under_the_root():
    outside = {f"{path}:{line}: class {name}" for path, text in _sources().items()
               for line, name in classes_outside_the_root(text)}
    assert not outside, "derive from InfomarketError (or a leaf of it) too:\n" + "\n".join(sorted(outside))


LEAVES = [cls for _, cls in inspect.getmembers(errors, inspect.isclass)
          if issubclass(cls, BaseException) and cls.__module__ == errors.__name__]


@pytest.mark.parametrize("cls", LEAVES, ids=lambda c: c.__name__)
def test_each_leaf_is_an_infomarket_error_with_the_exit_status_of_its_kind(cls):
    assert issubclass(cls, InfomarketError)
    err = cls("message")
    assert str(err) == "message"
    assert exit_code(err) == (EXIT_USAGE if isinstance(err, ValueError) else EXIT_FAILED)
