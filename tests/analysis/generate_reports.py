"""Every declared study's report, generated from the tests' synthetic stores, to compare before and after a
change to the analysis (the verdicts, numbers, CSV and JSON must not move):

    PYTHONPATH=src python tests/analysis/generate_reports.py OUT [STORES] [headline future chain terrain sens
                                                                           search defence]

STORES (default /tmp/infomarket-report-stores) keeps the stores between calls: the terrain and sensitivity
ones run short sweeps, the others are written directly.  The attack and defence searches' reports are
written from their tests' hand-built results (tests/search/test_report.py, tests/defence/test_report.py).
Run it on both trees and ``diff -r`` the OUTs.

``search-run`` and ``defence-run`` run the attack and defence searches' tiny studies (their tests' TINY
commands, one worker) into STORES once, then answer them again from a copy of that store (every run found,
none made) into OUT, so the two trees' reports come from the same store; what a call measures of itself
(wall seconds, how busy it kept the workers) is set to null in the JSON and dropped from the markdown
before the diff.  Give the run modes by name (they are not in the default list):

    PYTHONPATH=src python tests/analysis/generate_reports.py OUT STORES search-run defence-run
"""
import shutil
import sys
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from infomarket.cli import main  # after the repository is on the path
from tests.analysis.synthetic import _runs, paper_like, write_store

OUT = Path(sys.argv[1]) if __name__ == "__main__" else None
STORES = Path(sys.argv[2]) if len(sys.argv) > 2 and "/" in sys.argv[2] else Path("/tmp/infomarket-report-stores")
what = [w for w in sys.argv[2:] if "/" not in w] or ["headline", "future", "chain", "terrain", "sens", "search",
                                                     "defence"]

#: the tiny studies of the searches' tests (tests/search/test_attack_search.py, tests/defence/test_cli.py)
SEARCH_RUN = ["attack-search", "attack_search", "--defence", "staking", "--byzantines", "3", "--budget", "4",
              "--popsize", "2", "--restarts", "2", "--runs", "2", "--finalists", "2", "--race", "2,3",
              "--confirmation-runs", "3", "--grid-step", "90", "--steps", "400", "--transitory", "100", "--seed", "7",
              "--adaptive-budget", "0", "--workers", "1", "--quiet"]
DEFENCE_RUN = ["defence-search", "attack_search", "--questions",
               str(Path(__file__).resolve().parents[1] / "defence" / "tiny.toml"), "--family", "theta",
               "--byzantines", "3", "--steps", "1500", "--transitory", "500", "--seed", "6", "--workers", "1",
               "--quiet"]
#: what a call measures of itself: nulled in the JSON reports, its lines dropped from the markdown
OWN = ("wall_seconds", "busy")

#: how busy a study kept the machine, as the search and defence reports print it
BUSY = {"wall_seconds": 10.0, "workers": 2, "runs": 40, "run_seconds": 15.0, "compile_seconds": 1.5,
        "share_in_runs": 0.75, "plan_seconds": 1.0, "write_seconds": 0.5, "search_seconds": 2.0}


def fresh(p):
    if p.exists():
        shutil.rmtree(p)
    return p

