"""Ctrl-C on a sweep says how many runs are committed where, and the command that resumes (issue 21:
it printed "interrupted" alone)."""
from __future__ import annotations

import os
import pickle
import shlex
import signal
import subprocess
import time

import pytest

from infomarket.cli import main
from infomarket.store import Store

from ..procs import HANG

GRID = """
name = "grid"
steps = 50
runs = 2
seed = 9

[swarm]
robots = 4

[[swarm.groups]]
behaviour = "naive"
count = 4

[sweep.grid]
"payment.information_share" = [0.25, 0.5]
"""


def test_ctrl_c_on_a_sweep_says_what_is_committed_and_how_to_resume(tmp_path, capsys, monkeypatch):
    from infomarket.runner import execute

    (tmp_path / "grid.toml").write_text(GRID)
    real = execute.run_one
    calls = []

    def one(cfg, run, *args, **kw):
        calls.append(run)
        if len(calls) == 3:
            raise KeyboardInterrupt  # Ctrl-C during the third run (one run per task with one worker)
        return real(cfg, run, *args, **kw)

    monkeypatch.setattr(execute, "run_one", one)
    monkeypatch.chdir(tmp_path)
    assert main(["sweep", "grid.toml", "--out", "my store", "--workers", "1", "--seed", "5", "--quiet"]) == 130
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    expected = "infomarket sweep grid.toml --out 'my store' --seed 5 --workers 1 --quiet"  # every option kept
    assert err.strip() == f"infomarket: error: interrupted: 2 of 4 runs committed in my store; resume with: {expected}"
    assert len(Store(tmp_path / "my store").runs()) == 2
    monkeypatch.setattr(execute, "run_one", real)
    assert main(shlex.split(expected)[1:] + ["--quiet"]) == 0  # the command it gave resumes the sweep
    runs = Store(tmp_path / "my store").runs()
    assert len(runs) == 4 and not runs.duplicated(["condition", "run"]).any()


LONG = """
name = "long"
steps = 50
runs = 80
seed = 9

[swarm]
robots = 4

[[swarm.groups]]
behaviour = "naive"
count = 4
"""


def _same_runs(a: Store, b: Store, total: int = 80) -> None:
    """The two stores hold the same runs with the same rows (in whatever parts)."""
    for table in ("robots", "history"):
        x, y = (getattr(s, table)() for s in (a, b))
        order = [c for c in ("condition", "run", "robot", "step") if c in x.columns]
        if order:
            x, y = (t.sort_values(order).reset_index(drop=True) for t in (x, y))
        assert x.equals(y), table
    assert len(a.robots()) == total * 4
    runs = a.runs()
    assert len(runs) == total and not runs.duplicated(["condition", "run"]).any()


def test_ctrl_c_keeps_the_finished_runs_of_the_part_in_progress(tmp_path, capsys, monkeypatch):
    """One worker, 80 runs: tasks of 20 runs, each stepped as a group of 16 then one of 4.  Ctrl-C during the
    first task's second group keeps its first 16 runs (they were thrown away: "0 of 80 runs committed"); the
    same command then completes the sweep with the rows of an uninterrupted one."""
    from infomarket.runner import execute

    (tmp_path / "long.toml").write_text(LONG)
    real, calls = execute.run_together, []

    def together(cfg, group, *args, **kw):
        calls.append(len(group))
        if len(calls) == 2:
            raise KeyboardInterrupt  # Ctrl-C while the first task's second group runs
        return real(cfg, group, *args, **kw)

    monkeypatch.setattr(execute, "run_together", together)
    monkeypatch.chdir(tmp_path)
    argv = ["sweep", "long.toml", "--out", "s", "--workers", "1", "--quiet"]
    assert main(argv) == 130
    assert calls == [16, 4]
    err = capsys.readouterr().err
    assert err.startswith("infomarket: error: interrupted: 16 of 80 runs committed in s;"), err
    assert sorted(Store(tmp_path / "s").runs().run) == list(range(16))
    monkeypatch.setattr(execute, "run_together", real)
    assert main(argv) == 0
    assert main(["sweep", "long.toml", "--out", "whole", "--workers", "1", "--quiet"]) == 0
    _same_runs(Store(tmp_path / "s"), Store(tmp_path / "whole"))


@pytest.mark.parametrize("when", ["before", "after"])
def test_a_stop_during_a_commit_leaves_the_part_committed_once(when, tmp_path, capsys, monkeypatch):
    """Ctrl-C while the first part (20 runs) is being written, before or after its commit record: its runs
    are committed (once: no "already committed" error), and the sweep stops."""
    (tmp_path / "long.toml").write_text(LONG)
    real, calls = Store.write_part, []

    def write_part(self, *args, **kw):
        calls.append(1)
        if len(calls) == 1 and when == "before":
            raise KeyboardInterrupt
        real(self, *args, **kw)
        if len(calls) == 1:
            raise KeyboardInterrupt

    monkeypatch.setattr(Store, "write_part", write_part)
    monkeypatch.chdir(tmp_path)
    assert main(["sweep", "long.toml", "--out", "s", "--workers", "1", "--quiet"]) == 130
    err = capsys.readouterr().err
    assert err.startswith("infomarket: error: interrupted: 20 of 80 runs committed in s;"), err
    assert sorted(Store(tmp_path / "s").runs().run) == list(range(20))


def test_ctrl_c_of_a_pool_sweep_commits_the_runs_its_workers_had_finished(tmp_path, procs):
    """Two workers, 160 runs: tasks of 20 runs (a group of 16, then 4).  Once a worker has kept a finished group of
    a task still in progress (a file in the sweep's temporary folder), Ctrl-C: every run of those groups is
    committed, the message counts what the store holds, no temporary file is left, and the same command
    completes the sweep with the rows of an uninterrupted one."""
    (tmp_path / "long.toml").write_text(LONG.replace("runs = 80", "runs = 160"))
    spill = tmp_path / "tmp"
    spill.mkdir()
    argv = ["sweep", tmp_path / "long.toml", "--out", tmp_path / "s", "--workers", "2", "--quiet"]
    proc = procs.cli(*argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                     env={"TMPDIR": str(spill), "INFOMARKET_COMPILE_NOTICE": "0"})
    deadline, groups = time.monotonic() + HANG, []
    while not groups and proc.poll() is None and time.monotonic() < deadline:
        groups = sorted(spill.glob("infomarket-runs-*/*/*.pkl"))
        time.sleep(0.02)
    assert proc.poll() is None, "the sweep ended before a worker kept a finished group of a part in progress"
    kept = {o.run for path in groups for o in pickle.loads(path.read_bytes())}
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=HANG)
    assert proc.returncode == 130 and procs.leftovers(proc) == [], err
    runs = Store(tmp_path / "s").runs()
    assert kept and kept <= set(runs.run), (sorted(kept), sorted(runs.run))
    assert err.startswith(f"infomarket: error: interrupted: {len(runs)} of 160 runs committed in "), err
    assert list(spill.iterdir()) == []
    argv = [str(a) for a in argv]
    assert main(argv) == 0  # the resume, here: one process less to start
    assert main([*argv[:3], str(tmp_path / "whole"), *argv[4:]]) == 0
    _same_runs(Store(tmp_path / "s"), Store(tmp_path / "whole"), 160)
