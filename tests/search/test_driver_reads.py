"""The attack search's runner hands back the rows of the runs it just wrote, as the store holds them."""
import pandas as pd

from infomarket.config import load_experiment
from infomarket.search import driver, study
from infomarket.search.objective import per_run
from infomarket.store import Store


def test_the_rows_kept_from_the_written_parts_are_the_stores(tmp_path):
    st = study.load(load_experiment("attack_search"), budget=3, popsize=3, runs=3)
    cell = study.cells(st, ["staking"], [3])[0]
    store = Store(tmp_path / "s")
    run = driver.store_runner(store)
    ev = driver._Evaluator(st, cell, store, run, 60, 20)
    conds = [ev.condition({}, "search", "cma", 0, 0, i, f"g0c{i}", 3, 7) for i in range(3)]
    assert run(conds) == (9, 0)
    kept = per_run(run.robots(conds)).reset_index(drop=True)
    stored = per_run(store.robots()).reset_index(drop=True)
    assert len(kept) == 9
    pd.testing.assert_frame_equal(kept, stored, check_exact=True)
    # a second runner finds every run in the store (a resumed search): it reads them back from there
    again = driver.store_runner(store)
    assert again(conds) == (0, 9)
    pd.testing.assert_frame_equal(per_run(again.robots(conds)).reset_index(drop=True), stored, check_exact=True)


def test_a_race_stage_counts_only_its_new_runs(tmp_path):
    """A raced attack is one condition whose runs grow stage by stage: the runs of an earlier stage are
    neither made again nor counted as found, and its values on runs 0..n-1 come back whole."""
    st = study.load(load_experiment("attack_search"), budget=2, popsize=2, runs=2)
    cell = study.cells(st, ["staking"], [3])[0]
    store = Store(tmp_path / "s")
    run = driver.store_runner(store)
    ev = driver._Evaluator(st, cell, store, run, 60, 20)

    def cond(runs):
        return ev.condition({}, "selection", "baseline", -1, -1, -1, "x", runs, 11)

    first = ev.evaluate([cond(2)])[0]
    assert run([cond(2)]) == (0, 0)  # asked again: nothing new
    grown = ev.evaluate([cond(5)])[0]
    assert (ev.done, ev.skipped) == (5, 0) and list(grown.run) == [0, 1, 2, 3, 4]
    pd.testing.assert_frame_equal(grown.head(2), first, check_exact=True)
    stored = per_run(store.robots()).sort_values("run").reset_index(drop=True)
    assert list(grown["items"]) == list(stored["items"]) and ev.cost["selection"]["runs"] == 5
