"""Sampled designs ([sweep.sample]): bad designs refused before anything runs, integers sampled as
integers, the design seeded from the experiment's seed, kept in the store and resumed like a grid."""
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import infomarket as im
from infomarket.cli import main
from infomarket.runner.design import load, make_design
from infomarket.runner.plan import conditions
from infomarket.runner.sweep import run_sweep
from infomarket.store import Store, StoreError

HEAD = """
name = "design"
steps = 3
runs = 1
seed = 5

[swarm]
robots = 10

[[swarm.groups]]
behaviour = "sceptical"
count = 8

[[swarm.groups]]
behaviour = "scaboteur"
count = 2

[payment]
scheme = "outlier"
stake = 0.04
"""
SAMPLE = """
[sweep.sample]
method = "{method}"
samples = {samples}
remainder = "swarm.groups[0].count"
outputs = ["items"]

[sweep.sample.bounds]
"robot.noise_sd" = [0.0, 0.1]
"swarm.groups[1].count" = {{ range = [1, 4], name = "byzantines" }}
"""


def write(tmp_path: Path, extra: str = "", method="sobol", samples=8, body=None) -> Path:
    p = tmp_path / "design.toml"
    p.write_text(HEAD + (body if body is not None else SAMPLE.format(method=method, samples=samples)) + extra)
    return p