def run():
    if "headline" in what:
        for name, kw in (("paper", {}), ("equal", {"honest_richer": False})):
            st = STORES / name
            if not st.exists():
                write_store(st, paper_like(**kw))
            assert main(["figures", str(st), "--out", str(fresh(OUT / f"figures-{name}")), "--quiet"]) == 0
    if "future" in what:
        from tests.analysis import test_future as tf
        for fn in (tf.hopeless, tf.rescued, tf.costly):
            st = STORES / f"future-{fn.__name__}"
            if not st.exists():
                robots = tf.sweep(fn)
                write_store(st, {"future": (robots, _runs(robots, 30000, 20000, ("byzantines", "defence")), None)})
            assert main(["figures", str(st), "--out", str(fresh(OUT / f"future-{fn.__name__}")), "--quiet"]) == 0
    if "chain" in what:
        from tests.analysis import test_chain_study as tc
        from infomarket.analysis import chain_study as cs
        for shift in (0.0, 15.0):
            d = STORES / f"chain-{shift:g}"
            if not d.exists():
                d.mkdir(parents=True)
                tc._write(d, shift)
            assert main(["chain-study", str(d / "store"), "--out", str(fresh(OUT / f"chain-cli-{shift:g}"))]) == 0
        # in-memory: every question with data
        rng = np.random.default_rng(8)
        f7 = []
        for _, label in cs.axis_values(tc.DECL, "period"):
            if label != "toychain":
                f7.append(tc.fig7_runs(rng, n=12, gain=0.0 if label == "period_5" else 60.0, experiment=cs.FIG7_SWEEP,
                                       settings=(label,), angles=(90.0,)))
        runs = pd.concat([tc.paper_runs(rng, settings=("toychain", "geth_argos")), tc.sweep_runs(rng, {"period_50"}),
                          tc.fig7_runs(rng, settings=("instant", "toychain", "geth_argos")), *f7,
                          tc.partition_runs(rng, 0.0)])
        a = cs.answer(runs, None)
        (OUT / "chain-mem").mkdir(parents=True, exist_ok=True)
        (OUT / "chain-mem" / "chain-study.md").write_text(cs.markdown(a))
        a.table.to_csv(OUT / "chain-mem" / "chain-study.csv", index=False)
    if "terrain" in what:
        from tests.terrain.test_report import _small
        root = STORES / "terrain"
        if not root.exists():
            tmp = STORES / "terrain-toml"
            tmp.mkdir(parents=True, exist_ok=True)
            for name in ("corridor", "two_food", "crowd"):
                assert main(["sweep", str(_small(name, tmp)), "--runs", "2", "--out", str(root / name),
                             "--workers", "1", "--quiet"]) == 0
        assert main(["terrain-report", str(root), "--out", str(fresh(OUT / "terrain"))]) == 0
    if "sens" in what:
        from tests.analysis import test_sensitivity as ts
        from infomarket.analysis import sensitivity as sm
        sm.PAWN_PERMUTATIONS = 20
        st = STORES / "sens"
        if not st.exists():
            st.mkdir(parents=True)
            ts.sweep(st, "sobol", 128)
        assert main(["sensitivity", str(st / "store-sobol"), "--out", str(fresh(OUT / "sens"))]) == 0
        assert main(["figures", str(st / "store-sobol"), "--out", str(fresh(OUT / "sens-figures")), "--quiet"]) == 0
        st2 = STORES / "shipped-sens"
        if not st2.exists():
            assert main(["sweep", "sensitivity", "--samples", "2", "--out", str(st2), "--quiet"]) == 0
        assert main(["sensitivity", str(st2), "--out", str(fresh(OUT / "sens-shipped"))]) == 0
    if "search" in what:
        from tests.search import test_report as tsr
        from infomarket.search import report as sr
        a = sr.analyse(tsr.study(), [tsr.A, tsr.B])
        out = fresh(OUT / "search")
        out.mkdir(parents=True)
        sr.write(out, a, reduced="one cell", steps=2500, transitory=0,
                 provenance={"questions commit": "abc123"}, busy=BUSY,
                 header={"commit": "c0ffee", "tree_clean": False, "questions_commit": "abc123",
                         "validation": {"search": 0.9, "random": 0.25}},
                 records=["## Amendments", "", "- one", ""])
    if "defence" in what:
        from tests.defence import test_report as tdr
        from infomarket.config import load_experiment
        from infomarket.defence import report as dr
        from infomarket.defence import study as ds
        st = ds.load(load_experiment("attack_search"))
        judged = [tdr._judged("good", cost=0.01, loss=0.04), tdr._judged("broken", cost=0.01, loss=0.5),
                  tdr._judged("staking", "existing", cost=0.0, loss=0.35)]
        result = tdr._result({"staking": (0.0, 0.35), "good": (0.01, 0.04), "broken": (0.01, 0.5)}, judged)
        a = dr.analyse(st, result)
        out = fresh(OUT / "defence")
        out.mkdir(parents=True)
        dr.write_frames(out, result)
        dr.write(out, a, reduced="tiny", wall_seconds=12.5, provenance={"questions commit": "abc123"},
                 records=["## Amendments", "", "- one", ""], busy=BUSY)
    for mode, args, files in (("search-run", SEARCH_RUN, ("report.json", "report.md", "search.json")),
                               ("defence-run", DEFENCE_RUN, ("defence.json", "defence.md"))):
        if mode in what:
            made = STORES / mode
            if not made.exists():
                assert main(args + ["--out", str(made)]) == 0
            out = fresh(OUT / mode)
            shutil.copytree(made / "store", out / "store")
            assert main(args + ["--out", str(out)]) == 0
            for name in files:
                own(out / name)
    print("done", what)


def own(path: Path) -> None:
    """``path`` without what the call measured of itself (``OWN``): nulled in JSON, dropped from markdown."""
    import json

    if path.suffix == ".json":
        data = json.loads(path.read_text())
        path.write_text(json.dumps({k: (None if k in OWN else v) for k, v in data.items()}, indent=2) + "\n")
    else:
        path.write_text("".join(line for line in path.read_text().splitlines(keepends=True)
                                if not any(w in line.lower() for w in ("wall", "busy", "worker", "seconds"))))


if __name__ == "__main__":
    run()
