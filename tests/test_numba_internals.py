"""The fence around numba's private APIs (infomarket._numba_internals): each internal the package uses is
taken from there, and a numba outside the tested range, or one lacking an internal, fails with one message
naming the numba version and what is wrong."""
from __future__ import annotations

import ast
import tomllib
import types
from pathlib import Path

import numba
import pytest

import infomarket
from infomarket import _numba_internals as ni

PACKAGE = Path(infomarket.__file__).parent
ROOT = PACKAGE.parents[1]


@pytest.mark.parametrize("owner, name, where", ni.USES, ids=[u[1] for u in ni.USES])
def test_each_internal_is_there_in_the_installed_numba(owner, name, where):
    assert ni.require(owner, name, where) is not None


@pytest.mark.parametrize("owner, name, where", ni.USES, ids=[u[1] for u in ni.USES])
def test_a_numba_without_the_internal_is_refused_naming_version_and_attribute(owner, name, where):
    bare = types.SimpleNamespace()  # a numba module (or class) from a release that dropped the internal
    with pytest.raises(ni.UnsupportedNumba) as e:
        ni.require(bare, name, where, version="0.99.0")
    assert str(e.value) == (f"numba 0.99.0 has no {where}.{name}, which infomarket uses; "
                            "infomarket supports numba>=0.68,<0.69")
    assert isinstance(e.value, infomarket.errors.InfomarketError)


@pytest.mark.parametrize("version", ["0.58.1", "0.67.0", "0.69.0", "1.0.0", "0.70.0rc1"])
def test_a_numba_outside_the_range_is_refused(version):
    with pytest.raises(ni.UnsupportedNumba, match=rf"^numba {version} is not supported: infomarket supports "
                                                  r"numba>=0\.68,<0\.69"):
        ni.check_version(version)


@pytest.mark.parametrize("version", ["0.68.0", "0.68.1", "0.68.5rc1"])
def test_a_numba_in_the_range_is_taken(version):
    ni.check_version(version)


def test_the_installed_numba_is_in_the_range():
    ni.check_version(numba.__version__)


def test_pyproject_pins_numba_to_the_range():
    deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    assert [d for d in deps if d.startswith("numba")] == ["numba>=0.68,<0.69"]


PRIVATE_MODULES = ("numba.core.ir_utils", "numba.core.registry", "numba.np.random.generator_core",
                   "numba.np.random.distributions", "numba.core.caching")
PRIVATE_NAMES = ("_add_alias", "alias_func_extensions", "_numba_box_", "_meminfo", "CPUDispatcher", "ir_utils",
                 "generator_core", "next_double", "random_normal", "caching", "_CacheLocator", "IndexDataCacheFile",
                 "CacheImpl", "_locator_classes", "_load_index", "_save_index", "_save_data", "_data_name")


def _private_uses(source: str) -> list[int]:
    """Lines that import a private numba module or name, or reach one as an attribute or a string."""
    lines = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("numba"):
            if node.module in PRIVATE_MODULES or any(a.name in PRIVATE_NAMES for a in node.names):
                lines.append(node.lineno)
        elif isinstance(node, ast.Import) and any(a.name in PRIVATE_MODULES for a in node.names):
            lines.append(node.lineno)
        elif isinstance(node, ast.Attribute) and node.attr in PRIVATE_NAMES:
            lines.append(node.lineno)
        elif isinstance(node, ast.Constant) and node.value in PRIVATE_NAMES:
            lines.append(node.lineno)
    return lines


def test_the_private_use_finder_finds_each_form():
    assert _private_uses("from numba.core import ir_utils\nimport numba.core.registry\n"
                         "x = numba.core.registry.CPUDispatcher\ny = getattr(o, '_meminfo')\nz = 1") == [1, 2, 3, 4]


def test_no_module_but_the_fence_uses_a_private_numba_api():
    offenders = [f"{p.relative_to(PACKAGE)}:{n}" for p in PACKAGE.rglob("*.py") if p.name != "_numba_internals.py"
                 for n in _private_uses(p.read_text())]
    assert offenders == []
