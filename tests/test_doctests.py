"""The examples in the docstrings run, and give what they show: every module of the package whose source
holds a ``>>>`` example is run through ``doctest``, so an example added anywhere is checked without
being listed here, and an example that goes stale fails the suite instead of misleading a reader."""
from __future__ import annotations

import doctest
import importlib
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "infomarket"


def _modules_with_examples() -> list[str]:
    names = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if ">>>" not in path.read_text(encoding="utf-8"):
            continue
        parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        names.append(".".join(parts))
    return names


MODULES = _modules_with_examples()


def test_some_modules_have_examples():
    """The main entry points carry examples (so the loop below cannot pass by finding nothing)."""
    assert {"infomarket.engine.simulation", "infomarket.registry", "infomarket.store.results"} <= set(MODULES)


@pytest.mark.parametrize("name", MODULES)
def test_examples_run(name):
    module = importlib.import_module(name)
    result = doctest.testmod(module, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE, verbose=False)
    assert result.attempted > 0, f"{name}: a '>>>' in its source but no example doctest could find"
    assert result.failed == 0, f"{name}: {result.failed} of {result.attempted} examples failed (output above)"
