"""``infomarket run`` writes the sweeps' results store: ``figures``, ``store verify`` and a Parquet
dataset reader (DuckDB's layout) read it, and ``simulate`` with the recorded configuration and seed
repeats every run bit for bit.  Two ``run``s into one folder: the second is refused with exit 2."""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.dataset as ds
import pytest

import infomarket as im
from infomarket.cli import main
from infomarket.seeds import run_seed
from infomarket.store import Store

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


# Long enough that it cannot finish before the test interrupts it, even on a loaded machine where the
# second process takes a minute to start (400 runs finished first once, under a load of 10 on 2 cores).
LONG_RUNS = 100_000
LONG = ["fig2B", "--runs", str(LONG_RUNS), "--steps", "15000", "--workers", "1", "--quiet"]


def _cli(out: Path, *extra: str) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(Path(im.__file__).parents[1]),
                                                        os.environ.get("PYTHONPATH", "")])}
    return subprocess.Popen([sys.executable, "-m", "infomarket.cli", "run", *LONG, "--out", str(out), *extra],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                            start_new_session=True)


def _refused(proc: subprocess.Popen, out: Path) -> None:
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 2, err
    assert err.startswith(f"infomarket: error: {out}: another infomarket process is writing this store")
    assert err.count("\n") == 1 and "Traceback" not in err


def _interrupt(proc: subprocess.Popen) -> str:
    os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C: the runs already finished are kept
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    return err


def test_a_second_run_into_the_same_folder_exits_2_and_writes_nothing(tmp_path):
    out = tmp_path / "D"
    first = _cli(out)
    deadline = time.monotonic() + 120
    while not (out / "store.json").exists() and time.monotonic() < deadline:  # written under the lock
        time.sleep(0.02)
    assert first.poll() is None, first.communicate()
    second = _cli(out)  # the very same request: only the lock can refuse it
    _refused(second, out)
    assert first.poll() is None, "the first run should still be running"
    err = _interrupt(first)
    assert "kept the" in err or "nothing kept" in err
    runs = Store(out).runs()  # empty (no columns) when Ctrl-C came before the first commit, e.g. while compiling
    if len(runs):
        assert not runs.duplicated(["experiment", "condition", "run"]).any() and set(runs.experiment) <= {"fig2B"}
        assert set(runs.run) <= set(range(LONG_RUNS))
    else:
        assert "nothing kept" in err
    assert main(["store", "verify", str(out)]) == 0


def test_two_runs_started_at_once_into_a_new_folder_one_is_refused(tmp_path):
    out = tmp_path / "new" / "D"
    procs = [_cli(out), _cli(out)]
    deadline = time.monotonic() + 180
    while all(p.poll() is None for p in procs) and time.monotonic() < deadline:
        time.sleep(0.02)
    done = [p for p in procs if p.poll() is not None]
    assert len(done) == 1, "one of the two should have been refused at once"
    _refused(done[0], out)
    other = next(p for p in procs if p is not done[0])
    assert other.poll() is None
    _interrupt(other)
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


def test_ctrl_c_stops_a_process_pool_run_at_once(tmp_path):
    """Ctrl-C reaches the run and its pool workers (one process group, as from a terminal): the workers
    are ended at once rather than after the tasks already queued to them, finished runs are kept."""
    out = tmp_path / "D"
    proc = subprocess.Popen([sys.executable, "-m", "infomarket.cli", "run", "fig2B", "--runs", "2000", "--steps",
                             "60000", "--workers", "2", "--out", str(out)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
                            env={**os.environ, "PYTHONPATH": str(Path(im.__file__).parents[1])})
    deadline = time.monotonic() + 180
    while not (out / "store.json").exists() and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(3)  # the workers are busy with their first tasks of 16 runs, and one more is queued to each
    assert proc.poll() is None, proc.communicate()
    t0 = time.monotonic()
    err = _interrupt(proc)
    stopped = time.monotonic() - t0
    assert err.startswith("infomarket: error: interrupted") and err.count("\n") == 1
    with pytest.raises(ProcessLookupError):
        os.killpg(proc.pid, 0)  # no worker left behind
    kept = Store(out).runs()
    assert kept.empty or not kept.run.duplicated().any()
    # a task is 16 runs of 60 000 steps (over 5 s): stopping must not wait for the running and queued ones
    assert stopped < 8, f"took {stopped:.1f} s to stop"
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
