"""On a cell whose worst attack is known by construction (tests/search/planted.py: offers within Θ = 30° of
the truth are used, further ones penalised), the global search, every start point of it at a rotation
above 120° and the only hand-written attack at 150°, finds a rotation just below 30° and does more damage
than the random search at equal budget.  At this small budget the search does not find the weakness from
every seed: the test checks the one it declares (``SETTINGS``), and fails when the search's points are
replaced by random ones or its spread start points are turned off.  How often it finds the weakness over
other seeds, at this budget and at the study's, is measured by ``planted_rates`` (docs/attack-search.md)."""
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import infomarket as im
from infomarket.search import driver, space, study
from infomarket.search.restarts import design, spread_points, stream
from infomarket.store import Store

pytestmark = pytest.mark.slow  # a search of some hundred short runs, twice the budget of one searcher

HERE = Path(__file__).parent
SCEPTIC = 2.0 * math.degrees(math.asin(0.25 / 2.0))  # the angle a sceptic of threshold 0.25 accepts (attacks.py)


def planted_study(**settings) -> study.Study:
    declared = {**study.load_declarations(), "pending_defences": {}}
    st = study.load(im.load_experiment(HERE / "planted.toml"), declared, **settings)
    # no baseline near the weakness: one attack far away (150°), and the truthful reference
    return dataclasses.replace(st, baselines={"far": {"rot_base": 150.0}, "truthful": {"lie_from_rep": 1.0}},
                               reference="truthful")


def effective_rotation(p: dict) -> float:
    """The lie's rotation before the state-dependent terms: rot_base capped by cap_theta x Θ (30°, what the
    attacker knows of the contract) and by cap_sceptic x the sceptic's angle (behaviours.attacks)."""
    return min(p["rot_base"], p["cap_theta"] * 30.0, p["cap_sceptic"] * SCEPTIC)


SETTINGS = {"budget": 96, "popsize": 8, "restarts": 2, "runs": 2, "finalists": 3, "race": [2, 4],
            "confirmation_runs": 8, "sigma0": 0.3, "seed": 1}


def far_starts(s: study.Settings, cell: study.Cell) -> np.ndarray:
    """The search's own spread start points, every one moved to a rotation above 120°."""
    pts = design(spread_points(s), space.dimension(), stream(stream(s.seed, cell.experiment), "design"))
    k = space.NAMES.index("rot_base")
    pts[:, k] = 0.7 + 0.3 * pts[:, k]  # 126° to 180°
    return pts


def run_planted(tmp_path, **overrides) -> driver.CellSearch:
    st = planted_study(**{**SETTINGS, **overrides})
    cell = study.cells(st)[0]
    store = Store(tmp_path / "store", cache=True)  # as the search command makes it: each part read once
    starts = far_starts(st.settings, cell)
    assert min(space.to_params(x)["rot_base"] for x in starts) > 120.0
    return driver.search_cell(st, cell, store, run=driver.store_runner(store), steps=3000, transitory=1000,
                              starts=starts)


@pytest.fixture(scope="module")
def planted(tmp_path_factory):
    return run_planted(tmp_path_factory.mktemp("planted"))


def _median(r: driver.CellSearch, role: str) -> float:
    c = r.confirmation
    return float(np.median(c[c.attack == r.chosen[role]]["items"]))


def test_the_search_finds_the_planted_weakness_from_far_away(planted):
    r = planted
    assert r.chosen["baseline"] == "far"
    found = r.params[r.chosen["search"]]
    assert 15.0 <= effective_rotation(found) < 33.0, found
    # the weakness costs the honest robots about 1.3 items each (a 30° lie against the truth: the landscape
    # in planted.py); the search's attack costs them at least 0.8 on the confirmation seeds, the far one less
    assert _median(r, "search") <= _median(r, "reference") - 0.8
    assert _median(r, "baseline") > _median(r, "search") + 0.5


def test_the_search_beats_the_random_search_at_equal_budget(planted):
    r = planted
    counts = r.candidates.searcher.value_counts()
    # by hand: 24 start points (a quarter of 96), then 72 in two shares of 36: 4 generations of 8, then
    # 40 left for populations of 13 (16 capped at 40 // 3): 3 generations
    assert (counts["start"], counts["cma"], counts["random"]) == (24, 32 + 39, 24 + 32 + 39)
    assert _median(r, "search") < _median(r, "random") - 0.3
    assert r.chosen["worst"] == r.chosen["search"]
