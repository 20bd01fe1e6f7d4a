"""Tests start processes only through tests/procs.py, which leaves none behind, passed or failed."""
from __future__ import annotations

import ast
import sys
from pathlib import Path

from .procs import session_members

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent
#: What starts a process, by module: the functions a test file must not call itself.
STARTERS = {"subprocess": {"Popen", "run", "call", "check_call", "check_output", "getoutput", "getstatusoutput"},
            "os": {"fork", "forkpty", "system", "popen", "posix_spawn", "posix_spawnp", "spawnl", "spawnle",
                   "spawnlp", "spawnlpe", "spawnv", "spawnve", "spawnvp", "spawnvpe", "execv", "execve"},
            "multiprocessing": {"Process", "Pool", "get_context"}, "pty": {"spawn", "fork"}}


def starts_a_process(source: str) -> list[str]:
    """Where ``source`` starts a process itself: ``module.function(...)`` calls and ``from module import
    function`` of the ``STARTERS``."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                and node.attr in STARTERS.get(node.value.id, ()):
            found.append(f"line {node.lineno}: {node.value.id}.{node.attr}")
        elif isinstance(node, ast.ImportFrom) and node.module in STARTERS:
            found += [f"line {node.lineno}: from {node.module} import {a.name}" for a in node.names
                      if a.name in STARTERS[node.module]]
    return found


def test_no_test_file_starts_a_process_itself():
    offenders = {str(p.relative_to(ROOT)): hits for p in sorted(TESTS.rglob("*.py"))
                 if p.name != "procs.py" and (hits := starts_a_process(p.read_text()))}
    assert offenders == {}, "start processes with the procs fixture (tests/procs.py): " + repr(offenders)


def test_the_check_finds_each_way_of_starting_a_process():
    src = ("import subprocess, os\nfrom subprocess import Popen\nsubprocess.run(['x'])\nos.fork()\n"
           "import multiprocessing\nmultiprocessing.Process(target=print)\nsubprocess.PIPE\n")
    assert starts_a_process(src) == ["line 2: from subprocess import Popen", "line 3: subprocess.run",
                                     "line 4: os.fork", "line 6: multiprocessing.Process"]


# A test that starts a process, which forks a grandchild into a process group of its own (as a pool
# worker does); both write their pids and wait forever.  The test then passes or fails.
INNER = '''
import subprocess, sys, time
from pathlib import Path

CHILD = """
import os, sys, time
pid = os.fork()
if pid == 0:
    os.setpgid(0, 0)
    open(sys.argv[1] + ".grandchild", "w").write(str(os.getpid()))
else:
    open(sys.argv[1] + ".child", "w").write(str(os.getpid()))
while True:
    time.sleep(1000)
"""


def test_starts_and_{outcome}(procs, tmp_path):
    mark = Path({folder!r}) / "pids"
    procs.start([sys.executable, "-c", CHILD, str(mark)])
    while not (Path(str(mark) + ".child").exists() and Path(str(mark) + ".grandchild").exists()):
        time.sleep(0.01)
    assert {passes}
'''


def _alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat[stat.rindex(")") + 2] != "Z"


def test_the_fixture_kills_every_process_it_started_whether_the_test_passes_or_fails(tmp_path, procs):
    (tmp_path / "conftest.py").write_text(f"import sys\nsys.path.insert(0, {str(ROOT)!r})\n"
                                          "from tests.conftest import procs  # noqa: F401\n")
    for outcome, passes, code in (("passes", True, 0), ("fails", False, 1)):
        folder = tmp_path / outcome
        folder.mkdir()
        (tmp_path / f"test_{outcome}.py").write_text(INNER.format(outcome=outcome, folder=str(folder), passes=passes))
        done = procs.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:randomly",
                          "-n", "0", "--rootdir", tmp_path, tmp_path / f"test_{outcome}.py"], cwd=tmp_path)
        assert done.returncode == code, done.stdout + done.stderr
        pids = [int((folder / f"pids.{who}").read_text()) for who in ("child", "grandchild")]
        assert not any(_alive(pid) for pid in pids), (outcome, pids)
        assert all(session_members(pid) == [] for pid in pids)
