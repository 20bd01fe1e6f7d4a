"""``infomarket attack-search`` at tiny size: it completes with every run once, uses the three seed sets as
declared, reruns bit for bit, resumes after SIGKILL with no evaluation lost or repeated, gives the same
results on Dask, records its provenance, refuses bad input."""
import datetime
import hashlib
import json
import signal
import subprocess
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from infomarket.cli import main
from infomarket.config import load_experiment
from infomarket.search import adaptive, study
from infomarket.search.driver import confirmation_seeds, planned_runs
from infomarket.search.report import EXTRA_QUESTION
from infomarket.store import Store

from ..procs import HANG

TINY = ["attack-search", "attack_search", "--defence", "staking", "--byzantines", "3", "--budget", "4",
        "--popsize", "2", "--restarts", "2", "--runs", "2", "--finalists", "2", "--race", "2,3",
        "--confirmation-runs", "3", "--grid-step", "90", "--steps", "400", "--transitory", "100", "--seed", "7",
        "--adaptive-budget", "0"]
CELL = "attack_search.staking.b3"
DECLARED = len(study.load_declarations()["baselines"])  # hand-written + truthful
# by hand: start = (the hand-written + 18 grid (0, 90, 180 degrees x 2 x 3) + 2 start points) x 2 runs;
# search: budget 4 = 2 start points (one per restart) + 2 CMA-ES evaluations (restart 0's share of 1 is
# carried to restart 1: 1 generation of 2), random: 4 evaluations, each x 2 runs; race: search
# 2 x 3 runs, random 2 x 3, the n baselines n x 2 then the better half (rounded up) x 1 more, truthful 3;
# confirmation: 4 attacks (search, random, baseline, truthful) x 3
HAND = DECLARED - 1
N = HAND + 18
PLANNED = (N + 2) * 2 + (2 + 4) * 2 + (2 * 3 + 2 * 3 + N * 2 + (N + 1) // 2 + 3) + 4 * 3


def _frames(out: Path) -> dict:
    return {n: pd.read_parquet(out / "cells" / CELL / f"{n}.parquet")
            for n in ("candidates", "selection", "confirmation")}


def _same_frames(a: Path, b: Path) -> None:
    fa, fb = _frames(a), _frames(b)
    for name in fa:
        pd.testing.assert_frame_equal(fa[name], fb[name], check_exact=True)
    ja, jb = json.loads((a / "search.json").read_text()), json.loads((b / "search.json").read_text())
    assert [c["chosen"] for c in ja["cells"]] == [c["chosen"] for c in jb["cells"]]


def _runs_table(out: Path) -> pd.DataFrame:
    return Store(out / "store").runs().sort_values(["condition", "run"]).reset_index(drop=True)


@pytest.fixture(scope="module")
def inline(tmp_path_factory):
    out = tmp_path_factory.mktemp("inline") / "search"
    assert main(TINY + ["--workers", "1", "--quiet", "--out", str(out)]) == 0
    return out


def test_a_tiny_search_completes_with_every_run_once(inline):
    st = study.load(load_experiment("attack_search"), budget=4, popsize=2, restarts=2, runs=2, finalists=2,
                    race=[2, 3], confirmation_runs=3, grid_step=90.0)
    assert planned_runs(st) == PLANNED
    runs = _runs_table(inline)
    assert len(runs) == PLANNED and not runs.duplicated(["experiment", "condition", "run"]).any()
    f = _frames(inline)
    assert f["candidates"].searcher.value_counts().to_dict() == {"baseline": N, "cma": 2, "random": 4,
                                                                 "start": 2}
    chosen = json.loads((inline / "search.json").read_text())["cells"][0]["chosen"]
    assert set(chosen) == {"search", "random", "baseline", "worst", "reference"}
    assert chosen["worst"] in {chosen["search"], chosen["random"], chosen["baseline"]}
    conf = f["confirmation"]
    assert set(conf.attack) == set(chosen.values())
    assert all(sorted(g.run) == [0, 1, 2] for _, g in conf.groupby("attack"))  # every attack on every run


def test_each_run_belongs_to_its_seed_set_and_confirmation_seeds_are_fresh(inline):
    runs = _runs_table(inline)
    want = {"start": "search", "search": "search", "random": "search", "selection": "selection",
            "confirmation": "confirmation"}
    assert set(runs.phase) == set(want)
    assert (runs.seed_set == runs.phase.map(want)).all()
    seeds = {cond: tuple(g.sort_values("run").seed) for cond, g in runs.groupby("condition")}
    phase = runs.groupby("condition").phase.first()
    # candidates of one generation share seeds; generations, searchers and phases do not
    gen = runs[runs.phase.isin(["search", "random"])].groupby(["searcher", "restart", "gen"]).condition.unique()
    sets = [{seeds[c] for c in conds} for conds in gen]
    assert all(len(s) == 1 for s in sets) and len({next(iter(s)) for s in sets}) == len(sets)
    assert len({seeds[c] for c in phase.index if phase[c] == "start"}) == 1
    sel = [seeds[c] for c in phase.index if phase[c] == "selection"]
    longest = max(sel, key=len)
    assert len(longest) == 3 and all(s == longest[:len(s)] for s in sel)  # one shared set, run k alike
    confirm = {s for c in phase.index if phase[c] == "confirmation" for s in seeds[c]}
    others = {s for c in phase.index if phase[c] != "confirmation" for s in seeds[c]}
    assert len(confirm) == 3 and not confirm & others


def test_the_store_records_the_questions_file_and_the_first_run_time(inline, procs):
    meta = Store(inline / "store").meta()["attack_search"]
    assert meta["questions_sha256"] == hashlib.sha256(study.QUESTIONS.read_bytes()).hexdigest()
    assert meta["questions_commit"] is None or len(meta["questions_commit"]) == 40
    first = datetime.datetime.strptime(meta["first_run_utc"], "%Y-%m-%dT%H:%M:%SZ")
    assert first <= datetime.datetime.now(datetime.UTC).replace(tzinfo=None)
    assert first >= datetime.datetime.now(datetime.UTC).replace(tzinfo=None) - datetime.timedelta(hours=2)
    # the report's first keys: the code's commit now (this checkout's HEAD) and the questions file's
    head = procs.run(["git", "-C", str(study.QUESTIONS.parent), "rev-parse", "HEAD"]).stdout.strip() or None
    data = json.loads((inline / "report.json").read_text())
    assert list(data)[:4] == ["commit", "tree_clean", "questions_commit", "validation"]
    assert data["commit"] == head and data["questions_commit"] == meta["questions_commit"]
    assert meta["commit"] == head and isinstance(data["tree_clean"], bool) == (head is not None)
    assert f"Code: commit `{head}`" in (inline / "report.md").read_text()


def test_a_second_search_into_another_store_is_the_same_bit_for_bit(inline, tmp_path):
    out = tmp_path / "again"
    assert main(TINY + ["--workers", "1", "--quiet", "--out", str(out)]) == 0
    _same_frames(inline, out)


def test_a_killed_search_resumes_without_losing_or_repeating_an_evaluation(inline, tmp_path, capsys, procs):
    out = tmp_path / "search"
    proc = procs.cli(*TINY, "--workers", "1", "--quiet", "--out", out, env={"INFOMARKET_COMPILE_NOTICE": "0"},
                     stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    runs_dir = out / "store" / "runs"
    deadline = time.monotonic() + HANG
    while time.monotonic() < deadline and proc.poll() is None:  # killed in the search phase
        if runs_dir.exists() and len(list(runs_dir.glob("part-*.parquet"))) >= 3:
            break
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert proc.returncode == -signal.SIGKILL, proc.stderr.read().decode()[-2000:]  # killed mid-search
    first = Store(out / "store").meta()["attack_search"]["first_run_utc"]
    kept = len(Store(out / "store").completed_runs())
    assert 0 < kept < PLANNED
    capsys.readouterr()
    assert main(TINY + ["--workers", "1", "--out", str(out)]) == 0
    made = [line for line in capsys.readouterr().out.splitlines() if line.startswith("attack-search:")][-1]
    assert made.startswith(f"attack-search: {PLANNED - kept} runs made now, {kept} found in the store")
    runs = _runs_table(out)
    assert len(runs) == PLANNED and not runs.duplicated(["experiment", "condition", "run"]).any()
    _same_frames(inline, out)  # the optimisers' state and the race were rebuilt exactly
    assert Store(out / "store").meta()["attack_search"]["first_run_utc"] == first


def test_the_same_search_on_dask_gives_identical_results(inline, tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        out = tmp_path / "dask"
        assert main(TINY + ["--dask", cluster.scheduler_address, "--quiet", "--out", str(out)]) == 0
    _same_frames(inline, out)


@pytest.mark.parametrize("option, words", [
    (["--defence", "nope"], ["--defence nope", "allowed: outlier, staking"]),
    (["--byzantines", "5"], ["--byzantines 5", "allowed: 1, 3, 8"]),
    (["--race", "8,4"], ["race: cumulative runs per stage", "each above the one before", "(got [8, 4])"]),
    (["--race", "8,x"], ["--race '8,x'"]),
    (["--keep", "0"], ["keep: a number in (0, 1] is expected (got 0.0)"]),
    (["--grid-step", "-5"], ["grid_step: a number in (0, 180] is expected (got -5.0)"]),
])
def test_bad_input_is_refused_before_anything_is_written(tmp_path, capsys, option, words):
    out = tmp_path / "never"
    args = ["attack-search", "attack_search", *option, "--out", str(out)]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert all(w in err for w in words) and "Traceback" not in err, err
    assert not out.exists()


def test_an_unknown_search_setting_is_refused(tmp_path, capsys, monkeypatch):
    shipped = study.DECLARATION
    monkeypatch.setattr(study, "DECLARATION", replace(shipped, data={**shipped.data, "search": {"budegt": 3}}))
    out = tmp_path / "never"
    assert main(["attack-search", "attack_search", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "budegt: unknown key; allowed keys here: budget" in err and "Traceback" not in err
    assert not out.exists()


def test_the_baselines_are_listed(capsys):
    assert main(["attack-search", "attack_search", "--list-baselines", "--grid-step", "90"]) == 0
    lines = capsys.readouterr().out.splitlines()
    kinds = [line.split("\t")[1] for line in lines]
    assert kinds.count("grid") == 3 * 2 * 3 and kinds.count("declared") == HAND and kinds.count("reference") == 1
    assert any(line.startswith("rot_090_collude_nest\tgrid\t") and "collude=1" in line and "lie_site=1" in line
               for line in lines)


def test_a_pending_defence_waits_for_its_scheme(tmp_path, capsys, monkeypatch):
    """A defence declared in `[pending_defences]` joins the cells only once its scheme is registered:
    unregistered it is refused, saying which scheme it waits for; registered, it is a cell."""
    import infomarket as im

    declared = study.DECLARATION
    pending = {"later": {"requires": "outlier_distinct", "set": {"payment.scheme": "outlier_distinct"}}}
    monkeypatch.setattr(study, "DECLARATION", replace(
        declared, data={**declared.data, "pending_defences": pending}))
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

    s = study.load(im.load_experiment("attack_search"))
    got = {(c.defence, c.byzantines) for c in study.cells(s, ["distinct"], [3])}
    assert got == {("distinct", 3)}


def test_the_adaptive_attacker_is_the_second_searcher_on_the_same_confirmation_seeds(tmp_path):
    """With an adaptive budget the search trains the adaptive attacker (one generation of 2 x 8 + 1), plays it
    on the cell's confirmation seeds and the report compares it with the parametric search's attack; its
    runs are those ``adaptive.confirm`` gives for the policy saved beside the store, seed for seed."""
    out = tmp_path / "search"
    tiny = TINY[:TINY.index("--adaptive-budget")] + ["--adaptive-budget", "17", "--seed", "11"]
    assert main(tiny + ["--workers", "1", "--quiet", "--out", str(out)]) == 0
    report = json.loads((out / "report.json").read_text())
    cell_report = next(c for c in report["cells"] if c["experiment"] == CELL)
    assert cell_report["extra_attacks"] == {"adaptive": "adaptive"}
    assert "adaptive" in cell_report[EXTRA_QUESTION]
    st = study.load(load_experiment("attack_search"), seed=11, confirmation_runs=3)
    cell = study.cells(st, ["staking"], [3])[0]
    policy = adaptive.Policy.load(out / "adaptive" / CELL / "policy.npz")
    expected = adaptive.confirm(cell, policy, confirmation_seeds(st, cell), steps=400, transitory=100)
    assert len(expected) == 3
    conf = _frames(out)["confirmation"]
    search = conf[conf.attack == cell_report["chosen"]["search"]].sort_values("run")["items"].to_numpy()
    d = expected.sort_values("run")["items"].to_numpy() - search  # adaptive - search, seed by seed
    walsh = [(d[i] + d[j]) / 2 for i in range(3) for j in range(i, 3)]  # Hodges-Lehmann by hand
    assert cell_report[EXTRA_QUESTION]["adaptive"]["hl"] == pytest.approx(float(np.median(walsh)))


def test_a_reduced_search_with_the_declared_seed_is_refused_and_some_cells_are_not(tmp_path, capsys):
    """questions.toml [seed_sets]: a pilot or reduced search must not touch the study's confirmation seeds."""
    declared = str(study.load_declarations()["search"]["seed"])
    args = list(TINY)
    args[args.index("--seed") + 1] = declared
    assert main(args + ["--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert f"--seed {declared} is the declared study's own" in err and "--budget" in err
    assert len(err.strip()) <= len("infomarket: error: ") + 160, err  # one short line, however many differences
    assert not (tmp_path / "o").exists()
    st = study.load(load_experiment("attack_search"))
    from infomarket.analysis.study import refuse_declared_seed

    refuse_declared_seed(st.settings.seed, st.settings.seed, [])  # the whole declared study: allowed
    # some of the declared cells with the declared settings is not the whole study: refused
    args = ["attack-search", "attack_search", "--defence", "staking", "--seed", declared, "--out", str(tmp_path / "p")]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert f"--seed {declared} is the declared study's own" in err and "cells" in err and "Traceback" not in err
    assert not (tmp_path / "p").exists()


def test_a_rerun_over_a_finished_store_makes_no_run_and_compiles_nothing(inline, tmp_path, monkeypatch):
    """The same command over its finished store (copied) builds no world on any kernel, starts no compile
    child and no worker pool, and gives the same frames and choices."""
    import shutil

    from ..runner.loads import counting

    out = tmp_path / "again"
    shutil.copytree(inline, out)
    with counting(monkeypatch) as counts:
        assert main(TINY + ["--workers", "2", "--quiet", "--out", str(out)]) == 0
    assert counts == {"worlds": 0, "compile_children": 0, "submitted": 0}
    _same_frames(inline, out)


#: tools/study_stores.py's digest of the store of TWO_CELLS on 2 workers, made by the code before the study's
#: searches shared the workers (each cell's sweeps one after another): every row of runs, robots, history
#: and configs, sorted, without timings and part checksums; and the digest of the sorted part file names.
BEFORE = "4b50d397201b93833e695349610ea91fd38ce8f1982010a7dd5e41082e7e4574"
BEFORE_PARTS = "d23853f7fa41abffc03657c5ea8f8a1c9e0d46a79c6073cde6e4ee1a17f722b9"
TWO_CELLS = [a if a != "staking" else "outlier,staking" for a in TINY]


def test_two_cells_sharing_the_workers_make_the_store_the_cells_made_one_after_another(tmp_path):
    """The cells' searches run side by side on 2 workers (runner.feed); the store holds the same runs, rows
    and parts as the code that ran them one after another made (digests recorded from that code)."""
    import importlib.util

    path = Path(__file__).resolve().parents[2] / "tools" / "study_stores.py"
    spec = importlib.util.spec_from_file_location("study_stores", path)
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    out = tmp_path / "two"
    assert main(TWO_CELLS + ["--workers", "2", "--quiet", "--out", str(out)]) == 0
    assert tool.digest(out / "store") == BEFORE
    assert hashlib.sha256(tool.part_names(out / "store").encode()).hexdigest() == BEFORE_PARTS
