"""Global sensitivity through the whole machinery (design -> sweep -> store -> SALib), on a known function.

The swarm's number of honest robots is ``robots - byzantines``: it depends on two of the four sampled
keys only.  Both are integers drawn uniformly, so by hand (variance of a discrete uniform on n values:
(n^2 - 1) / 12) Var(robots on 12..30) = (19^2 - 1) / 12 = 30 and Var(byzantines on 0..10) =
(11^2 - 1) / 12 = 10: the first-order (and total) indices are 30 / 40 = 0.75 and 10 / 40 = 0.25, and
the idle keys (noise, stake) have 0.  The runs are 2 steps long: the value comes out of the engine's
robots table, through the store, whatever the dynamics.
"""
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import infomarket as im
from infomarket.analysis.sensitivity import from_store, run_outputs, sensitivity
from infomarket.cli import main
from infomarket.runner.design import load
from infomarket.runner.plan import conditions
from infomarket.runner.sweep import run_sweep
from infomarket.store import Store

KNOWN = """
name = "known"
steps = 2
runs = 1
seed = 7

[swarm]
robots = 20

[[swarm.groups]]
behaviour = "naive"
count = 15

[[swarm.groups]]
behaviour = "saboteur"
count = 5

[sweep.sample]
method = "{method}"
samples = {samples}
second_order = {second}
remainder = "swarm.groups[0].count"
outputs = ["honest_robots", "items"]

[sweep.sample.custom.honest_robots]
column = "honest"
stat = "sum"

[sweep.sample.bounds]
"robot.noise_sd" = [0.0, 0.1]
"swarm.robots" = [12, 30]
"payment.stake" = [0.0, 0.1]
"swarm.groups[1].count" = {{ range = [0, 10], name = "byzantines" }}
"""
S1 = {"robots": 0.75, "byzantines": 0.25, "noise_sd": 0.0, "stake": 0.0}


