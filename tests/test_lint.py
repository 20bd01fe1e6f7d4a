"""The linters CI runs (``make lint``: ruff on src and tests, mypy on the public API; pyproject.toml configures
both): CI runs them before the suite and stops on a finding, and their configuration catches what it is meant
to.  ruff is fast, so the suite also checks the tree is clean by it; mypy's clean run is ``make lint``'s (a cold
run takes a minute, too long to repeat in every suite)."""
from __future__ import annotations

import re
import sys
import tokenize
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PYPROJECT = ROOT / "pyproject.toml"
#: A noqa comment: its codes, then the rest of the comment (the reason).
NOQA = re.compile(r"#\s*noqa\b(:\s*[A-Z]+[0-9]+(?:\s*,\s*[A-Z]+[0-9]+)*)?(.*)")

# One lint error of each kind the configuration is chosen for: an unused import (pyflakes), a line over the
# project's 120 columns (pycodestyle), a blind except with no reason (BLE), a loop variable a closure reads
# late (bugbear), and a noqa that silences nothing (RUF100).
BAD = '''import os


def f(xs):
    fs = []
    for x in xs:
        fs.append(lambda: x)
    try:
        return fs, "''' + "x" * 110 + '''"
    except Exception:
        return None


y = 1  # ''' + '''noqa: E731
'''
FOUND = {"F401", "E501", "BLE001", "B023", "RUF100"}


def _ruff(procs, *args: str):
    return procs.run([sys.executable, "-m", "ruff", "check", "--no-cache", "--config", str(PYPROJECT), *args],
                     cwd=ROOT)


def test_ci_runs_the_linters_before_the_suite_and_stops_on_a_finding():
    ci = (ROOT / ".ci" / "run").read_text()
    commands = [line.split("#")[0].strip() for line in ci.splitlines()]
    assert "set -euo pipefail" in commands  # a failing command ends the run
    assert commands.index("make lint") < commands.index("make test")
    recipe = re.search(r"^lint:.*\n((?:\t.*\n)+)", (ROOT / "Makefile").read_text(), re.MULTILINE)
    assert recipe is not None, "the Makefile has no lint target"
    assert [line.strip() for line in recipe.group(1).splitlines()] == ["$(BIN)/ruff check src tests", "$(BIN)/mypy"]


def test_the_linters_are_installed_with_the_dev_extra():
    dev = tomllib.loads(PYPROJECT.read_text())["project"]["optional-dependencies"]["dev"]
    assert {re.split(r"[<>=\[ ]", d)[0] for d in dev} >= {"ruff", "mypy"}


def test_ruff_finds_each_kind_of_error_it_is_configured_for(procs, tmp_path):
    (tmp_path / "bad.py").write_text(BAD)
    done = _ruff(procs, "--output-format", "concise", str(tmp_path / "bad.py"))
    assert done.returncode == 1, done.stdout + done.stderr
    assert set(re.findall(r"bad\.py:\d+:\d+: ([A-Z]+\d+)", done.stdout)) == FOUND, done.stdout


def test_src_and_tests_are_clean_by_ruff(procs):
    done = _ruff(procs, "src", "tests")
    assert done.returncode == 0, done.stdout + done.stderr


def test_every_noqa_says_why():
    """A kept ``# noqa`` comment names its codes and, after them, why it is kept."""
    bare = []
    for path in [*(ROOT / "src").rglob("*.py"), *(ROOT / "tests").rglob("*.py")]:
        if "noqa" not in path.read_text():
            continue
        with tokenize.open(path) as f:
            comments = [t for t in tokenize.generate_tokens(f.readline) if t.type == tokenize.COMMENT]
        for t in comments:
            m = NOQA.search(t.string)
            if m and (not m.group(1) or len(m.group(2).strip(" -()")) < 8):
                bare.append(f"{path.relative_to(ROOT)}:{t.start[0]}: {t.string}")
    assert bare == []


def test_mypy_checks_the_public_api(procs, tmp_path):
    """The configured files exist, and a type error in a module like them fails mypy (the configuration,
    with a cache of its own)."""
    config = tomllib.loads(PYPROJECT.read_text())["tool"]["mypy"]
    assert all((ROOT / f).exists() for f in config["files"]), config["files"]
    checked = {Path(f).name for f in config["files"]}
    assert {"__init__.py", "registry.py", "checks.py", "config", "store", "runner", "rl"} <= checked
    (tmp_path / "typed.py").write_text("def half(n: int) -> int:\n    return n / 2\n")
    done = procs.run([sys.executable, "-m", "mypy", "--config-file", str(PYPROJECT), "--cache-dir",
                      str(tmp_path / "cache"), str(tmp_path / "typed.py")], cwd=ROOT)
    assert done.returncode == 1 and 'Incompatible return value type (got "float", expected "int")' in done.stdout, \
        done.stdout + done.stderr
