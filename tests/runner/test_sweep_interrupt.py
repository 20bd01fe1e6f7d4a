"""Ctrl-C on a sweep says how many runs are committed where, and the command that resumes (issue 21:
it printed "interrupted" alone)."""
from __future__ import annotations

import shlex

from infomarket.cli import main
from infomarket.store import Store

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
