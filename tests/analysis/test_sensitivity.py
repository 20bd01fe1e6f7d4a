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
from infomarket.analysis import sensitivity as sensitivity_module
from infomarket.analysis.frames import MissingDataError
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


@pytest.fixture(autouse=True)
def few_pawn_resamples(monkeypatch):
    """PAWN's permutation test calls SALib once per shuffle; 20 are enough to check the machinery."""
    monkeypatch.setattr(sensitivity_module, "PAWN_PERMUTATIONS", 20)


@pytest.fixture(scope="module")
def replicated_store(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("replicated")
    p = tmp / "known.toml"
    text = KNOWN.format(method="sobol", samples=32, second="false").replace("runs = 1", "runs = 2")
    p.write_text(text.replace('outputs = ["honest_robots", "items"]', 'outputs = ["honest_robots", "drift"]')
                 + '\n[sweep.sample.custom.drift]\ncolumn = "drift"\nstat = "mean"\n')
    out = tmp / "store"
    assert main(["sweep", str(p), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    return out


def by_param(table: pd.DataFrame, output: str, index: str) -> pd.Series:
    return table[(table.output == output) & (table["index"] == index)].set_index("parameter")["value"]


def test_sobol_recovers_the_known_indices(sobol_store):
    s = from_store(sobol_store)
    for index in ("S1", "ST"):
        got = by_param(s.table, "honest_robots", index)
        assert got.sort_values(ascending=False).index[:2].tolist() == ["robots", "byzantines"]
        for p, want in S1.items():
            assert got[p] == pytest.approx(want, abs=0.1), (index, p)
    idle = s.table[(s.table.output == "honest_robots") & s.table.parameter.isin(["noise_sd", "stake"])
                   & s.table["index"].isin(["S1", "ST"])]
    assert (idle.value.abs() < 0.02).all() and (idle.high < 0.05).all()
    # PAWN ranks the two keys first too; the idle keys stay at the level a shuffled output reaches
    pawn = by_param(s.table, "honest_robots", "PAWN")
    null = by_param(s.table, "honest_robots", "PAWN_null")
    assert pawn.sort_values(ascending=False).index[:2].tolist() == ["robots", "byzantines"]
    assert pawn["robots"] > 2 * null["robots"] and pawn["byzantines"] > null["byzantines"]
    assert (pawn[["noise_sd", "stake"]] < null[["noise_sd", "stake"]]).all()
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
    csv = pd.read_csv(out / "sensitivity-known.csv", keep_default_na=False,
                      na_values={"conf": [""], "low": [""], "high": [""]})
    pd.testing.assert_frame_equal(table, csv, check_dtype=False)
    assert set(table["index"]) == {"S1", "ST", "PAWN", "PAWN_null"} and set(table.output) == {"honest_robots", "items"}
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
    # replicated points are the shipped default: 2 base samples x (8 + 2) points x 2 runs
    assert len(Store(store).runs()) == 2 * (8 + 2) * 2
    assert main(["sensitivity", str(store), "--out", str(out)]) == 0
    names = {p.name for p in out.iterdir()}
    # issue 21: named after the experiment, not sensitivity-sensitivity.*
    assert {"sensitivity.csv", "sensitivity.parquet", "sensitivity-indices.png", "sensitivity.md"} <= names
    assert not any(n.startswith("sensitivity-sensitivity") for n in names)
    table = pd.read_csv(out / "sensitivity.csv")
    assert set(table.output) == {"items", "share_gap", "byzantine_share"}
    assert set(table.parameter.dropna()) == {"noise_sd", "bias_mean", "communication_range", "threshold", "theta",
                                             "stake", "byzantines", "rotation_angle"}
    assert {"S1", "ST", "floor", "run_share", "PAWN"} <= set(table["index"])
    md = (out / "sensitivity.md").read_text()
    assert "## Global sensitivity: sensitivity" in md and "40 runs" in md
    # answered at another size than the declared one: every answer says so, precision is not answered
    assert "not the 256 x 2 declared" in md and "not answered (2 x 2 is not the declared size)" in md


def test_a_noisy_output_sits_on_a_floor_of_one_and_a_noiseless_one_on_zero(replicated_store):
    """honest_robots is a function of the design (no seed noise: floor 0 exactly); the mean |drift| of a
    run's robots is drawn from the run's seed only (no sampled key changes it): all its variance is seed
    noise, so its floor and run-level share are 1 up to sampling error."""
    s = from_store(replicated_store)
    floor = s.floor.set_index("output")
    assert floor.loc["honest_robots", "floor"] == 0 and floor.loc["honest_robots", "floor_high"] == 0
    drift = floor.loc["drift"]
    assert drift.runs_per_point == 2
    assert drift.floor_low < 1.0 < drift.floor_high and drift.floor_low > 0.6
    assert drift.run_share_low > 0.7
    # the floor is drawn on the figure, with its value in the legend, and every panel names its run count
    from infomarket.analysis.sensitivity_report import _bars

    fig = _bars(s)
    labels = [t.get_text() for ax in fig.axes for t in (ax.get_legend().get_texts() if ax.get_legend() else [])]
    assert any(lab.startswith("seed-noise floor of S_T") for lab in labels)
    titles = [ax.get_title(loc="left") for ax in fig.axes]
    assert titles and all("x 2 runs = " in t for t in titles)
    from .layout import problems

    assert problems(fig) == []  # nothing cut or overlapping; no legend over a bar (one hid a bar before)


def test_the_noise_floor_matches_a_hand_computation():
    """Four points of a hypercube design, two runs each: 4 +/- 1 around means 0, 2, 4, 6.  By hand:
    within-point variance (ddof 1) 2, so noise per mean 2 / 2 = 1; variance of the means (ddof 1)
    (9 + 1 + 1 + 9) / 3 = 20 / 3; floor = 1 / (20 / 3) = 0.15; run share = 2 / (20 / 3 - 1 + 2) = 6 / 23."""
    from infomarket.analysis.sensitivity import noise_floor
    from infomarket.runner.design import Design

    d = Design("toy", "lhs", 4, False, 4, 1, ["a", "b"], ["a", "b"], [[], []], [0.0, 0.0], [1.0, 1.0],
               [False, False], None, ["y"], {}, "test", X=np.zeros((4, 2)))
    runs = pd.DataFrame({"point": np.repeat(np.arange(4), 2), "y": [-1.0, 1.0, 1.0, 3.0, 3.0, 5.0, 5.0, 7.0]})
    f = noise_floor(runs, d).iloc[0]
    assert f.floor == pytest.approx(0.15) and f.run_share == pytest.approx(6 / 23)
    assert f.floor_low <= f.floor <= f.floor_high
    assert noise_floor(runs.iloc[::2], d).empty  # one run per point: no replicates, no floor


def _local(tmp_path, slope: float, seed: int = 3, noise: float = 1.0):
    """A replicated Morris design over the KNOWN experiment's keys, its runs made up: y = slope x noise_sd
    (in units of the key's range) + N(0, 1) seed noise, 4 runs per point."""
    from infomarket.analysis.sensitivity import Sensitivity, analyse, point_outputs
    from infomarket.runner.design import make_design

    p = tmp_path / "m.toml"
    p.write_text(KNOWN.format(method="morris", samples=40, second="false").replace("runs = 1", "runs = 4"))
    d = make_design(im.load_experiment(p))
    d = type(d).from_spec({**d.spec(), "outputs": ["y"]}, d.X)
    rng = np.random.default_rng(seed)
    x = d.X[:, 0] / 0.1
    runs = pd.DataFrame({"point": np.repeat(np.arange(d.points), 4),
                         "y": np.repeat(slope * x, 4) + rng.normal(0.0, noise, 4 * d.points)})
    points = point_outputs(runs, d)
    return Sensitivity(d, analyse(d, points), points, runs)


def test_local_robustness_tells_a_flat_box_from_a_slope(tmp_path):
    from infomarket.analysis.sensitivity import local_robustness, morris_noise

    flat = _local(tmp_path, 0.0)
    reference = pd.DataFrame({"y": np.linspace(0.0, 100.0, 101)})  # 5-95 % range 90: tolerance 4.5
    verdict, params = local_robustness(flat, reference)
    row = verdict.iloc[0]
    assert row.tolerance == pytest.approx(0.05 * 90.0)
    assert row.robust == "yes" and row.spread_high < row.tolerance
    # pure noise: Morris mu* is what noise alone gives, sqrt(2/pi) sqrt(2 * 1 / 4) / (4 / 6) = 0.846
    assert morris_noise(flat, "y") == pytest.approx(np.sqrt(2 / np.pi) * np.sqrt(0.5) / (4 / 6), rel=0.15)
    assert not params.moves.any()
    # loud seed noise (sd 3: the means of 4 runs spread by 1.5) and no effect, against a tolerance of 1
    # (5 % of a range of 20): the spread of the means alone would say "not robust"; noise removed, robust
    loud = _local(tmp_path, 0.0, noise=3.0)
    row = local_robustness(loud, pd.DataFrame({"y": np.linspace(0.0, 200 / 9, 101)}))[0].iloc[0]
    assert row.tolerance == pytest.approx(1.0)
    assert loud.points["y"].std() > 1.2 and row.robust == "yes", row
    steep = _local(tmp_path, 40.0)  # uniform levels 0, 1/3, 2/3, 1 of a 40-wide slope: sd about 15
    verdict, params = local_robustness(steep, reference)
    assert verdict.iloc[0].robust == "no" and verdict.iloc[0].spread_low > 4.5
    assert params.set_index("parameter").moves.to_dict() == {"noise_sd": True, "robots": False, "stake": False,
                                                             "byzantines": False}
    # a design without replicates cannot be judged
    one = _local(tmp_path, 0.0)
    one.runs = one.runs.groupby("point").head(1)
    with pytest.raises(MissingDataError, match="replicates"):
        local_robustness(one, reference)


def test_the_command_judges_a_point_from_a_local_design(replicated_store, tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["sensitivity", str(replicated_store), "--out", str(out), "--local", str(replicated_store)]) == 0
    rows = pd.read_csv(out / "sensitivity-known-robustness.csv")
    assert set(rows.output) == {"honest_robots", "drift"} and set(rows.robust) <= {"yes", "no", "inconclusive"}
    # the bin-by-bin comparison of the global design is gone (issue 24): --at is refused
    with pytest.raises(SystemExit) as exc:
        main(["sensitivity", str(replicated_store), "--out", str(tmp_path / "p"), "--at", "robots=12"])
    assert exc.value.code == 2
