"""`infomarket defence-search` on a tiny declared study (tests/defence/tiny.toml): it completes, records
its questions file, keeps the confirmation seeds fresh, resumes after SIGKILL with nothing lost or
repeated and the same answers bit for bit (the rerun from a partial store makes every choice again), gives
the same frontier on Dask, and refuses bad input before writing."""
import hashlib
import json
import signal
import subprocess
import time
from pathlib import Path

import pandas as pd
import pytest

from infomarket.cli import main
from infomarket.store import Store

from ..procs import HANG

TINY_FILE = Path(__file__).with_name("tiny.toml")
TINY = ["defence-search", "attack_search", "--questions", str(TINY_FILE), "--family", "theta", "--byzantines", "3",
        "--steps", "1500", "--transitory", "500", "--seed", "6"]


def _answers(out: Path) -> dict:
    """Everything the report decides (not how long it took, nor what this call made or found)."""
    a = json.loads((out / "defence.json").read_text())
    for k in ("wall_seconds", "made", "found", "provenance", "busy"):
        a.pop(k)
    return a


def _same(a: Path, b: Path) -> None:
    assert _answers(a) == _answers(b)
    for name in ("defence_cost.parquet", "defence_attacks.parquet"):
        pd.testing.assert_frame_equal(pd.read_parquet(a / name), pd.read_parquet(b / name), check_exact=True)


def _runs(out: Path) -> pd.DataFrame:
    return Store(out / "store").runs().sort_values(["experiment", "condition", "run"]).reset_index(drop=True)


@pytest.fixture(scope="module")
def inline(tmp_path_factory):
    out = tmp_path_factory.mktemp("defence") / "study"
    assert main(TINY + ["--workers", "1", "--quiet", "--out", str(out)]) == 0
    return out


def test_a_tiny_study_judges_every_candidate_and_confirms_the_frontier(inline):
    a = json.loads((inline / "defence.json").read_text())
    # tiny.toml: 2 first candidates and 1 refinement of the one family (the existing defences left out)
    labels = [r["label"] for r in a["search"]]
    assert labels == ["theta0", "theta1", "theta2"]
    assert [r["origin"] for r in a["search"]] == ["default", "design", "refine"]
    confirmed = [r["label"] for r in a["confirmed"]]
    assert 1 <= len(confirmed) <= 2  # frontier = 2 at most
    assert set(confirmed) <= {r["label"] for r in a["search"] if r["pareto"]}
    cost = pd.read_parquet(inline / "defence_cost.parquet")
    attacks = pd.read_parquet(inline / "defence_attacks.parquet")
    assert sorted(cost.label.unique()) == sorted(confirmed) and (cost.groupby("label").run.count() == 3).all()
    assert (attacks.groupby(["label", "byzantines"]).run.count() == 3).all()
    assert {r["answer"] for r in a["confirmed"]} <= {"yes", "no", "inconclusive"}
    runs = _runs(inline)
    assert not runs.duplicated(["experiment", "condition", "run"]).any()
    assert (inline / "frontier.png").stat().st_size > 0 and "# Defence search" in (inline / "defence.md").read_text()


def test_the_confirmation_seeds_are_touched_by_no_other_phase(inline):
    runs = _runs(inline)
    conf = runs[runs.seed_set == "confirmation"]
    assert set(conf.phase) == {"cost", "defence_confirmation"} or set(conf.phase) == {"cost", "defence_confirmation",
                                                                                     "confirmation"}
    mine = runs[runs.phase.isin(["cost", "defence_confirmation"]) & (runs.seed_set == "confirmation")]
    others = runs.drop(mine.index)
    assert set(mine.seed) and not set(mine.seed) & set(others.seed)
    # every confirmed defence, the undefended swarm and every attack ran on the same three seeds
    assert mine.groupby(["experiment", "condition"]).seed.apply(lambda s: tuple(sorted(s))).nunique() == 1


def test_the_store_records_the_questions_file(inline):
    meta = Store(inline / "store").meta()["defence_search"]
    assert meta["questions_sha256"] == hashlib.sha256(TINY_FILE.read_bytes()).hexdigest()
    assert meta["questions_file"] == "tiny.toml" and meta["first_run_utc"].endswith("Z")


