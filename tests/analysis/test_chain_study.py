"""The chain study's answers (analysis.chain_study) on synthetic runs whose answer is known by
construction: a chain that leaves the Byzantines' share where the instant ledger has it ("yes"), one that
gives them 12 points more against a 5-point margin ("no"), three runs a group ("inconclusive", n too
small); the smallest breaking period; the CLI on a store written through the real Store writer."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from infomarket.analysis import chain_study as cs
from infomarket.analysis import stats as st
from infomarket.cli import main

from .synthetic import write_store

DECL = cs.declaration()


def _rows(experiment, n, rng, *, centre, sd, col="byz_share", **keys):
    out = pd.DataFrame({"experiment": experiment, "run": np.arange(n), col: rng.normal(centre, sd, n)})
    out["condition"] = ",".join(f"{k}={v}" for k, v in sorted(keys.items()))
    for k, v in keys.items():
        out[k] = v
    return out


def paper_runs(rng, n=24, shift=0.0, settings=("toychain",)) -> pd.DataFrame:
    """chain_paper's per-run Byzantine shares: instant at 2k % (sd 0.5), each chain setting + ``shift``."""
    frames = []
    for payment in ("outlier", "staking"):
        for k in (1, 3, 5):
            frames.append(_rows(cs.PAPER, n, rng, centre=2.0 * k, sd=0.5, chain="instant", payment=payment,
                                byzantines=k))
            for s in settings:
                frames.append(_rows(cs.PAPER, n, rng, centre=2.0 * k + shift, sd=0.5, chain=s, payment=payment,
                                    byzantines=k))
    return pd.concat(frames, ignore_index=True)


def fig7_runs(rng, n=24, gain=60.0, experiment=cs.FIG7, settings=("instant", "toychain"), angles=(45.0, 90.0)):
    frames = []
    for s in settings:
        for a in angles:
            keys = {"rotation_angle": a} if experiment == cs.FIG7 else {}
            frames.append(_rows(experiment, n, rng, centre=250.0 + gain, sd=10.0, col="items", chain=s,
                                market="staking", **keys))
            frames.append(_rows(experiment, n, rng, centre=250.0, sd=10.0, col="items", chain=s,
                                market="no_staking", **keys))
    return pd.concat(frames, ignore_index=True)


# ------------------------------------------------------------------------------------------ per run
def test_per_run_by_hand():
    # one run, 4 robots: shares 0.4, 0.3 honest, 0.2, 0.1 Byzantine; items 3, 2, 1, 0
    robots = pd.DataFrame({"experiment": "chain_paper", "condition": "c", "run": 0,
                           "honest": [True, True, False, False],
                           "wealth_share": [0.4, 0.3, 0.2, 0.1], "items_collected": [3, 2, 1, 0],
                           "chain": "toychain", "payment": "staking", "byzantines": 2})
    r = cs.per_run(robots).iloc[0]
    assert r["byz_share"] == pytest.approx(30.0)          # (0.2 + 0.1) x 100
    assert r["gap"] == pytest.approx(35.0 - 15.0)          # mean honest 0.35, mean Byzantine 0.15, in pp
    assert r["items"] == 6 and r["chain"] == "toychain" and r["byzantines"] == 2


# ------------------------------------------------------------------------------------------ wealth
def test_wealth_yes_when_the_chain_leaves_the_share_alone():
    runs = paper_runs(np.random.default_rng(1), shift=0.0)
    v = cs.wealth_question(runs, DECL, "toychain")
    assert v.answer == st.YES, v.details


def test_wealth_no_when_the_chain_gives_byzantines_more_than_the_margin():
    # +12 pp everywhere; the margins are 1, 3, 5 pp (k Byzantines): every condition breaks
    runs = paper_runs(np.random.default_rng(2), shift=12.0)
    v = cs.wealth_question(runs, DECL, "toychain")
    assert v.answer == st.NO
    assert sum("BREAKS" in d for d in v.details) == 6


def test_wealth_lower_on_the_chain_is_not_a_break():
    # the rule is non-inferiority: a chain that leaves the Byzantines LESS still holds
    runs = paper_runs(np.random.default_rng(3), shift=-1.0)
    assert cs.wealth_question(runs, DECL, "toychain").answer == st.YES


def test_wealth_inconclusive_with_three_runs():
    # 3 vs 3 runs: the smallest one-sided p is 1 / C(6, 3) = 0.05, not below 0.05 / 6
    runs = paper_runs(np.random.default_rng(4), n=3, shift=0.0)
    v = cs.wealth_question(runs, DECL, "toychain")
    assert v.answer == st.INCONCLUSIVE and v.note == st.N_TOO_SMALL


def test_wealth_not_run_without_the_setting():
    runs = paper_runs(np.random.default_rng(5))
    assert cs.wealth_question(runs, DECL, "geth_argos").answer == cs.NOT_RUN


