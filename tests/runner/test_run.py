"""``infomarket run`` writes the sweeps' results store: ``figures``, ``store verify`` and a Parquet
dataset reader (DuckDB's layout) read it, and ``simulate`` with the recorded configuration and seed
repeats every run bit for bit.  Two ``run``s into one folder: the second is refused with exit 2."""
from __future__ import annotations

import os
import signal
import subprocess
import time
import tomllib
from pathlib import Path

import numpy as np
import pyarrow.dataset as ds
import pytest

import infomarket as im
from infomarket.cli import main
from infomarket.seeds import run_seed
from infomarket.store import Store

from ..procs import HANG

SHIPPED = Path(im.__file__).parent / "experiments" / "paper"
COLUMNS = ("robot", "behaviour", "honest", "drift", "items_collected", "wealth", "wealth_share")


def test_run_store_is_read_by_figures_verify_and_reproduced_by_simulate(tmp_path, capsys):
    master = tomllib.loads((SHIPPED / "fig2B.toml").read_text())["seed"]  # the file's seed, read here
    out, figs = tmp_path / "D", tmp_path / "F"
    assert main(["run", "fig2B", "--runs", "2", "--steps", "300", "--out", str(out), "--workers", "2",
                 "--quiet"]) == 0

    assert main(["store", "verify", str(out)]) == 0
    assert capsys.readouterr().out.strip().endswith("0 damaged, 0 orphan(s)")
    assert main(["figures", str(out), "--out", str(figs)]) == 0
    assert (figs / "fig2.png").stat().st_size > 0
    # the report's provenance table: fig2B, 2 runs, 1 condition, 300 steps
    assert "| fig2B | 2 | 1 | 300 |" in (figs / "report.md").read_text()

    store = Store(out)
    runs = store.runs().sort_values("run").reset_index(drop=True)
    assert runs.experiment.tolist() == ["fig2B", "fig2B"] and runs.condition.tolist() == ["base", "base"]
    assert runs.run.tolist() == [0, 1] and runs.steps.tolist() == [300, 300]
    assert runs.master_seed.tolist() == [master, master] and store.seeds() == {"fig2B": master}
    assert runs.seed.astype(int).tolist() == [run_seed(master, 0, 0), run_seed(master, 1, 0)]
    cfg = store.config("fig2B")
    assert cfg.steps == 300 and cfg.name == "fig2B" and cfg.seed == master and cfg.runs == 2
    assert runs.config_hash.tolist() == [cfg.config_hash()] * 2

    # a Parquet dataset reader sees the same rows (DuckDB reads 'D/robots/*.parquet' the same way)
    arrow = ds.dataset(str(out / "robots"), format="parquet").to_table().to_pandas()
    robots = store.robots()
    assert len(arrow) == len(robots) == 2 * 25

    shipped = im.load_experiment("fig2B")
    for row in runs.itertuples():
        stored = robots[robots.run == row.run].reset_index(drop=True)
        again = im.simulate(cfg, seed=int(row.seed)).robots  # the recorded configuration and seed
        also = im.simulate(shipped, seed=int(row.seed), steps=300).robots  # the shipped file, 300 steps
        for col in COLUMNS:
            assert np.array_equal(stored[col].to_numpy(), again[col].to_numpy()), col
            assert np.array_equal(stored[col].to_numpy(), also[col].to_numpy()), col
    assert robots.items_collected.sum() >= 0 and robots.wealth_share.groupby(robots.run).sum().round(9).eq(1).all()


# More runs than any machine does before the test interrupts them (a hundred thousand runs of 15 000
# steps: hours), so that the command is still running when the test acts.  With one worker the runs are
# stepped in the command's own process, in kernel calls of bounded work between which a signal is acted on.
LONG_RUNS = 100_000
LONG = ["fig2B", "--runs", str(LONG_RUNS), "--steps", "15000", "--workers", "1", "--quiet"]


def _cli(procs, out: Path, *words: str):
    """``infomarket run`` in a process of its own.  Without the notice of a first compile: these tests read
    what a stop or a refusal prints, which must not depend on whether an earlier test compiled the kernel."""
    return procs.cli("run", *(words or LONG), "--out", out, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                     text=True, env={"INFOMARKET_COMPILE_NOTICE": "0"})


def _wait_for(path: Path, proc) -> None:
    """Until ``path`` exists (or ``proc`` ended, or hung for ``HANG``)."""
    deadline = time.monotonic() + HANG
    while not path.exists() and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)


def _refused(proc, out: Path) -> None:
    _, err = proc.communicate(timeout=HANG)
    assert proc.returncode == 2, err
    assert err.startswith(f"infomarket: error: {out}: another infomarket process is writing this store")
    assert err.count("\n") == 1 and "Traceback" not in err


def _interrupt(procs, proc) -> str:
    os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C from a terminal: the runs already finished are kept
    _, err = proc.communicate(timeout=HANG)
    assert proc.returncode == 130, err
    assert procs.leftovers(proc) == []  # no worker or compile left behind
    return err


