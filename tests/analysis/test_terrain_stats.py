"""Terrain answers with run-level statistics (issue 24): hand-made tables whose answers follow from the
numbers chosen here."""
from __future__ import annotations

import numpy as np
import pandas as pd

from infomarket.analysis import terrain

TWO_FOOD = {"p_below": 0.001, "min_runs_separated": 0.9}


def _two_food(gaps, robots_per_run: int = 200):
    """food_sites 1 and 2, each run: honest robots at share 1 + gap/2, Byzantine at 1 - gap/2 (plus
    a tiny robot-to-robot spread so nothing ties)."""
    rows = []
    for sites in (1, 2):
        for run, gap in enumerate(gaps):
            for r in range(robots_per_run):
                honest = r < robots_per_run * 4 // 5
                share = (1 + gap / 2 if honest else 1 - gap / 2) + 1e-6 * r
                rows.append({"food_sites": sites, "run": run, "honest": honest, "wealth_share": share})
    return pd.DataFrame(rows)


def test_two_food_is_tested_at_the_run_level_not_on_pooled_robots():
    """4 runs, honest richer in every one: robot-level p is astronomically small (800 vs 160 pooled
    robots), but 4 runs can give at best p = 1/16 > 0.001: inconclusive, not yes."""
    a = terrain.outlier_two_food(_two_food([0.01, 0.02, 0.03, 0.04]), TWO_FOOD, None)
    two = a["two_sites"]
    assert two["p_robot_level"] < 1e-50
    assert two["p_run_level"] == 1 / 16 and two["min_p_run_level"] == 1 / 16
    assert a["answer"] == "inconclusive"


def test_two_food_with_enough_runs_decides_at_the_run_level():
    gaps = np.linspace(0.01, 0.05, 16)
    assert terrain.outlier_two_food(_two_food(gaps, 20), TWO_FOOD, None)["answer"] == "yes"  # p = 2^-16
    # half the runs the other way: pooled robots may still look separated, the runs do not
    mixed = np.r_[gaps[:8], -gaps[:8]]
    assert terrain.outlier_two_food(_two_food(mixed, 20), TWO_FOOD, None)["answer"] == "no"


def _crowd(on100, off100):
    rows = []
    for n, on, off in ((100, on100, off100), (25, on100, off100)):
        for coll, vals in ((True, on), (False, off)):
            rows += [{"robots": n, "collisions": coll, "run": r, "items_collected": v} for r, v in enumerate(vals)]
    return pd.DataFrame(rows)


def test_crowd_reads_the_ratio_from_its_interval():
    off = list(np.linspace(90, 110, 32))
    assert terrain.crowd_collisions(_crowd([0.8 * v for v in off], off), {"min_ratio": 0.5})["answer"] == "yes"
    assert terrain.crowd_collisions(_crowd([0.3 * v for v in off], off), {"min_ratio": 0.5})["answer"] == "no"
    # 4 wildly spread runs with a point ratio below one half: the interval straddles it
    wide = terrain.crowd_collisions(_crowd([10, 20, 45, 90], [100, 100, 100, 100]), {"min_ratio": 0.5})
    assert wide[100]["ratio"] == 0.325 and wide["answer"] == "inconclusive"


def _answers_for_figure() -> dict:
    rng = np.random.default_rng(5)
    runs = {"plane/on": rng.normal(450, 20, 64), "plane/off": rng.normal(30, 8, 64),
            "corridor/on": rng.normal(18, 4, 64), "corridor/off": rng.normal(5, 2, 64).clip(0)}
    return {"chain_blocked": {"per_run": runs},
            "waypoints_restore": {"answer": "no", "per_run": {"waypoint/plane": rng.normal(440, 20, 64),
                                                               "waypoint/corridor": rng.normal(22, 5, 64)}},
            "outlier_two_food": {"gaps_pct": {"one": rng.normal(4.5, 1, 64), "two": rng.normal(4.9, 0.2, 64)}},
            "crowd_collisions": {"25": {"per_run_off": rng.normal(19, 1, 32), "per_run_on": rng.normal(1, 0.3, 32)},
                                 "100": {"per_run_off": rng.normal(22, 0.2, 32),
                                         "per_run_on": rng.normal(0.1, 0.02, 32)}}}


def test_the_terrain_figure_is_readable_and_counts_its_runs():
    """docs/images/terrain.png was out of date: an old title, a symlog axis down to -10, overlapping
    tick labels, a cut axis label and no run counts."""
    from .layout import problems

    fig = terrain.terrain_figure(_answers_for_figure())
    assert problems(fig) == []
    corridor, two_food, crowd = fig.axes
    assert corridor.get_ylim()[0] == 0 and min(corridor.get_yticks()) >= 0
    assert "waypoint" in corridor.get_title(loc="left")
    for ax, n in ((corridor, 64), (two_food, 64), (crowd, 32)):
        labels = [t.get_text() for t in ax.get_xticklabels()]
        assert labels and all(lab.endswith(f"n = {n}") for lab in labels)
    assert [h.get_label() for h in fig.legends[0].legend_handles] == ["no gap (0 points)"]
