import math

import numpy as np

import pytest

from infomarket.analysis import headline
from infomarket.analysis.headline import FAIL, INCONCLUSIVE, NO_DATA, PASS, Rule, headline_table, load_rules

from .synthetic import paper_like, write_store


def verdicts(table) -> dict[str, str]:
    return dict(zip(table["id"], table["verdict"]))


def test_every_rule_has_a_metric_and_every_metric_a_rule():
    assert set(load_rules()) == set(headline.METRICS)


#: The loosest bound each row may ever declare, from the paper's wording and the issue that set the
#: rules (see the reasoning comments in tolerances.toml).  A row may be made stricter, never looser:
#: ("min", x) / ("above", x) are lower bounds, ("max", x) / ("below", x) upper bounds; above/below strict.
LOOSEST = {
    "fig2A_median": [("min", 18), ("max", 22)],
    "fig2B_halves": [("max", 0.65)],
    "fig2B_saboteur_gains": [("min", 0)],
    "fig2C_below_2A": [("below", 0)],
    "fig2C_wider": [("above", 1.0)],
    "fig2D_vs_2B": [("min", 1.5)],
    "fig2D_vs_2C": [("min", -3), ("max", 3)],
    "fig3A_scaboteur_share": [("max", 3.6)],
    "fig3A_honest_share": [("above", 4.0)],
    "fig3_gap_shrinks": [("above", 0)],
    **{f"fig{n}{p}_mannwhitney": [("below", 0.001)] for n in (3, 4) for p in "ABC"},
    **{f"fig4{p}_gap_larger": [("above", 0)] for p in "ABC"},
    "fig5_scaboteurs_poor": [("max", 1.0)],
    "fig5_honest_grows": [("above", 0)],
    "fig6A_pearson": [("min", -0.54 - 0.15), ("max", -0.54 + 0.15)],
    "fig6B_pearson": [("min", -0.64 - 0.15), ("max", -0.64 + 0.15)],
    "fig7B_staking_helps": [("min", 1.0)],
    "fig7A_no_difference": [("max", 10.0)],
}


def _as_strict_as(rule: Rule, kind: str, limit: float) -> bool:
    """Does ``rule`` bound the value at least as tightly as ``kind`` ``limit`` does?"""
    eps = 1e-12
    if kind in ("min", "above"):
        lows = [(v, k == "above") for k, v in (("min", rule.min), ("above", rule.above)) if v is not None]
        return any(v > limit + eps or (abs(v - limit) <= eps and (strict or kind == "min")) for v, strict in lows)
    highs = [(v, k == "below") for k, v in (("max", rule.max), ("below", rule.below)) if v is not None]
    return any(v < limit - eps or (abs(v - limit) <= eps and (strict or kind == "max")) for v, strict in highs)


def test_the_declared_tolerances_are_no_wider_than_the_issue_allows():
    """Guards every row against widening a rule until it passes."""
    rules = load_rules()
    assert set(rules) == set(LOOSEST), "every row of tolerances.toml needs its loosest bound declared here"
    for rid, limits in LOOSEST.items():
        for kind, limit in limits:
            assert _as_strict_as(rules[rid], kind, limit), f"rows.{rid}: wider than {kind} = {limit}"


@pytest.mark.parametrize("rule, kind, limit, ok", [
    (Rule("r", "f", "c", "p", min=18), "min", 18, True),
    (Rule("r", "f", "c", "p", min=17.9), "min", 18, False),
    (Rule("r", "f", "c", "p", above=18), "min", 18, True),
    (Rule("r", "f", "c", "p", min=4.0), "above", 4.0, False),  # inclusive is looser than strict
    (Rule("r", "f", "c", "p", min=4.1), "above", 4.0, True),
    (Rule("r", "f", "c", "p", max=0.001), "below", 0.001, False),
    (Rule("r", "f", "c", "p", below=0.01), "below", 0.001, False),
    (Rule("r", "f", "c", "p", max=3.5), "max", 3.6, True),
    (Rule("r", "f", "c", "p", min=0), "max", 3.6, False),  # a missing upper bound is the widest of all
])
def test_the_widening_guard_itself(rule, kind, limit, ok):
    assert _as_strict_as(rule, kind, limit) is ok


def test_every_rule_states_the_paper_value_and_the_reason_for_its_bounds():
    text = headline.TOLERANCES.read_text()
    for rid, rule in load_rules().items():
        assert rule.paper and rule.claim and rule.figure, rid
        block = text.split(f"[rows.{rid}]\n")[1].split("\n[rows.")[0]
        assert any(line.startswith("# ") for line in block.splitlines()), f"rows.{rid}: no reasoning comment"


@pytest.mark.parametrize("rule, value, ok", [
    (Rule("r", "f", "c", "p", min=18, max=22), 18, True),
    (Rule("r", "f", "c", "p", min=18, max=22), 22.5, False),
    (Rule("r", "f", "c", "p", above=4.0), 4.0, False),
    (Rule("r", "f", "c", "p", above=4.0), 4.01, True),
    (Rule("r", "f", "c", "p", below=0.001), 0.0009, True),
    (Rule("r", "f", "c", "p", below=0.001), 0.001, False),
    (Rule("r", "f", "c", "p", max=3.6), math.nan, False),
])
def test_rule_bounds_are_inclusive_or_strict_as_declared(rule, value, ok):
    assert rule.passes(value) is ok


