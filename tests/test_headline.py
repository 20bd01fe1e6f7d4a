"""Reduced-size statistical checks of the paper's headline results (MODEL.md §8), 12 runs per panel.

The full-size check (16+ runs per panel on the original JSON files) is in the closing notes and
``infomarket reproduce``; these use fewer runs and fixed seeds, with the same thresholds as the issue.
"""
import pandas as pd
import pytest
from scipy import stats

import infomarket as im
from infomarket.runner import run_batch

RUNS = 12


@pytest.fixture(scope="module")
def panels():
    out = {}
    for name in ("fig2A", "fig2B", "fig2C", "fig2D", "fig3A", "fig4A"):
        cfg = im.load_experiment(name)
        out[name] = run_batch(cfg, RUNS, 1000 + cfg.seed, workers=2).robots
    return out


def med(df: pd.DataFrame, honest: bool, col: str = "items_collected") -> float:
    return float(df[df.honest == honest][col].median())


def test_fig2a_naive_swarm_collects_about_20(panels):
    assert 18 <= med(panels["fig2A"], True) <= 22


def test_fig2b_one_saboteur_halves_naive_robots(panels):
    a, b = med(panels["fig2A"], True), med(panels["fig2B"], True)
    assert b <= 0.65 * a
    assert med(panels["fig2B"], False) >= b


def test_fig2c_scepticism_costs_efficiency(panels):
    assert med(panels["fig2C"], True) < med(panels["fig2A"], True)


def test_fig2d_sceptics_resist_a_scaboteur(panels):
    assert med(panels["fig2D"], True) >= 1.5 * med(panels["fig2B"], True)


def test_fig3a_outlier_penalisation_makes_the_scaboteur_poorer(panels):
    d = panels["fig3A"]
    assert med(d, False, "wealth_share") < 0.036
    assert med(d, True, "wealth_share") > 0.04
    p = stats.mannwhitneyu(d[d.honest].wealth_share, d[~d.honest].wealth_share, alternative="greater").pvalue
    assert p < 0.001


def test_fig4a_staking_widens_the_gap(panels):
    gap3 = med(panels["fig3A"], True, "wealth_share") - med(panels["fig3A"], False, "wealth_share")
    gap4 = med(panels["fig4A"], True, "wealth_share") - med(panels["fig4A"], False, "wealth_share")
    assert gap4 > gap3
