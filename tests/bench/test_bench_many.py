"""bench --many's report: each many-run path's rate and its ratio to the engine's, measured in one run
(rates are measured, never asserted)."""
import pytest

from infomarket.bench.many import run_many_bench
from infomarket.config import load_experiment
from infomarket.search import study


def test_many_runs_report_rates_and_ratios_to_the_engines():
    pytest.importorskip("cma")
    r = run_many_bench(steps=60, repeats=1, sweep_runs=3, budget=2, popsize=2, runs=1, workers=1)
    e = r["engine"]["env_steps_per_second"]
    assert r["steps"] == 60 and r["clock"] == "process CPU time" and "search_pool" not in r
    assert r["sweep"]["runs"] == 3 and r["sweep"]["env_steps"] == 3 * 60
    # the search: 1 start run per hand-written attack but the reference, 2 candidates, 2 held-out runs each
    # for the best candidate and every hand-written attack
    st = study.load(load_experiment("attack_search"))
    hand = len(st.baselines)
    assert r["search"]["runs"] == (hand - bool(st.reference)) * 1 + 2 * 1 + (1 + hand) * 2
    assert r["search"]["env_steps"] == 60 * r["search"]["runs"]
    for k in ("sweep", "search"):
        assert r[k]["env_steps_per_second"] == pytest.approx(r[k]["env_steps"] / r[k]["cpu_seconds"])
        assert r[k]["ratio_to_engine"] == pytest.approx(r[k]["env_steps_per_second"] / e)
        assert r[k]["goal"] == 0.8
