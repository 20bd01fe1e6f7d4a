"""The version is written in one place, ``src/infomarket/_version.py``; pyproject.toml reads it from there."""
from __future__ import annotations

import re
import tomllib
from pathlib import Path

import infomarket

ROOT = Path(__file__).resolve().parents[1]
VERSION_LINE = re.compile(r'^__version__\s*=\s*["\']([^"\']+)["\']', re.MULTILINE)


def test_pyproject_takes_the_version_from_the_package():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert "version" not in project["project"], "pyproject.toml writes a version of its own"
    assert "version" in project["project"].get("dynamic", [])
    source = ROOT / project["tool"]["hatch"]["version"]["path"]
    assert source == ROOT / "src" / "infomarket" / "_version.py"
    assert VERSION_LINE.findall(source.read_text()) == [infomarket.__version__]


def test_no_other_file_writes_a_version():
    writers = [str(p.relative_to(ROOT)) for p in (ROOT / "src").rglob("*.py") if VERSION_LINE.search(p.read_text())]
    assert writers == ["src/infomarket/_version.py"]


def test_the_package_says_it_is_typed_and_offers_a_sql_extra():
    # issue 21: no py.typed marker; DuckDB (used in docs/sweeps.md) installed by no extra
    import tomllib
    from importlib import resources
    from pathlib import Path

    assert resources.files("infomarket").joinpath("py.typed").is_file()
    project = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml").read_text())["project"]
    assert any(dep.startswith("duckdb") for dep in project["optional-dependencies"]["sql"])