def test_a_killed_study_resumes_without_losing_or_repeating_a_run(inline, tmp_path, capsys, procs):
    out = tmp_path / "study"
    proc = procs.cli(*TINY, "--workers", "1", "--quiet", "--out", out, env={"INFOMARKET_COMPILE_NOTICE": "0"},
                     stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    runs_dir = out / "store" / "runs"
    deadline = time.monotonic() + HANG
    while time.monotonic() < deadline and proc.poll() is None:  # killed in the outer search
        if runs_dir.exists() and len(list(runs_dir.glob("part-*.parquet"))) >= 4:
            break
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert proc.returncode == -signal.SIGKILL, proc.stderr.read().decode()[-2000:]
    kept = len(Store(out / "store").completed_runs())
    total = len(_runs(inline))
    assert 0 < kept < total
    assert main(TINY + ["--workers", "1", "--quiet", "--out", str(out)]) == 0
    runs = _runs(out)
    assert len(runs) == total and not runs.duplicated(["experiment", "condition", "run"]).any()
    _same(inline, out)


def test_the_same_study_on_dask_gives_the_same_frontier(inline, tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        out = tmp_path / "dask"
        assert main(TINY + ["--dask", cluster.scheduler_address, "--quiet", "--out", str(out)]) == 0
    _same(inline, out)


def _with_counts(tmp_path: Path, every_count: bool) -> list[str]:
    """TINY at 1 and 3 Byzantines, from a copy of tiny.toml with ``every_count`` set."""
    q = tmp_path / f"tiny-every-{every_count}.toml"
    q.write_text(TINY_FILE.read_text().replace("seed = 5\n", f"seed = 5\nevery_count = {str(every_count).lower()}\n",
                                               1))
    args = list(TINY)
    args[args.index("--questions") + 1] = str(q)
    args[args.index("--byzantines") + 1] = "1,3"
    args[args.index("--steps") + 1], args[args.index("--transitory") + 1] = "800", "300"  # runs' length: not the point
    return args


def test_judging_the_target_count_alone_confirms_the_same_numbers_with_fewer_runs(tmp_path):
    """every_count = false: the outer search judges at the target count (3) only and completes the confirmed
    candidates at 1 before confirming them; their confirmation is the one every_count = true makes."""
    full, lean = tmp_path / "full", tmp_path / "lean"
    assert main(_with_counts(tmp_path, True) + ["--workers", "1", "--quiet", "--out", str(full)]) == 0
    assert main(_with_counts(tmp_path, False) + ["--workers", "1", "--quiet", "--out", str(lean)]) == 0
    a, b = (json.loads((d / "defence.json").read_text()) for d in (full, lean))
    assert [r["label"] for r in a["confirmed"]] == [r["label"] for r in b["confirmed"]]
    assert all(set(r["losses"]) == {"1", "3"} for r in a["search"])
    for r in b["search"]:  # 3 candidates, at most 2 confirmed: one at least judged at the target alone
        assert set(r["losses"]) == ({"1", "3"} if r["confirmed"] else {"3"})
        assert r["losses"]["3"] == next(x for x in a["search"] if x["label"] == r["label"])["losses"]["3"]
    assert any(not r["confirmed"] for r in b["search"])
    assert [r["loss"] for r in a["confirmed"]] == [r["loss"] for r in b["confirmed"]]
    for name in ("defence_cost.parquet", "defence_attacks.parquet"):
        pd.testing.assert_frame_equal(pd.read_parquet(full / name), pd.read_parquet(lean / name), check_exact=True)
    made_full, made_lean = len(_runs(full)), len(_runs(lean))
    assert made_lean < made_full
    assert set(map(tuple, _runs(lean)[["experiment", "condition", "run"]].values)) < \
        set(map(tuple, _runs(full)[["experiment", "condition", "run"]].values))


BAD_FAMILY = """
[defence]
candidates = 2
[families.f]
set = {}
params.a = { paths = "payment.stake", low = 1, high = 0 }
[undefended]
set = { "payment.stake" = 0.0 }
"""


@pytest.mark.parametrize("option, words", [
    (["--family", "nope"], ["--family nope", "allowed: theta, existing"]),
    (["--family", " "], ["--family ' '"]),
    (["--byzantines", "5"], ["--byzantines 5", "allowed: 1, 3, 8"]),
    (["--transitory", "1500"], ["--transitory 1500", "below --steps 1500"]),
    (["--inner-race", "4,2"], ["race: cumulative runs per stage", "(got [4, 2])"]),
    (["--questions", "/nonexistent/q.toml"], ["--questions /nonexistent/q.toml", "no such file"]),
    (["--out", " "], ["--out ' '"]),
])
def test_bad_input_is_refused_before_anything_is_written(tmp_path, capsys, option, words):
    args = list(TINY)
    args += ["--out", str(tmp_path / "out")] if "--out" not in option else []
    assert main(args + option) == 2
    err = capsys.readouterr().err
    assert all(w in err for w in words), err
    assert "Traceback" not in err and not (tmp_path / "out").exists()


def test_a_malformed_questions_file_is_refused_naming_what_is_wrong(tmp_path, capsys):
    q = tmp_path / "q.toml"
    q.write_text(BAD_FAMILY)
    assert main(["defence-search", "attack_search", "--questions", str(q), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "[families.f] params.a" in err and "low must be below high" in err and not (tmp_path / "o").exists()
    q.write_text(BAD_FAMILY.replace("[families.f]", "[famlies.f]"))
    assert main(["defence-search", "attack_search", "--questions", str(q), "--out", str(tmp_path / "o")]) == 2
    assert "unknown table [famlies]" in capsys.readouterr().err


def test_the_families_are_listed(capsys):
    assert main(["defence-search", "attack_search", "--list-families"]) == 0
    out = capsys.readouterr().out
    assert "robust_median" in out and "vectors\tint [2, 9], default 5" in out and "staking\texisting" in out


def test_a_reduced_study_with_the_declared_seed_is_refused_and_a_part_of_the_study_is_not(tmp_path, capsys):
    """[seed_sets]: a reduced run's confirmation runs would be the study's own, seen before the study."""
    reduced = [a for a in TINY if a not in ("--seed", "6")]  # tiny.toml declares seed 5
    assert main(reduced + ["--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "--seed 5 is the declared study's own" in err and "--steps" in err and not (tmp_path / "o").exists()
    # the declared settings on some of the families and counts: the study itself, in parts (only listed here)
    part = ["defence-search", "attack_search", "--questions", str(TINY_FILE), "--family", "theta",
            "--byzantines", "3", "--list-families"]
    assert main(part) == 0


def test_a_rerun_over_a_finished_store_makes_no_run_and_compiles_nothing(inline, tmp_path, monkeypatch):
    """The same command over its finished store (copied) builds no world on any kernel (no run, no warm-up,
    no kernel's preflight), starts no compile child and hands no task to a worker pool, and writes the same answers."""
    import shutil

    from ..runner.loads import counting

    out = tmp_path / "again"
    shutil.copytree(inline, out)
    with counting(monkeypatch) as counts:
        assert main(TINY + ["--workers", "2", "--quiet", "--out", str(out)]) == 0
    assert counts == {"worlds": 0, "compile_children": 0, "submitted": 0}
    _same(inline, out)