# ------------------------------------------------------------------------------------------ Fig. 7
def test_fig7_yes_no_inconclusive():
    rng = np.random.default_rng(6)
    assert cs.fig7_question(fig7_runs(rng, gain=60.0), DECL, "toychain").answer == st.YES
    # no gain: d = 10 % of 250 = 25 items; gain < 25 is shown -> no
    assert cs.fig7_question(fig7_runs(rng, gain=0.0), DECL, "toychain").answer == st.NO
    v = cs.fig7_question(fig7_runs(rng, n=3, gain=60.0), DECL, "toychain")
    assert v.answer == st.INCONCLUSIVE and v.note == st.N_TOO_SMALL


def test_fig7_gain_margin_comes_from_the_instant_ledger():
    # instant no-staking median 250 -> d = 25: a true gain of 40 on the chain helps, is not "below d"
    rng = np.random.default_rng(7)
    runs = pd.concat([fig7_runs(rng, gain=0.0, settings=("instant",)),
                      fig7_runs(rng, gain=40.0, settings=("toychain",))])
    assert cs._d(runs, DECL, 90.0) == pytest.approx(0.1 * np.median(
        runs[(runs.chain == "instant") & (runs.market == "no_staking") & (runs.rotation_angle == 90.0)]["items"]))
    assert cs.fig7_question(runs, DECL, "toychain").answer == st.YES


# ------------------------------------------------------------------------------------------ where it breaks
def sweep_runs(rng, broken: set[str], n=24) -> pd.DataFrame:
    """chain_sweep runs at every declared period: shares as instant, +12 pp at the ``broken`` labels."""
    frames = []
    for _, label in cs.axis_values(DECL, "period"):
        if label == "toychain":
            continue
        for payment in ("outlier", "staking"):
            frames.append(_rows(cs.SWEEP, n, rng, centre=10.0 + (12.0 if label in broken else 0.0), sd=0.5,
                                chain=label, payment=payment))
    return pd.concat(frames, ignore_index=True)


def test_breaks_at_the_smallest_breaking_period():
    rng = np.random.default_rng(8)
    runs = pd.concat([paper_runs(rng), sweep_runs(rng, {"period_50", "period_500"}), fig7_runs(rng)])
    v = cs.breaks_question(runs, DECL, "period")
    assert v.answer == st.YES and v.value == 50
    # the Fig. 7 half was not run below 50, so 50 is an upper bound of the smallest breaking period
    assert v.note == ("Fig. 7 not run at period 1, 5, 20, 50, 500; breaks at or below 50: a value below it is not "
                      "fully run")
    # period 150 (toychain, from chain_paper) holds between the two broken values
    assert any(d.startswith("period 150 (toychain): holds") for d in v.details)


def test_breaks_no_when_it_holds_everywhere_and_fig7_breaks_it_too():
    rng = np.random.default_rng(9)
    base = [paper_runs(rng), sweep_runs(rng, set()), fig7_runs(rng)]
    assert cs.breaks_question(pd.concat(base), DECL, "period").answer == st.NO
    # the Fig. 7 half alone breaks it at period 5: staking gains nothing there
    f7 = []
    for _, label in cs.axis_values(DECL, "period"):
        if label != "toychain":
            f7.append(fig7_runs(rng, n=12, gain=0.0 if label == "period_5" else 60.0, experiment=cs.FIG7_SWEEP,
                                settings=(label,), angles=(90.0,)))
    v = cs.breaks_question(pd.concat(base + f7), DECL, "period")
    assert v.answer == st.YES and v.value == 5 and v.note == ""


def test_breaks_not_run_without_sweeps():
    assert cs.breaks_question(paper_runs(np.random.default_rng(10)).iloc[0:0], DECL, "loss").answer == cs.NOT_RUN


def test_partition_pending_without_its_runs():
    forks, rich = cs.partition_questions(paper_runs(np.random.default_rng(11)), None, DECL)
    assert forks.answer == rich.answer == cs.PENDING


# ------------------------------------------------------------------------------------------ CLI
def _store_robots(rng, shift: float) -> pd.DataFrame:
    """chain_paper robots tables (25 robots, 12 runs per condition, staking, 5 Byzantines only)."""
    frames = []
    for chain in ("instant", "toychain"):
        for run in range(12):
            share = np.full(25, 0.95 / 20)
            byz = (0.05 + (shift / 100 if chain == "toychain" else 0.0) + rng.normal(0, 0.002)) / 5
            share[20:] = byz
            share[:20] = (1 - 5 * byz) / 20
            frames.append(pd.DataFrame({
                "experiment": cs.PAPER, "condition": f"byzantines=5,chain={chain},payment=staking", "run": run,
                "seed": np.uint64(100 + run), "robot": np.arange(25),
                "behaviour": ["sceptical"] * 20 + ["scaboteur"] * 5,
                "honest": [True] * 20 + [False] * 5, "drift": 0.0, "items_collected": np.full(25, 3),
                "wealth": share * 25, "wealth_share": share,
                "byzantines": 5, "chain": chain, "payment": "staking"}))
    robots = pd.concat(frames, ignore_index=True)
    return robots