def sweep(tmp_path: Path, method: str, samples: int, second: bool = False) -> Path:
    p = tmp_path / f"known-{method}.toml"
    p.write_text(KNOWN.format(method=method, samples=samples, second=str(second).lower()))
    out = tmp_path / f"store-{method}"
    assert main(["sweep", str(p), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    return out


@pytest.fixture(scope="module")
def sobol_store(tmp_path_factory):
    return sweep(tmp_path_factory.mktemp("sobol"), "sobol", 128)


def by_param(table: pd.DataFrame, output: str, index: str) -> pd.Series:
    return table[(table.output == output) & (table["index"] == index)].set_index("parameter")["value"]


def test_sobol_recovers_the_known_indices(sobol_store):
    s = from_store(sobol_store)
    for index in ("S1", "ST"):
        got = by_param(s.table, "honest_robots", index)
        assert got.sort_values(ascending=False).index[:2].tolist() == ["robots", "byzantines"]
        for p, want in S1.items():
            assert got[p] == pytest.approx(want, abs=0.1), (index, p)
    idle = s.table[(s.table.output == "honest_robots") & s.table.parameter.isin(["noise_sd", "stake"])]
    assert (idle.value.abs() < 0.02).all() and (idle.high < 0.05).all()
    # the per-point outputs are the function itself, point by point in the design's order
    design = load(sobol_store, "known")
    frame = design.frame()
    np.testing.assert_array_equal(s.points["honest_robots"].to_numpy(), (frame.robots - frame.byzantines).to_numpy())


def test_the_analysis_runs_on_dataframes_and_any_robots_column(sobol_store):
    robots = Store(sobol_store).robots()
    design = load(sobol_store, "known")
    runs = run_outputs(robots, design)
    assert len(runs) == design.points and runs["items"].ge(0).all()
    # a notebook's own table: shuffled rows give the same indices (points are matched by key, not order)
    a = sensitivity(robots, design).table
    b = sensitivity(robots.sample(frac=1.0, random_state=1), design).table
    pd.testing.assert_frame_equal(a, b)


def test_the_command_writes_table_figures_and_report(sobol_store, tmp_path, capsys):
    out = tmp_path / "sens"
    assert main(["sensitivity", str(sobol_store), "--out", str(out)]) == 0
    names = {p.name for p in out.iterdir()}
    assert {"sensitivity-known.csv", "sensitivity-known.parquet", "sensitivity-known-indices.png",
            "sensitivity-known-indices.svg", "sensitivity-known.md"} <= names
    table = pd.read_parquet(out / "sensitivity-known.parquet")
    pd.testing.assert_frame_equal(table, pd.read_csv(out / "sensitivity-known.csv", keep_default_na=False, na_values={"conf": [""], "low": [""], "high": [""]}),
                                  check_dtype=False)
    assert set(table["index"]) == {"S1", "ST"} and set(table.output) == {"honest_robots", "items"}
    assert "honest_robots" in capsys.readouterr().out
    rep = tmp_path / "rep"
    assert main(["figures", str(sobol_store), "--out", str(rep)]) == 0
    md = (rep / "report.md").read_text()
    assert "## Global sensitivity: known" in md and "sensitivity-known-indices.png" in md
    assert "Global sensitivity: known" in (rep / "report.html").read_text()


def test_morris_ranks_the_two_keys_and_gives_idle_keys_zero(tmp_path):
    s = from_store(sweep(tmp_path, "morris", 12))
    mu = by_param(s.table, "honest_robots", "mu_star")
    # elementary effects over the sampled span (robots 19 wide, byzantines 11 wide, in the design's units)
    assert mu.sort_values(ascending=False).index.tolist()[:2] == ["robots", "byzantines"]
    assert mu["noise_sd"] == 0 and mu["stake"] == 0
    assert mu["robots"] > 1.3 * mu["byzantines"] > 0


def test_a_latin_hypercube_is_analysed_with_rbd_fast(tmp_path):
    s = from_store(sweep(tmp_path, "lhs", 200))
    got = by_param(s.table, "honest_robots", "S1")
    assert got.sort_values(ascending=False).index.tolist()[:2] == ["robots", "byzantines"]
    assert got["robots"] == pytest.approx(0.75, abs=0.15) and got["byzantines"] == pytest.approx(0.25, abs=0.15)
    assert abs(got["noise_sd"]) < 0.1 and abs(got["stake"]) < 0.1


def test_second_order_indices_and_their_heat_map(tmp_path):
    store = sweep(tmp_path, "sobol", 16, second=True)
    s = from_store(store)
    s2 = s.table[s.table["index"] == "S2"]
    assert len(s2) == 2 * 6  # two outputs x (4 choose 2) pairs
    out = tmp_path / "f"
    assert main(["sensitivity", str(store), "--out", str(out)]) == 0
    assert (out / "sensitivity-known-S2.png").exists()


def test_an_incomplete_design_or_a_store_without_one_is_refused(tmp_path, capsys):
    p = tmp_path / "k.toml"
    p.write_text(KNOWN.format(method="sobol", samples=4, second="false"))
    store = tmp_path / "store"
    run_sweep(conditions(im.load_experiment(p))[:5], Store(store))
    assert main(["sensitivity", str(store), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "19 of the design's 24 points" in err and "resume" in err
    assert not (tmp_path / "o").exists()
    plain = Store(tmp_path / "plain").create()
    assert main(["sensitivity", str(plain.root), "--out", str(tmp_path / "o")]) == 2
    assert "holds no sampled design" in capsys.readouterr().err
    assert main(["sensitivity", str(tmp_path / "nowhere"), "--out", str(tmp_path / "o")]) == 2
    assert "not an infomarket results store" in capsys.readouterr().err


def test_the_shipped_study_runs_at_reduced_size(tmp_path, capsys):
    store, out = tmp_path / "s", tmp_path / "r"
    assert main(["sweep", "sensitivity", "--samples", "2", "--out", str(store), "--quiet"]) == 0
    assert len(Store(store).runs()) == 2 * (8 + 2)
    assert main(["sensitivity", str(store), "--out", str(out)]) == 0
    table = pd.read_csv(out / "sensitivity-sensitivity.csv")
    assert set(table.output) == {"items", "share_gap", "byzantine_share"}
    assert set(table.parameter) == {"noise_sd", "bias_mean", "communication_range", "threshold", "theta", "stake",
                                    "byzantines", "rotation_angle"}
    assert (out / "sensitivity-sensitivity-indices.png").exists()
    assert "## Global sensitivity: sensitivity" in (out / "sensitivity-sensitivity.md").read_text()


def test_local_robustness_compares_the_points_bin_with_its_neighbours(sobol_store, tmp_path):
    from infomarket.analysis.sensitivity import robustness

    s = from_store(sobol_store)
    runs = run_outputs(Store(sobol_store).robots(), s.design)
    rows = robustness(s, runs, {"robots": 12, "byzantines": 5, "noise_sd": 0.05}).set_index(["output", "parameter"])
    # only the parameters that drive an output are examined (noise is idle, items are all 0 in 2 steps)
    assert set(rows.index) == {("honest_robots", "robots"), ("honest_robots", "byzantines")}
    edge = rows.loc[("honest_robots", "robots")]
    # integer key: the bin is the value itself; at the low edge the only neighbour is 13 robots
    assert edge.runs_in_bin == (runs.merge(s.design.frame()[["point", "robots"]], on="point").robots == 12).sum()
    assert edge.median_in_bin < edge.median_adjacent  # one more robot, one more honest robot
    assert bool(edge.robust) == (abs(edge.difference) < 0.1 * edge.range_5_95)
    assert robustness(s, runs, {"robots": 12}, tolerance=0.0).robust.eq(False).all()
    assert main(["sensitivity", str(sobol_store), "--out", str(tmp_path / "o"), "--at", "robots=12,byzantines=5"]) == 0
    assert (tmp_path / "o" / "sensitivity-known-robustness.csv").exists()
    assert main(["sensitivity", str(sobol_store), "--out", str(tmp_path / "p"), "--at", "speed=3"]) == 2
    assert not (tmp_path / "p").exists()
