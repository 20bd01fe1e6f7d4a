"""The attack search's runner hands back the rows of the runs it just wrote, as the store holds them."""
import pandas as pd

from infomarket.config import load_experiment
from infomarket.search import driver, study
from infomarket.search.objective import per_run
from infomarket.store import Store


def test_the_rows_kept_from_the_written_parts_are_the_stores(tmp_path):
    st = study.load(load_experiment("attack_search"), budget=3, popsize=3, runs=3, heldout_runs=2, best=1)
    cell = study.cells(st, ["staking"], [3])[0]
    conds = [driver._condition(cell, {}, driver._keys("search", 0, i, f"g0c{i}"), 3, 7, 60, 20) for i in range(3)]
    store = Store(tmp_path / "s")
    run = driver.store_runner(store)
    assert run(conds) == (9, 0)
    kept = per_run(run.robots(conds)).reset_index(drop=True)
    stored = per_run(store.robots()).reset_index(drop=True)
    assert len(kept) == 9
    pd.testing.assert_frame_equal(kept, stored, check_exact=True)
    # a second runner finds every run in the store (a resumed search): it reads them back from there
    again = driver.store_runner(store)
    assert again(conds) == (0, 9)
    pd.testing.assert_frame_equal(per_run(again.robots(conds)).reset_index(drop=True), stored, check_exact=True)
