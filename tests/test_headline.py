"""Reduced-size statistical checks of the paper's headline results (docs/model.md §8), 12 runs per panel.

The full-size check is ``infomarket reproduce paper`` followed by ``infomarket figures``; these use fewer
runs and fixed seeds.  The bounds are not restated here: each check reads its rule from
``analysis/tolerances.toml`` (the file the report judges with), so the two cannot drift apart.
"""
import pandas as pd
import pytest
from scipy import stats

import infomarket as im
from infomarket.analysis.headline import load_rules
from infomarket.runner import run_batch

RUNS = 12
RULES = load_rules()


@pytest.fixture(scope="module")
def panels():
    out = {}
    for name in ("fig2A", "fig2B", "fig2C", "fig2D", "fig3A", "fig4A"):
        cfg = im.load_experiment(name)
        out[name] = run_batch(cfg, RUNS, 1000 + cfg.seed, workers=2).robots
    return out


def med(df: pd.DataFrame, honest: bool, col: str = "items_collected") -> float:
    return float(df[df.honest == honest][col].median())


def judged(rid: str, value: float) -> None:
    rule = RULES[rid]
    assert rule.passes(value), f"{rid}: {value:.4g} outside {rule.describe()} ({rule.claim})"


def test_fig2a_naive_swarm_collects_about_20(panels):
    judged("fig2A_median", med(panels["fig2A"], True))


def test_fig2b_one_saboteur_halves_naive_robots(panels):
    a, b = med(panels["fig2A"], True), med(panels["fig2B"], True)
    judged("fig2B_halves", b / a)
    judged("fig2B_saboteur_gains", med(panels["fig2B"], False) - b)


def test_fig2c_scepticism_costs_efficiency(panels):
    judged("fig2C_below_2A", med(panels["fig2C"], True) - med(panels["fig2A"], True))


def test_fig2d_sceptics_resist_a_scaboteur(panels):
    judged("fig2D_vs_2B", med(panels["fig2D"], True) / med(panels["fig2B"], True))
    judged("fig2D_vs_2C", med(panels["fig2D"], True) - med(panels["fig2C"], True))


def test_fig3a_outlier_penalisation_makes_the_scaboteur_poorer(panels):
    d = panels["fig3A"]
    judged("fig3A_scaboteur_share", 100 * med(d, False, "wealth_share"))
    judged("fig3A_honest_share", 100 * med(d, True, "wealth_share"))
    p = stats.mannwhitneyu(d[d.honest].wealth_share, d[~d.honest].wealth_share, alternative="greater").pvalue
    judged("fig3A_mannwhitney", p)


def test_fig4a_staking_widens_the_gap(panels):
    gap3 = med(panels["fig3A"], True, "wealth_share") - med(panels["fig3A"], False, "wealth_share")
    gap4 = med(panels["fig4A"], True, "wealth_share") - med(panels["fig4A"], False, "wealth_share")
    judged("fig4A_gap_larger", 100 * (gap4 - gap3))