def test_a_second_run_into_the_same_folder_exits_2_and_writes_nothing(tmp_path, procs):
    out = tmp_path / "D"
    first = _cli(procs, out)
    _wait_for(out / "store.json", first)  # written under the lock
    assert first.poll() is None, first.communicate()
    second = _cli(procs, out)  # the very same request: only the lock can refuse it
    _refused(second, out)
    assert first.poll() is None, "the first run should still be running"
    err = _interrupt(procs, first)
    runs = Store(out).runs()  # empty (no columns) when Ctrl-C came before the first commit
    if len(runs):
        assert err == (f"infomarket: error: interrupted: kept the {len(runs)} of {LONG_RUNS} runs that had finished "
                       f"in the store {out}; the same command again runs only the others\n")
        assert not runs.duplicated(["experiment", "condition", "run"]).any() and set(runs.experiment) == {"fig2B"}
    else:
        assert err == f"infomarket: error: interrupted before any of the {LONG_RUNS} runs finished; nothing kept\n"
    assert main(["store", "verify", str(out)]) == 0


def test_two_runs_started_at_once_into_a_new_folder_one_is_refused(tmp_path, procs):
    out = tmp_path / "new" / "D"
    both = [_cli(procs, out), _cli(procs, out)]
    deadline = time.monotonic() + HANG
    while all(p.poll() is None for p in both) and time.monotonic() < deadline:
        time.sleep(0.02)
    done = [p for p in both if p.poll() is not None]
    assert len(done) == 1, "one of the two should have been refused at once"
    _refused(done[0], out)
    other = next(p for p in both if p is not done[0])
    assert other.poll() is None
    _interrupt(procs, other)
    assert main(["store", "verify", str(out)]) == 0
    assert sorted(p.name for p in out.iterdir()) == sorted(
        ["store.json", "store.lock", "robots", "history", "events", "payments", "sites", "configs", "runs"])


def test_bad_input_writes_nothing(tmp_path, capsys):
    out = tmp_path / "D"
    for argv, message in ((["--steps", "0"], "--steps: must be >= 1"),
                          (["--runs", "-1"], "--runs: must be >= 1"),
                          (["--seed", str(2**63)], "--seed: must be at most 2**63 - 1")):
        with pytest.raises(SystemExit) as exc:
            main(["run", "fig2B", "--out", str(out), *argv])
        assert exc.value.code == 2 and message in capsys.readouterr().err
    every = tomllib.loads((SHIPPED / "fig5.toml").read_text())["history_every"]  # 100
    assert main(["run", "fig5", "--steps", "10", "--out", str(out)]) == 2  # shorter than its history period
    err = capsys.readouterr().err
    assert err == f"infomarket: error: --steps 10: history_every = {every} must be at most steps = 10\n"
    assert main(["run", "no_such_experiment", "--out", str(out)]) == 2
    assert capsys.readouterr().err.startswith("infomarket: error: ")
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["run", "fig2B", "--runs", "1", "--steps", "10", "--out", str(f)]) == 2
    assert "exists and is not a directory" in capsys.readouterr().err and f.read_text() == "x"
    assert not out.exists()


def test_ctrl_c_stops_a_process_pool_run_and_its_workers(tmp_path, procs):
    """Ctrl-C reaches the run alone (its workers are in process groups of their own), which ends its
    workers itself, keeps what had finished and leaves no process behind (how soon: tools/sigint_proof.py)."""
    out = tmp_path / "D"
    proc = _cli(procs, out, "fig2B", "--runs", str(LONG_RUNS), "--steps", "15000", "--workers", "2")
    deadline = time.monotonic() + HANG
    while len(procs.leftovers(proc)) < 3 and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)  # until the pool's two workers are there, taking their first tasks
    assert proc.poll() is None, proc.communicate()
    err = _interrupt(procs, proc)
    assert err.startswith("infomarket: error: interrupted") and err.count("\n") == 1
    kept = Store(out).runs()
    assert kept.empty or not kept.run.duplicated().any()
    assert main(["store", "verify", str(out)]) == 0


def test_run_batch_is_the_same_runs_kept_in_memory(tmp_path):
    """``run_batch`` (the Python API the headline tests use) and ``infomarket run`` make the same tasks with
    the same seeds: the in-memory rows equal the store's, on any executor."""
    from concurrent.futures import ThreadPoolExecutor

    from infomarket.runner import run_batch

    out = tmp_path / "D"
    assert main(["run", "fig2D", "--runs", "3", "--steps", "400", "--seed", "21", "--out", str(out),
                 "--workers", "1", "--quiet"]) == 0
    stored = Store(out).robots().drop(columns=["experiment", "condition"])
    cfg = im.load_experiment("fig2D")
    for kw in ({"workers": 1}, {"workers": 2}, {"executor": ThreadPoolExecutor(2)}):
        got = run_batch(cfg, 3, 21, steps=400, **kw).robots
        assert got.seed.astype(int).tolist() == [run_seed(21, r, 0) for r in (0, 1, 2) for _ in range(25)]
        for col in COLUMNS:
            assert np.array_equal(got[col].to_numpy(), stored[col].to_numpy()), (kw, col)
