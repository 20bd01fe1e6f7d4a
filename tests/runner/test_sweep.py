"""Sweeps into a results store: plans, seeds, executors, resuming, refusing bad input."""
import os
import signal
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import pandas as pd
import pytest

import infomarket as im
from infomarket.cli import main
from infomarket.errors import ConfigError
from infomarket.runner.plan import conditions
from infomarket.runner.sweep import _alike, plan, run_sweep
from infomarket.store import Store

from ..procs import HANG

SWEEP = """
name = "tiny"
steps = {steps}
runs = {runs}
seed = 3

[swarm]
robots = 10

[[swarm.groups]]
behaviour = "sceptical"
count = 9

[[swarm.groups]]
behaviour = "scaboteur"
count = 1

[payment]
scheme = "outlier"
stake = 0.04

[sweep.grid]
"swarm.groups[1].params.rotation_angle" = [0.0, 90.0]

[[sweep.axes.market]]
value = "staking"
set = {{ "payment.stake" = 0.04 }}

[[sweep.axes.market]]
value = "no_staking"
set = {{ "payment.scheme" = "delayed", "payment.stake" = 0.0 }}
"""


def write(tmp_path: Path, steps=600, runs=3, text=SWEEP) -> Path:
    p = tmp_path / "tiny.toml"
    p.write_text(text.format(steps=steps, runs=runs))
    return p


def test_conditions_are_the_product_of_grid_and_axes(tmp_path):
    conds = conditions(im.load_experiment(write(tmp_path)))
    assert [c.id for c in conds] == ["market=staking,rotation_angle=0.0", "market=no_staking,rotation_angle=0.0",
                                     "market=staking,rotation_angle=90.0", "market=no_staking,rotation_angle=90.0"]
    c = conds[3]
    assert c.config.payment.scheme == "delayed" and c.config.swarm.groups[1].params["rotation_angle"] == 90.0
    assert c.keys == {"rotation_angle": 90.0, "market": "no_staking"}
    # seeds depend on the condition's id only: adding grid values leaves existing conditions' seeds alone
    more = write(tmp_path, text=SWEEP.replace("[0.0, 90.0]", "[0.0, 45.0, 90.0]"))
    seeds = {c.id: c.seed(1) for c in conditions(im.load_experiment(more))}
    assert all(seeds[c.id] == c.seed(1) for c in conds)


def test_unknown_condition_key_and_empty_grid(tmp_path):
    bad = write(tmp_path, text=SWEEP.replace("swarm.groups[1].params.rotation_angle", "swarm.groupz[1].count"))
    with pytest.raises(ConfigError, match="unknown condition key 'swarm.groupz"):
        conditions(im.load_experiment(bad))
    empty = write(tmp_path, text=SWEEP.replace("[0.0, 90.0]", "[]"))
    with pytest.raises(ConfigError, match="empty list"):
        im.load_experiment(empty)


def test_a_run_rerun_alone_equals_its_row_in_the_sweep(tmp_path):
    exp = im.load_experiment(write(tmp_path))
    store = Store(tmp_path / "s")
    run_sweep(plan([exp]), store, workers=2)
    robots = store.robots()
    c = conditions(exp)[2]
    alone = im.simulate(c.config, seed=c.seed(1)).robots
    row = robots[(robots.condition == c.id) & (robots.run == 1)].reset_index(drop=True)
    for col in ("seed", "robot", "drift", "items_collected", "wealth", "wealth_share"):
        assert (row[col].to_numpy() == alone[col].to_numpy()).all(), col


def test_every_executor_gives_the_same_store(tmp_path):
    exp = im.load_experiment(write(tmp_path, runs=2))
    tables = []
    for k, kw in enumerate(({"workers": 1}, {"workers": 2})):
        s = Store(tmp_path / f"s{k}")
        run_sweep(plan([exp]), s, **kw)
        tables.append(s.robots())
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        s = Store(tmp_path / "dask")
        run_sweep(plan([exp]), s, executor=client.get_executor(pure=False))
        tables.append(s.robots())
    for t in tables[1:]:
        pd.testing.assert_frame_equal(tables[0], t, check_exact=True)


def test_resume_skips_completed_runs_and_removes_orphans(tmp_path):
    exp = im.load_experiment(write(tmp_path))
    store = Store(tmp_path / "s")
    first = run_sweep(plan([exp]), store, workers=1)
    assert first.done == 12 and first.skipped == 0
    runs_parts = sorted((store.root / "runs").glob("*.parquet"))
    runs_parts[0].unlink()  # as if killed between writing a part's robots and its commit record
    again = run_sweep(plan([exp]), store, workers=1)
    assert again.skipped == 12 - again.done and 0 < again.done < 12
    runs = store.runs()
    assert len(runs) == 12 and not runs.duplicated(["experiment", "condition", "run"]).any()
    assert len(store.robots()) == 12 * 10
    assert run_sweep(plan([exp]), store, workers=1).done == 0