def test_rule_describes_its_bounds():
    assert Rule("r", "f", "c", "p", min=-0.69, max=-0.39).describe() == "[-0.69, -0.39]"
    assert Rule("r", "f", "c", "p", below=0.001).describe() == "< 0.001"


def test_a_store_like_the_paper_passes_every_row(paper_store):
    table = headline_table(paper_store)
    assert list(table["verdict"]) == [PASS] * len(load_rules()), table[table.verdict != PASS]
    assert list(table.columns) == headline.COLUMNS


def test_honest_robots_clearly_richer_give_p_below_0001(paper_store):
    table = headline_table(paper_store).set_index("id")
    for rid in [f"fig{n}{p}_mannwhitney" for n in (3, 4) for p in "ABC"]:
        assert table.loc[rid, "value"] < 0.001
        assert table.loc[rid, "verdict"] == PASS


def test_honest_robots_not_richer_fail_the_wealth_rows(equal_wealth_store):
    v = verdicts(headline_table(equal_wealth_store))
    for rid in [f"fig{n}{p}_mannwhitney" for n in (3, 4) for p in "ABC"]:
        assert v[rid] == FAIL, rid
    assert v["fig3A_scaboteur_share"] == FAIL
    assert v["fig2A_median"] == PASS  # rows about items are untouched


def test_missing_experiments_give_no_data_rows_not_errors(tmp_path):
    store = write_store(tmp_path / "s", paper_like(), only=("fig2",))
    v = verdicts(headline_table(store))
    assert v["fig2A_median"] == PASS
    assert all(v[rid] == NO_DATA for rid in v if not rid.startswith("fig2"))


def test_weaker_correlation_than_the_paper_fails(paper_frames):
    robots = paper_frames.robots.copy()
    sel = robots.experiment == "fig6A"
    robots.loc[sel, "drift"] = robots.loc[sel, "drift"].sample(frac=1, random_state=0).to_numpy()  # r ~ 0
    v = verdicts(headline_table({"robots": robots, "history": paper_frames.history}))
    assert v["fig6A_pearson"] == FAIL and v["fig6B_pearson"] == PASS


def test_staking_that_does_not_help_three_byzantines_fails(paper_frames):
    robots = paper_frames.robots.copy()
    byz3 = (robots.experiment == "fig7") & (robots.byzantines == 3) & (robots.market == "no_staking")
    robots.loc[byz3, "items_collected"] += 5  # no staking now does better at every angle
    v = verdicts(headline_table(robots))
    assert v["fig7B_staking_helps"] == FAIL and v["fig7A_no_difference"] == PASS


def test_headline_table_takes_frames_dicts_and_paths(paper_store, paper_frames):
    a = headline_table(paper_store.root)
    b = headline_table({"robots": paper_frames.robots, "history": paper_frames.history})
    assert list(a["verdict"]) == list(b["verdict"])


# ------------------------------------------------------------------------------- issue 24: run level
def test_fig3_4_rows_are_run_level_and_too_few_runs_are_inconclusive(paper_frames):
    """Honest robots far richer in every run, but only 6 runs of fig3A: the robot-level p (pooled robots)
    is tiny, the run-level signed-rank p can be no smaller than 1/64 > 0.001: inconclusive, not pass."""
    robots = paper_frames.robots
    robots = robots[(robots.experiment != "fig3A") | (robots.run < 6)]
    table = headline_table({"robots": robots, "history": paper_frames.history}).set_index("id")
    assert table.loc["fig3A_mannwhitney", "value"] == pytest.approx(1 / 64)
    assert table.loc["fig3A_mannwhitney", "verdict"] == INCONCLUSIVE
    assert "robot-level" in table.loc["fig3A_mannwhitney", "store"]
    assert table.loc["fig3B_mannwhitney", "verdict"] == PASS  # 12 runs: 1 / 4096 < 0.001


def test_fig7b_needs_a_significant_gain_not_just_a_higher_median(paper_frames):
    """No staking one item lower per run than staking's distribution: staking's median stays higher
    at every angle above Theta (the old rule's pass), but the gain is no test's evidence: fail."""
    robots = paper_frames.robots.copy()
    rng = np.random.default_rng(5)
    sel = (robots.experiment == "fig7") & (robots.byzantines == 3) & (robots.rotation_angle > 30)
    robots.loc[sel, "items_collected"] = rng.integers(12, 14, sel.sum())
    lower = sel & (robots.market == "no_staking") & (robots.robot == 0)
    robots.loc[lower, "items_collected"] -= 1
    runs = robots[sel].groupby(["rotation_angle", "market", "run"])["items_collected"].sum()
    med = runs.groupby(["rotation_angle", "market"]).median().unstack()
    if not (med["staking"] > med["no_staking"]).all():
        pytest.skip("the draw did not give higher staking medians everywhere")
    table = headline_table({"robots": robots}).set_index("id")
    assert table.loc["fig7B_staking_helps", "value"] < 1.0
    assert table.loc["fig7B_staking_helps", "verdict"] in (FAIL, INCONCLUSIVE)
    assert "Holm" in table.loc["fig7B_staking_helps", "store"]


def test_fig7b_with_two_runs_per_condition_is_inconclusive(paper_frames):
    robots = paper_frames.robots
    robots = robots[(robots.experiment != "fig7") | (robots.run < 2)]
    assert verdicts(headline_table({"robots": robots}))["fig7B_staking_helps"] == INCONCLUSIVE