def _write(tmp_path, shift):
    robots = _store_robots(np.random.default_rng(12), shift)
    parts = {}
    for cond, rows in robots.groupby("condition"):
        runs = rows.groupby(["experiment", "condition", "run", "byzantines", "chain", "payment"],
                            as_index=False)["seed"].first()
        runs = runs.assign(config_hash="cafe", package_version="0.1.0", duration_s=0.1, steps=15000, transitory=0,
                           status="ok")
        parts[cond.replace(",", "_").replace("=", "-")] = (rows.reset_index(drop=True), runs, None)
    return write_store(tmp_path / "store", parts)


@pytest.mark.parametrize("shift, expected", [(0.0, "yes (1 of 6 conditions run)"),
                                             (15.0, "no (1 of 6 conditions run)")])
def test_cli_writes_answers_and_figure(tmp_path, capsys, shift, expected):
    # only Fig. 4C's condition is in the store (12 runs a ledger): +15 pp on the chain breaks it against
    # its 5 pp margin; without a shift it holds; either answer says it rests on 1 of the 6 conditions
    _write(tmp_path, shift)
    out = tmp_path / "report"
    assert main(["chain-study", str(tmp_path / "store"), "--out", str(out)]) == 0
    table = pd.read_csv(out / "chain-study.csv")
    row = table[table.question == "wealth_toychain"].iloc[0]
    assert row["answer"] == expected
    assert (out / "chain-study.png").stat().st_size > 10_000
    assert "wealth_toychain" in (out / "chain-study.md").read_text()
    assert table.set_index("question").loc["partition_forks", "answer"].startswith("pending")
    # the sweeps are not in the store: holding at toychain alone is not "holds at every period", and
    # breaking there says only "at or below 150"
    period = table.set_index("question").loc["breaks_period", "answer"]
    assert period.startswith("yes, at period 150 (") and "at or below 150" in period if shift else \
        period.startswith("inconclusive")


def test_cli_bad_store_is_exit_2(tmp_path, capsys):
    assert main(["chain-study", str(tmp_path / "missing"), "--out", str(tmp_path / "o")]) == 2
    assert not (tmp_path / "o").exists()


def test_wealth_inconclusive_when_one_condition_sits_on_its_margin():
    # Figs. 3C/4C (5 Byzantines) shifted by exactly their 5 pp margin: neither within it nor beyond it is
    # shown; the other four hold.  "yes" needs all six, so the answer is inconclusive (and 24 runs had the
    # power to show non-inferiority had nothing differed: no "n too small")
    rng = np.random.default_rng(13)
    runs = paper_runs(rng)
    at5 = (runs.chain == "toychain") & (runs.byzantines == 5)
    runs.loc[at5, "byz_share"] += 5.0
    v = cs.wealth_question(runs, DECL, "toychain")
    assert v.answer == st.INCONCLUSIVE and v.note == ""
    assert sum("undecided" in d for d in v.details) == 2 and sum(": holds;" in d for d in v.details) == 4


def test_fig7_no_when_staking_helps_at_one_angle_only():
    # helps at 45 degrees (gain 60), nothing at 90: shown not to help at 90 -> no (not yes, not inconclusive)
    rng = np.random.default_rng(14)
    runs = pd.concat([fig7_runs(rng, gain=60.0, angles=(45.0,)), fig7_runs(rng, gain=0.0, angles=(90.0,))])
    v = cs.fig7_question(runs, DECL, "toychain")
    assert v.answer == st.NO
    assert any(d.startswith("45 deg: helps") for d in v.details)
    assert any(d.startswith("90 deg: does NOT") for d in v.details)


def partition_runs(rng, shift: float, col="byz_share", centre=4.0, sd=0.5, n=24) -> pd.DataFrame:
    frames = []
    for base in ("toychain", "backbone"):
        frames.append(_rows(cs.PARTITION, n, rng, centre=centre, sd=sd, col=col, base=base, partition="none"))
        frames.append(_rows(cs.PARTITION, n, rng, centre=centre + shift, sd=sd, col=col, base=base, partition="on"))
    return pd.concat(frames, ignore_index=True)


def test_partition_rules_once_its_runs_exist():
    rng = np.random.default_rng(15)
    # the Byzantines' share 10 pp higher with the partition (margin 5): who gets rich changes -> yes;
    # reorganised transactions 50 with it, 0 without -> forks that undo payments -> yes
    chain = partition_runs(rng, 50.0, col="reorganised_tx", centre=0.0, sd=0.0)
    chain["reorganised_tx"] = chain["reorganised_tx"] + np.where(chain["partition"] == "on",
                                                                 rng.integers(0, 5, len(chain)), 0)
    forks, rich = cs.partition_questions(partition_runs(rng, 10.0), chain, DECL)
    assert (forks.answer, rich.answer) == (st.YES, st.YES)
    # the same share with and without (equivalent within 5 pp) and no chain measures stored
    forks, rich = cs.partition_questions(partition_runs(rng, 0.0), None, DECL)
    assert (forks.answer, rich.answer) == (cs.PENDING, st.NO)
    # reorganised transactions unchanged by the partition (200 +- 5 either way): shown below none + 20
    chain = partition_runs(rng, 0.0, col="reorganised_tx", centre=200.0, sd=5.0)
    assert cs.partition_questions(partition_runs(rng, 0.0), chain, DECL)[0].answer == st.NO