def test_store_of_another_configuration_is_refused_untouched(tmp_path, capsys):
    path = write(tmp_path)
    out = tmp_path / "s"
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    before = {p: p.stat().st_mtime_ns for p in out.rglob("*")}
    write(tmp_path, steps=700)
    assert main(["sweep", str(path), "--out", str(out), "--workers", "1", "--quiet"]) == 2
    assert "another configuration" in capsys.readouterr().err
    assert {p: p.stat().st_mtime_ns for p in out.rglob("*")} == before


def test_bad_targets_exit_2(tmp_path, capsys):
    path = write(tmp_path)
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["sweep", str(path), "--out", str(f), "--quiet"]) == 2
    assert "not a directory" in capsys.readouterr().err
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("mine")
    assert main(["sweep", str(path), "--out", str(other), "--quiet"]) == 2
    assert "not an infomarket results store" in capsys.readouterr().err
    assert (other / "notes.txt").read_text() == "mine"
    assert main(["sweep", str(path), "--out", str(tmp_path / "d"), "--scheduler", "tcp://127.0.0.1:9", "--quiet"]) == 2
    assert "no Dask scheduler answers" in capsys.readouterr().err
    assert not (tmp_path / "d").exists()  # nothing written


def test_killed_sweep_resumes_with_every_run_exactly_once(tmp_path, procs):
    path = write(tmp_path, steps=3000, runs=12)
    out = tmp_path / "s"
    cmd = [sys.executable, "-m", "infomarket.cli", "sweep", str(path), "--out", str(out), "--workers", "2"]
    log = open(tmp_path / "log.txt", "w")
    proc = procs.start(cmd, stdout=log, stderr=log)
    deadline = time.monotonic() + HANG
    while proc.poll() is None and time.monotonic() < deadline and len(list((out / "runs").glob("*.parquet"))) < 2:
        time.sleep(0.05)
    assert proc.poll() is None, (tmp_path / "log.txt").read_text()  # still running: kill it now
    for pid in procs.leftovers(proc):  # the sweep and its workers (in process groups of their own), mid-way
        os.kill(pid, signal.SIGKILL)
    proc.wait()
    committed = len(Store(out).runs())
    assert 0 < committed < 48, "the kill should land in the middle of the sweep"
    assert procs.run(cmd + ["--quiet"]).returncode == 0
    runs = Store(out).runs()
    assert len(runs) == 48 and not runs.duplicated(["experiment", "condition", "run"]).any()
    robots = Store(out).robots()
    assert len(robots) == 48 * 10 and not robots.duplicated(["condition", "run", "robot"]).any()
    assert not list(out.rglob("*.tmp"))


def test_conditions_are_labelled_together_only_when_one_column_types_their_keys_as_each_alone():
    """A part's conditions get their key columns by repetition when their keys are the same and each key
    has values of one type; otherwise (an int beside a float, a key one lacks) each is labelled alone and
    pandas reconciles the columns, as it did."""
    def members(*keys):
        return [(SimpleNamespace(keys=k), (0,)) for k in keys]

    assert _alike(members({"a": 1, "m": "x"}, {"a": 2, "m": "y"}))
    assert not _alike(members({"a": 1}, {"a": 2.5}))
    assert not _alike(members({"a": 1}, {"b": 1}))
    assert not _alike(members({"a": 1, "b": 2}, {"b": 2, "a": 1}))  # another column order


SAMPLED = """
name = "sampled"
steps = 2
runs = 1
seed = 4

[swarm]
robots = 6

[[swarm.groups]]
behaviour = "naive"
count = 6

[sweep.sample]
method = "sobol"
samples = 2
outputs = ["items"]

[sweep.sample.bounds]
"payment.stake" = [0.0, 0.1]
"robot.noise_sd" = [0.0, 0.1]
"""


def test_a_sampled_design_labels_each_run_with_its_own_point(tmp_path):
    """Many conditions in one part: every robot row carries its own condition's id and sampled value."""
    p = tmp_path / "sampled.toml"
    p.write_text(SAMPLED)
    out = tmp_path / "s"
    assert main(["sweep", str(p), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    store = Store(out)
    runs, robots = store.runs(), store.robots()
    assert len(runs) == 12 and len(list((out / "runs").glob("*.parquet"))) < len(runs)  # grouped into parts
    for _, r in runs.iterrows():
        mine = robots[(robots.condition == r.condition) & (robots.run == r.run)]
        assert len(mine) == 6 and (mine.experiment == "sampled").all()
        assert ((mine.point == r.point) & (mine.stake == r.stake) & (mine.noise_sd == r.noise_sd)).all()
    assert runs.point.nunique() == 12 and runs.stake.nunique() > 2 and runs.noise_sd.nunique() > 2
