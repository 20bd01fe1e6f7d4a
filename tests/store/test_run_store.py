"""What ``infomarket run`` and sweeps put in a store beyond the robots: items per site (terrain setups),
the configuration of every condition (``Store.config``), and the store's writer rules (lock first,
``drop_experiment`` removes one experiment only)."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import infomarket as im
from infomarket.cli import main
from infomarket.runner.plan import conditions
from infomarket.runner.sweep import plan, run_sweep
from infomarket.store import Store, StoreError

#: The paper's Fig. 4 mix (sceptical robots, scaboteurs, outlier payment): the suite compiles its step kernels
#: for other tests too, on the plane and with terrain (tests/store/test_dictionary.py).
TERRAIN = """
name = "two_sites"
steps = 3000
runs = 2
seed = 7
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
[[food]]
x = 200.0
y = 300.0
[[food]]
x = 700.0
y = 100.0
[[obstacles]]
shape = "circle"
x = 600.0
y = 400.0
radius = 30.0
"""


def test_run_stores_items_per_site_of_a_terrain_setup(tmp_path):
    path = tmp_path / "t.toml"
    path.write_text(TERRAIN)
    out = tmp_path / "out"
    assert main(["run", str(path), "--runs", "2", "--out", str(out), "--workers", "1", "--quiet"]) == 0
    store = Store(out)
    sites, robots = store.sites(), store.robots()
    assert sites.columns.tolist() == ["experiment", "condition", "run", "seed", "site", "kind", "x", "y", "radius",
                                      "items"]
    # two food sites and one nest per run, in the file's order
    assert sites.groupby("run").kind.apply(list).tolist() == [["food", "food", "nest"]] * 2
    assert sites[sites.kind == "food"].x.tolist() == [200.0, 700.0, 200.0, 700.0]
    # every deposit is counted at the one nest and in some robot's items (two independent counters)
    nest = sites[sites.kind == "nest"].set_index("run")["items"]
    assert nest.to_dict() == robots.groupby("run").items_collected.sum().to_dict() and nest.sum() > 0
    runs = store.runs()
    assert (runs.sites_rows == 3).all() and (runs.sites_sha256.str.len() == 64).all()  # checksummed


def test_a_plane_run_stores_no_sites(tmp_path):
    out = tmp_path / "p"
    assert main(["run", "fig2A", "--runs", "1", "--steps", "200", "--out", str(out), "--quiet"]) == 0
    assert Store(out).sites().empty and not list((out / "sites").iterdir())
    assert Store(out).runs().sites_rows.tolist() == [0]


def test_every_condition_of_a_sweep_records_its_configuration(tiny, tmp_path):
    exp = im.load_experiment(tiny(runs=2, steps=300))
    store = Store(tmp_path / "s")
    run_sweep(plan([exp]), store, workers=1)
    conds = conditions(exp)
    configs = store.configs()
    assert sorted(configs.condition) == sorted(c.id for c in conds) and len(configs) == 2
    robots = store.robots()
    for c in conds:
        cfg = store.config("tiny", c.id)
        assert cfg.payment.information_share == c.keys["information_share"] and cfg.steps == 300
        again = im.simulate(cfg, seed=c.seed(1)).robots
        stored = robots[(robots.condition == c.id) & (robots.run == 1)].reset_index(drop=True)
        assert np.array_equal(again.wealth.to_numpy(), stored.wealth.to_numpy())
    with pytest.raises(StoreError, match=r"no recorded configuration of tiny \[base\]"):
        store.config("tiny")


def test_a_foreign_folder_is_refused_before_the_lock_file_is_written(tmp_path):
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "notes.txt").write_text("x")
    with pytest.raises(StoreError, match="not an infomarket results store"):
        with Store(folder).writing():
            pytest.fail("entered")
    assert sorted(p.name for p in folder.iterdir()) == ["notes.txt"]


def test_writing_twice_in_one_process_is_refused(tmp_path):
    store = Store(tmp_path / "s")
    with store.writing():
        with pytest.raises(StoreError, match="already writing this store"):
            with Store(tmp_path / "s").writing():
                pass


def test_drop_experiment_removes_that_experiment_only(tmp_path):
    out = tmp_path / "s"
    assert main(["run", "fig2A", "--runs", "2", "--steps", "200", "--out", str(out), "--quiet"]) == 0
    assert main(["run", "fig2B", "--runs", "1", "--steps", "200", "--out", str(out), "--quiet"]) == 0
    store = Store(out)
    b = store.robots().query("experiment == 'fig2B'").reset_index(drop=True)
    assert store.seeds() == {"fig2A": 1, "fig2B": 2}
    with store.writing():
        assert store.drop_experiment("fig2A") == 2  # its two parts (one run each)
    assert set(store.runs().experiment) == {"fig2B"} and store.seeds() == {"fig2B": 2}
    pd.testing.assert_frame_equal(store.robots(), b, check_exact=True, check_dtype=False, check_categorical=False)
    assert store.verify().ok and not store.verify().orphans
    assert sorted(p.name for p in (out / "configs").iterdir()) == ["part-fig2B-base-00000-00000.parquet"]
