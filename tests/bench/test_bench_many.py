"""bench --many's report: each many-run path's rate and its ratio to the engine's, measured in one run
(rates are measured, never asserted)."""
import pytest

from infomarket.bench.many import run_many_bench
from infomarket.config import load_experiment
from infomarket.search import study


def test_many_runs_report_rates_and_ratios_to_the_engines():
    pytest.importorskip("cma")
    r = run_many_bench(steps=60, repeats=1, sweep_runs=3, budget=3, popsize=2, runs=1, workers=1)
    e = r["engine"]["env_steps_per_second"]
    assert r["steps"] == 60 and r["clock"] == "process CPU time" and "search_pool" not in r
    assert r["sweep"]["runs"] == 3 and r["sweep"]["env_steps"] == 3 * 60
    # the search, by hand: 1 start run per baseline (the hand-written but the reference, 12 grid points at
    # 0 and 180 degrees) and the one start point (budget 3: one a restart); 1 CMA-ES generation of 2 and 3
    # random candidates (as many as the global search's start point and candidates); the race (one stage of
    # 2 runs) of 1 finalist per searcher, every baseline and the reference; 4 chosen attacks x 2 confirmation runs
    st = study.load(load_experiment("attack_search"))
    hand = len([n for n in st.baselines if not n.startswith("rot_")]) - 1
    assert r["search"]["runs"] == (hand + 12 + 1) + 2 + 3 + (1 + 1 + hand + 12 + 1) * 2 + 4 * 2
    assert r["search"]["phases"] == {"start": hand + 13, "search": 2, "random": 3, "selection": (hand + 15) * 2,
                                     "confirmation": 8}
    assert r["search"]["env_steps"] == 60 * r["search"]["runs"]
    for k in ("sweep", "search"):
        assert r[k]["env_steps_per_second"] == pytest.approx(r[k]["env_steps"] / r[k]["cpu_seconds"])
        assert r[k]["ratio_to_engine"] == pytest.approx(r[k]["env_steps_per_second"] / e)
        assert r[k]["goal"] == 0.8
        assert r[k]["runs_per_second"] == pytest.approx(r[k]["runs"] / r[k]["cpu_seconds"])
        assert r[k]["engine_runs_per_second"] == pytest.approx(e / 60)  # the engine's runs: 60 steps each
