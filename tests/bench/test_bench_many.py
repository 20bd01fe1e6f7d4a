"""bench --many's report: each many-run path's rate and its ratio to the engine's, measured in one run
(rates are measured, never asserted)."""
import pytest

from infomarket.bench.many import run_many_bench
from infomarket.config import load_experiment
from infomarket.search import study


def test_many_runs_report_rates_and_ratios_to_the_engines():
    pytest.importorskip("cma")
    r = run_many_bench(steps=60, repeats=1, sweep_runs=3, budget=3, popsize=2, runs=1, workers=1)
    assert r["engine"]["repeats"] == 3  # before the sweep, between the sweep and the search, after the search
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
        e = r[k]["engine_env_steps_per_second"]
        assert r[k]["ratio_to_engine"] == pytest.approx(r[k]["env_steps_per_second"] / e)
        assert r[k]["goal"] == 0.8
        assert r[k]["runs_per_second"] == pytest.approx(r[k]["runs"] / r[k]["cpu_seconds"])
        assert r[k]["engine_runs_per_second"] == pytest.approx(e / 60)  # the engine's runs: 60 steps each


def test_each_path_is_judged_against_the_engine_just_before_and_just_after_it(monkeypatch):
    """The engine runs before the first path and after each one; a path's ratio is against the median of
    the engine's runs on either side of it (the machine's speed may drift over the bench's minutes)."""
    from infomarket.bench import many

    order, engine = [], iter([[1.0, 1.0], [3.0, 3.0], [5.0, 5.0], [7.0, 7.0]])  # CPU s a run, by bracket

    def engine_seconds(cfg, repeats):
        order.append("engine")
        return next(engine)

    def sweep_rate(cfg, runs, folder):
        order.append("sweep")
        return {"env_steps_per_second": 100.0, "runs_per_second": 1.0, "runs": runs}

    def search_rate(steps, transitory, folder, *, budget, popsize, runs, workers=1):
        order.append("warm" if folder.name == "warm" else f"search{workers}")
        out = {"env_steps_per_second": 100.0, "runs_per_second": 1.0, "runs": 1}
        return {**out, "wall_env_steps_per_second": 150.0} if workers > 1 else out

    monkeypatch.setattr(many, "engine_seconds", engine_seconds)
    monkeypatch.setattr(many, "sweep_rate", sweep_rate)
    monkeypatch.setattr(many, "search_rate", search_rate)
    monkeypatch.setattr(many, "Simulation", lambda cfg, seed: None)
    r = many.run_many_bench(steps=60, repeats=2, workers=2)
    assert order == ["engine", "warm", "sweep", "engine", "search1", "engine", "search2", "engine"]
    # 60 steps a run: the engine's medians are 60 / 2, 60 / 4 and 60 / 6 env-steps/s around the three paths
    for k, median_seconds in (("sweep", 2.0), ("search", 4.0), ("search_pool", 6.0)):
        assert r[k]["engine_env_steps_per_second"] == pytest.approx(60 / median_seconds)
        assert r[k]["ratio_to_engine"] == pytest.approx(100.0 / (60 / median_seconds))
    assert r["search_pool"]["wall_ratio_to_engine_per_worker"] == pytest.approx(150.0 / (2 * 60 / 6.0))
    assert r["engine"]["repeats"] == 8 and r["engine"]["cpu_seconds_per_run"] == 4.0
