"""``infomarket attack-search`` at tiny size: it completes, resumes after SIGKILL with no evaluation lost
or repeated, gives the same results inline and on Dask, uses common random numbers, refuses bad input."""
import json
import signal
import subprocess
import time
from pathlib import Path

import pytest

from infomarket.cli import main
from infomarket.search import space
from infomarket.search.study import load as load_study
from infomarket.store import Store

from ..procs import HANG

TINY = ["attack-search", "attack_search", "--defence", "staking", "--byzantines", "3", "--budget", "4",
        "--popsize", "2", "--runs", "2", "--heldout-runs", "2", "--best", "1", "--steps", "2500",
        "--transitory", "0", "--seed", "7"]
BASELINES = len(load_study.__globals__["load_declarations"]()["baselines"])  # the hand-written + truthful
# the start (every hand-written attack) and 2 generations x 2 candidates, 2 runs each; then (1 searched +
# every declared baseline) x 2 held-out runs
PLANNED = (BASELINES - 1) * 2 + 2 * 2 * 2 + (1 + BASELINES) * 2


def _report(out: Path) -> dict:
    data = json.loads((out / "report.json").read_text())
    data.pop("wall_seconds")
    return data


def _runs_table(out: Path):
    runs = Store(out / "store").runs()
    return runs.sort_values(["condition", "run"]).reset_index(drop=True)


@pytest.fixture(scope="module")
def inline(tmp_path_factory):
    out = tmp_path_factory.mktemp("inline") / "search"
    assert main(TINY + ["--workers", "1", "--quiet", "--out", str(out)]) == 0
    return out


def test_a_tiny_search_completes_with_every_run_once(inline):
    runs = _runs_table(inline)
    assert len(runs) == PLANNED and not runs.duplicated(["experiment", "condition", "run"]).any()
    rep = _report(inline)
    assert [(c["defence"], c["byzantines"], c["evaluations"]) for c in rep["cells"]] == [("staking", 3, 4)]
    assert set(rep["cells"][0]["params"]) == set(space.NAMES)
    assert rep["cells"][0]["start_from"] in load_study.__globals__["load_declarations"]()["baselines"]


def test_candidates_of_a_generation_share_seeds_and_held_out_seeds_are_new(inline):
    runs = _runs_table(inline)
    seeds = {cond: tuple(g.sort_values("run").seed) for cond, g in runs.groupby("condition")}
    gen = {c: s for c, s in seeds.items() if "phase=search" in c}
    g0 = {s for c, s in gen.items() if "gen=0" in c}
    g1 = {s for c, s in gen.items() if "gen=1" in c}
    held = {s for c, s in seeds.items() if "phase=heldout" in c}
    start = {s for c, s in seeds.items() if "phase=start" in c}
    assert len(g0) == len(g1) == len(held) == len(start) == 1  # one seed set per generation, start, held-out
    assert len(g0 | g1 | held | start) == 4
    assert not set(next(iter(held))) & (set(next(iter(g0))) | set(next(iter(g1))))


def test_a_killed_search_resumes_without_losing_or_repeating_an_evaluation(inline, tmp_path, capsys, procs):
    out = tmp_path / "search"
    proc = procs.cli(*TINY, "--workers", "1", "--quiet", "--out", out, env={"INFOMARKET_COMPILE_NOTICE": "0"},
                     stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    runs_dir = out / "store" / "runs"
    deadline = time.monotonic() + HANG
    while time.monotonic() < deadline and proc.poll() is None:
        if runs_dir.exists() and len(list(runs_dir.glob("part-*.parquet"))) >= 3:
            break
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert proc.returncode == -signal.SIGKILL, proc.stderr.read().decode()[-2000:]  # killed mid-search
    kept = len(Store(out / "store").completed_runs())
    assert 0 < kept < PLANNED
    capsys.readouterr()
    assert main(TINY + ["--workers", "1", "--out", str(out)]) == 0
    made = [line for line in capsys.readouterr().out.splitlines() if line.startswith("attack-search:")][-1]
    assert made.startswith(f"attack-search: {PLANNED - kept} runs made now, {kept} found in the store")
    runs = _runs_table(out)
    assert len(runs) == PLANNED and not runs.duplicated(["experiment", "condition", "run"]).any()
    assert _report(out) == _report(inline)  # the optimiser's state was rebuilt exactly


def test_the_same_search_on_dask_gives_identical_results(inline, tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        out = tmp_path / "dask"
        assert main(TINY + ["--dask", cluster.scheduler_address, "--quiet", "--out", str(out)]) == 0
    assert _report(out) == _report(inline)
    a, b = Store(inline / "store").robots(), Store(out / "store").robots()
    key = ["condition", "run", "robot"]
    cols = ["condition", "run", "robot", "items_collected", "wealth"]
    assert a.sort_values(key)[cols].reset_index(drop=True).equals(b.sort_values(key)[cols].reset_index(drop=True))


@pytest.mark.parametrize("option, words", [
    (["--defence", "nope"], ["--defence nope", "allowed: outlier, staking"]),
    (["--byzantines", "5"], ["--byzantines 5", "allowed: 1, 3, 8"]),
])
def test_bad_cells_are_refused_before_anything_is_written(tmp_path, capsys, option, words):
    out = tmp_path / "never"
    args = ["attack-search", "attack_search", *option, "--out", str(out)]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert all(w in err for w in words) and "Traceback" not in err
    assert not out.exists()


def test_a_pending_defence_waits_for_its_scheme(tmp_path, capsys, monkeypatch):
    """A defence declared in `[pending_defences]` joins the cells only once its scheme is registered:
    unregistered it is refused, saying which scheme it waits for; registered, it is a cell.  (`distinct`
    waited so for `outlier_distinct`; now registered, it is on the experiment's own axis.)"""
    import infomarket as im
    from infomarket.search import study

    declared = study.load_declarations()
    pending = {"later": {"requires": "outlier_distinct", "set": {"payment.scheme": "outlier_distinct"}}}
    monkeypatch.setattr(study, "load_declarations", lambda: {**declared, "pending_defences": pending})
    registered = study.payments()
    monkeypatch.setattr(study, "payments", lambda: {k: v for k, v in registered.items() if k != "outlier_distinct"})
    out = tmp_path / "never"
    assert main(["attack-search", "attack_search", "--defence", "later", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--defence later" in err and "outlier_distinct" in err and "Traceback" not in err
    assert not out.exists()
    monkeypatch.setattr(study, "payments", lambda: registered)
    s = study.load(im.load_experiment("attack_search"))
    assert {(c.defence, c.byzantines) for c in study.cells(s, ["later"], [3])} == {("later", 3)}


def test_with_outlier_distinct_registered_the_distinct_cell_is_searched():
    import infomarket as im
    from infomarket.search import study

    s = study.load(im.load_experiment("attack_search"))
    got = {(c.defence, c.byzantines) for c in study.cells(s, ["distinct"], [3])}
    assert got == {("distinct", 3)}