def refused(tmp_path, capsys, path, *words):
    out = tmp_path / "store"
    assert main(["sweep", str(path), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("infomarket: error:") == 1 and "Traceback" not in err
    for w in words:
        assert w in err, err
    assert not out.exists()  # nothing written
    return err


@pytest.mark.parametrize("bounds, words", [
    ('"robot.noise" = [0.0, 0.1]', ["unknown key", "'robot.noise'", "noise_sd"]),
    ('"robot.noise_sd" = [0.1, 0.1]', ["robot.noise_sd", "empty or inverted range"]),
    ('"robot.noise_sd" = [0.2, 0.1]', ["robot.noise_sd", "empty or inverted range"]),
    ('"robot.noise_sd" = [0.1]', ["robot.noise_sd"]),
    ('"payment.scheme" = [0.0, 1.0]', ["'payment.scheme' is not a numeric key"]),
    ('"swarm.groups[1].count" = [0.5, 3]', ["whole-number bounds"]),
    # a corner where the Byzantines outnumber the swarm: the remainder count goes negative
    ('"swarm.groups[1].count" = [1, 12]', ["corner", "count", "12"]),
    # a corner outside what the validator accepts for the sceptic's threshold (> 0)
    ('"swarm.groups[0].params.threshold" = [0.0, 1.0]', ["corner", "threshold", "> 0"]),
    ('"payment.params.theta" = [10.0, 200.0]', ["corner", "theta", "200"]),
])
def test_bad_bounds_are_refused_before_anything_runs(tmp_path, capsys, bounds, words):
    body = ('[sweep.sample]\nmethod = "sobol"\nsamples = 8\nremainder = "swarm.groups[0].count"\n'
            'outputs = ["items"]\n[sweep.sample.bounds]\n"robot.bias_mean" = [0.0, 0.1]\n' + bounds + "\n")
    refused(tmp_path, capsys, write(tmp_path, body=body), *words)


@pytest.mark.parametrize("method, samples, words", [
    ("sobol", 12, ["samples = 12", "power of 2"]),
    ("sobol", 1, ["samples = 1", "power of 2"]),
    ("morris", 1, ["samples = 1", "at least 2 trajectories"]),
    ("lhs", 20, ["samples = 20", "more than 20"]),
])
def test_sample_sizes_the_method_cannot_use_are_refused(tmp_path, capsys, method, samples, words):
    refused(tmp_path, capsys, write(tmp_path, method=method, samples=samples), *words)


def test_odd_morris_levels_unknown_outputs_and_grid_with_sample_are_refused(tmp_path, capsys):
    odd = SAMPLE.format(method="morris", samples=4).replace('outputs = ["items"]', 'outputs = ["items"]\nlevels = 3')
    refused(tmp_path, capsys, write(tmp_path, body=odd), "levels = 3", "even")
    refused(tmp_path, capsys, write(tmp_path, body=SAMPLE.format(method="sobol", samples=8).replace(
        '["items"]', '["items", "speed"]')), "unknown output 'speed'", "sweep.sample.custom.speed")
    refused(tmp_path, capsys, write(tmp_path, extra='\n[sweep.grid]\n"payment.stake" = [0.0, 0.04]\n'),
            "either a grid and axes or a sample design")


def test_outputs_comparing_honest_and_byzantine_need_both_at_every_corner(tmp_path, capsys):
    body = SAMPLE.format(method="sobol", samples=8).replace('[1, 4]', '[0, 4]').replace(
        '["items"]', '["items", "share_gap"]')
    refused(tmp_path, capsys, write(tmp_path, body=body), "share_gap", "0 Byzantine")
    assert main(["check", str(write(tmp_path, body=body))]) == 2  # `check` checks the corners too
    assert "0 Byzantine" in capsys.readouterr().err
    # the same range is fine for an output that does not compare them
    assert main(["check", str(write(tmp_path, body=body.replace(', "share_gap"', "")))]) == 0


def test_two_keys_with_one_column_name_are_refused(tmp_path, capsys):
    body = SAMPLE.format(method="sobol", samples=8).replace(
        '{ range = [1, 4], name = "byzantines" }', '[1, 4]').replace(
        '"robot.noise_sd" = [0.0, 0.1]', '"swarm.robots" = [10, 12]\n"swarm.groups[0].params.threshold" = [0.1, 1.0]'
        '\n"swarm.groups[1].params.threshold" = [0.1, 1.0]')
    refused(tmp_path, capsys, write(tmp_path, body=body), "threshold", "give one of them a name")


def test_integer_keys_are_sampled_as_integers_over_their_whole_range(tmp_path):
    exp = im.load_experiment(write(tmp_path, samples=64))
    conds = conditions(exp)
    assert len(conds) == 64 * (2 * 2 + 2)  # Saltelli with second order: N (2D + 2)
    counts = [c.config.swarm.groups[1].count for c in conds]
    assert all(isinstance(n, int) for n in counts)
    assert set(counts) == {1, 2, 3, 4}
    share = np.bincount(counts, minlength=5)[1:] / len(counts)
    assert np.all(np.abs(share - 0.25) < 0.07)  # each integer about equally likely
    for c in conds:  # the remainder keeps the swarm whole; the condition's keys are what it ran
        assert c.config.swarm.groups[0].count == 10 - c.config.swarm.groups[1].count
        assert c.keys["byzantines"] == c.config.swarm.groups[1].count
        assert c.keys["noise_sd"] == c.config.robot.noise_sd
        assert 0.0 <= c.config.robot.noise_sd <= 0.1
    assert [c.id for c in conds[:3]] == ["point=0", "point=1", "point=2"]


def test_the_design_follows_the_experiments_seed(tmp_path):
    exp = im.load_experiment(write(tmp_path))
    a, b = make_design(exp), make_design(exp)
    np.testing.assert_array_equal(a.X, b.X)
    assert not np.array_equal(a.X, make_design(exp, seed=6).X)
    assert a.seed == 5 and make_design(exp, seed=6).seed == 6


def test_also_keys_take_the_sampled_value(tmp_path):
    body = SAMPLE.format(method="lhs", samples=24).replace(
        '"robot.noise_sd" = [0.0, 0.1]',
        '"swarm.groups[0].params.threshold" = { range = [0.1, 1.0], also = ["swarm.groups[1].params.threshold"] }')
    for c in conditions(im.load_experiment(write(tmp_path, body=body))):
        g = c.config.swarm.groups
        assert g[0].params["threshold"] == g[1].params["threshold"] == c.keys["threshold"]


def test_a_design_is_kept_in_the_store_resumed_and_not_mixed_with_another(tmp_path, capsys):
    path = write(tmp_path, method="sobol", samples=4)
    out = tmp_path / "store"
    conds = conditions(im.load_experiment(path))
    rep = run_sweep(conds[:10], Store(out))  # an interrupted sweep: 10 of the 24 points
    assert rep.done == 10
    kept = load(out, "design")
    np.testing.assert_array_equal(kept.X, conds[0].design.X)
    assert kept.points == 24 and kept.names == ["noise_sd", "byzantines"]
    assert main(["sweep", str(path), "--out", str(out), "--quiet"]) == 0
    runs = Store(out).runs()
    assert len(runs) == 24 and sorted(runs.point) == list(range(24))  # every point once
    robots = Store(out).robots()
    assert {"point", "noise_sd", "byzantines"} <= set(robots.columns)
    # another design of the same experiment into the same store is refused, the store untouched
    before = sorted(p.name for p in (out / "runs").iterdir())
    assert main(["sweep", str(path), "--samples", "2", "--out", str(out), "--quiet"]) == 2
    assert "design" in capsys.readouterr().err
    assert sorted(p.name for p in (out / "runs").iterdir()) == before
    assert load(out, "design").points == 24


def test_a_sobol_design_grows_in_its_store_and_runs_only_its_new_points(tmp_path):
    path = write(tmp_path, method="sobol", samples=4)
    out = tmp_path / "store"
    assert main(["sweep", str(path), "--out", str(out), "--quiet"]) == 0
    parts = {p.name: p.stat().st_mtime_ns for p in (out / "runs").iterdir()}
    small = Store(out).runs().set_index("point").sort_index()
    assert main(["sweep", str(path), "--samples", "8", "--out", str(out), "--quiet"]) == 0
    runs = Store(out).runs().set_index("point").sort_index()
    # (2 x 2 keys + 2) x 8 points (second order), each once; the first 24 are the runs made before, untouched
    assert list(runs.index) == list(range(48))
    assert {p.name: p.stat().st_mtime_ns for p in (out / "runs").iterdir() if p.name in parts} == parts
    assert list(runs.loc[:23, "duration_s"]) == list(small["duration_s"])
    grown = load(out, "design")
    assert grown.samples == 8 and grown.points == 48
    np.testing.assert_array_equal(grown.X, make_design(im.load_experiment(write(tmp_path, samples=8))).X)
    # the new points are the grown design's: the same seeds and values as a store made at 8 at once
    fresh = tmp_path / "fresh"
    assert main(["sweep", str(path), "--samples", "8", "--out", str(fresh), "--quiet"]) == 0
    once = Store(fresh).runs().set_index("point").sort_index()
    assert list(once.seed) == list(runs.seed) and list(once.noise_sd) == list(runs.noise_sd)
    pd.testing.assert_frame_equal(Store(fresh).robots().sort_values(["point", "robot"]).reset_index(drop=True)
                                  .drop(columns="duration_s", errors="ignore"),
                                  Store(out).robots().sort_values(["point", "robot"]).reset_index(drop=True)
                                  .drop(columns="duration_s", errors="ignore"))


def test_a_growth_cut_short_between_its_writes_reads_as_the_old_design(tmp_path):
    from infomarket.runner.design import _paths, save
    from infomarket.store.files import write_parquet_atomic

    store = Store(tmp_path / "s").create()
    small = make_design(im.load_experiment(write(tmp_path, samples=4)))
    big = make_design(im.load_experiment(write(tmp_path, samples=8)))
    save(store, small)
    write_parquet_atomic(big.frame(), _paths(store.root, "design")[1])  # the matrix written, not the settings
    kept = load(store.root, "design")
    assert kept.samples == 4 and kept.points == 24
    np.testing.assert_array_equal(kept.X, small.X)
    save(store, big)
    assert load(store.root, "design").points == 48



def test_the_store_keeps_one_design_per_experiment_but_outputs_may_change(tmp_path):
    from infomarket.runner.design import save

    store = Store(tmp_path / "s").create()
    exp = im.load_experiment(write(tmp_path, samples=4))
    first = make_design(exp)
    save(store, first)
    with pytest.raises(StoreError, match="other settings.*samples"):
        save(store, make_design(im.load_experiment(write(tmp_path, samples=2))))  # fewer: refused
    with pytest.raises(StoreError, match="other settings.*seed"):
        save(store, make_design(im.load_experiment(write(tmp_path, samples=8)), seed=6))  # grown, other seed
    body = SAMPLE.format(method="sobol", samples=4).replace('["items"]', '["items", "share_gap"]')
    save(store, make_design(im.load_experiment(write(tmp_path, body=body))))  # the analysis may change
    assert load(store.root, "design").outputs == ["items", "share_gap"]
    np.testing.assert_array_equal(load(store.root, "design").X, first.X)


def test_design_points_give_the_same_store_on_every_executor_and_rerun_alone(tmp_path):
    import pandas as pd

    exp = im.load_experiment(write(tmp_path, samples=4)).with_overrides(steps=200)
    conds = conditions(exp)
    tables = []
    for k, kw in enumerate(({"workers": 1}, {"workers": 2})):
        s = Store(tmp_path / f"s{k}")
        run_sweep(conds, s, **kw)
        tables.append(s.robots())
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        s = Store(tmp_path / "dask")
        run_sweep(conds, s, executor=client.get_executor(pure=False))
        tables.append(s.robots())
    for t in tables[1:]:
        pd.testing.assert_frame_equal(tables[0], t, check_exact=True)
    c = conds[7]  # any point rerun alone with its seed gives its rows
    alone = im.simulate(c.config, seed=c.seed(0)).robots
    row = tables[0][tables[0].condition == c.id].reset_index(drop=True)
    assert len(row) == 10 and (row.items_collected.to_numpy() == alone.items_collected.to_numpy()).all()
    assert (row.wealth.to_numpy() == alone.wealth.to_numpy()).all()


def test_grouped_points_keep_their_event_and_payment_logs(tmp_path):
    exp = im.load_experiment(write(tmp_path, samples=2)).with_overrides(steps=300)
    conds = conditions(exp)
    store = Store(tmp_path / "s")
    run_sweep(conds, store, record_events=True)
    assert len(list((tmp_path / "s" / "runs").glob("*.parquet"))) < len(conds)  # points share parts
    events = store.events()
    assert set(events.condition) <= {c.id for c in conds} and events.condition.nunique() > 1
    for c in conds[:3]:  # each point's log is its own run's log
        alone = im.simulate(c.config, seed=c.seed(0), record_events=True).events
        mine = events[events.condition == c.id]
        assert len(mine) == len(alone)
        assert (mine.step.to_numpy() == alone.step.to_numpy()).all()
