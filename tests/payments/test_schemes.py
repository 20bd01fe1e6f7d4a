"""Payment schemes: the original simulator's 32 conformance cases, and eqs. (7)-(8) by hand."""
import json
from pathlib import Path

import pytest

from infomarket.engine.world import SITE_NAMES
from infomarket.ledger import LedgerEvent, replay_events

CASES = json.loads((Path(__file__).parents[1] / "fixtures" / "payment_vectors.json").read_text())["cases"]
SCHEMES = {"delayed": ("delayed", False), "outlier": ("outlier", False), "outlier+stake": ("outlier", True)}
SITES = {name: code for code, name in enumerate(SITE_NAMES)}


def _events(case):
    evs = [LedgerEvent("purchase", case["buyer"], t["seller"], SITES[t["site"]], t["direction_deg"])
           for t in case["transactions"]]
    return evs


@pytest.mark.parametrize("k", range(len(CASES)), ids=[f"case{k}-{c['scheme']}" for k, c in enumerate(CASES)])
def test_conformance_vector(k):
    case = CASES[k]
    scheme, staking = SCHEMES[case["scheme"]]
    common = dict(scheme=scheme, initial_wealth=case["initial_wealth"], reward=case["reward"],
                  information_share=case["information_share"], stake=case["stake"] if staking else 0.0,
                  params={"theta": float(case["theta_deg"])} if scheme == "outlier" else {})
    before = replay_events(_events(case), case["robots"], **common)
    assert before.accepted == [t["accepted"] for t in case["transactions"]]
    for robot, bal in case["balances_after_transactions"].items():
        assert before.balances[int(robot)] == pytest.approx(bal, abs=1e-9)
    after = replay_events(_events(case) + [LedgerEvent("deposit", case["buyer"])], case["robots"], **common)
    for robot, bal in case["balances_after_deposit"].items():
        assert after.balances[int(robot)] == pytest.approx(bal, abs=1e-9)
    assert after.pots.sum() == 0.0


def test_outlier_weights_by_hand():
    # food: 10, 20 agree, 200 is an outlier; nest: 5 and 350 agree across 0 degrees (15 apart)
    events = [LedgerEvent("purchase", 0, 1, 0, 10.0), LedgerEvent("purchase", 0, 2, 0, 20.0),
              LedgerEvent("purchase", 0, 3, 0, 200.0), LedgerEvent("purchase", 0, 1, 1, 5.0),
              LedgerEvent("purchase", 0, 2, 1, 350.0), LedgerEvent("deposit", 0)]
    res = replay_events(events, 4, scheme="outlier", params={"theta": 30.0})
    # weights 2, 2, 1, 2, 2 -> sellers 1: 4, 2: 4, 3: 1 of 9; they share 0.5
    assert res.balances == pytest.approx([1.5, 1 + 0.5 * 4 / 9, 1 + 0.5 * 4 / 9, 1 + 0.5 / 9])


def test_outlier_with_stake_pays_back_the_pot_by_weight():
    events = [LedgerEvent("purchase", 0, 1, 0, 10.0), LedgerEvent("purchase", 0, 2, 0, 15.0),
              LedgerEvent("purchase", 0, 3, 0, 100.0)]
    mid = replay_events(events, 4, scheme="outlier", stake=0.04)
    assert mid.balances == pytest.approx([1.0, 0.96, 0.96, 0.96]) and mid.pots[0] == pytest.approx(0.12)
    end = replay_events(events + [LedgerEvent("deposit", 0)], 4, scheme="outlier", stake=0.04)
    share = 0.5 + 0.12
    assert end.balances == pytest.approx([1.5, 0.96 + share * 2 / 5, 0.96 + share * 2 / 5, 0.96 + share / 5])


def test_outlier_seller_loses_its_stake_when_the_majority_agrees():
    # ten sellers agree (directions 10..19), seller 11 sells an outlier (200 degrees)
    events = [LedgerEvent("purchase", 0, s, 0, 9.0 + s) for s in range(1, 11)]
    events += [LedgerEvent("purchase", 0, 11, 0, 200.0), LedgerEvent("deposit", 0)]
    res = replay_events(events, 12, scheme="outlier", stake=0.04)
    total = 0.5 + 11 * 0.04  # weights: 10 each for the agreeing ones, 1 for the outlier (sum 101)
    assert res.balances[11] == pytest.approx(0.96 + total / 101)
    assert res.balances[11] < 1.0 < res.balances[1]


def test_stake_refused_on_insufficient_balance():
    events = [LedgerEvent("purchase", 0, 1, 0, 0.0)] * 3
    res = replay_events(events, 2, scheme="outlier", initial_wealth=0.1, stake=0.04)
    assert res.accepted == [True, True, False]  # 0.1 -> 0.06 -> 0.02 < 0.04: refused, nothing recorded
    assert res.balances[1] == pytest.approx(0.02) and res.pots[0] == pytest.approx(0.08)


def test_delayed_pays_per_transaction():
    events = [LedgerEvent("purchase", 0, 1, 0, 0.0), LedgerEvent("purchase", 0, 1, 1, 0.0),
              LedgerEvent("purchase", 0, 2, 0, 90.0), LedgerEvent("deposit", 0)]
    res = replay_events(events, 3)
    assert res.balances == pytest.approx([1.5, 1 + 1 / 3, 1 + 1 / 6])


@pytest.mark.parametrize("directions", [(10.0, 40.0, 41.0), (350.0, 20.0, 21.0)], ids=["plain", "across-0"])
def test_directions_exactly_theta_apart_are_not_similar(directions):
    # eq. 8 counts transactions strictly within theta: with theta = 30, 10 and 40 (or 350 and 20, across 0)
    # are exactly 30 apart and do not count each other; 40 and 41 do.  Weights 1, 2, 2 (total 5), so the
    # 0.5 paid out (information_share x reward) splits 0.1, 0.2, 0.2.  With <= it would be 2, 3, 2.
    a, b, c = directions
    events = [LedgerEvent("purchase", 0, 1, 0, a), LedgerEvent("purchase", 0, 2, 0, b),
              LedgerEvent("purchase", 0, 3, 0, c), LedgerEvent("deposit", 0)]
    out = replay_events(events, 4, scheme="outlier", params={"theta": 30.0})
    assert list(out.balances) == pytest.approx([1.5, 1.1, 1.2, 1.2], abs=1e-12)
    # and one hair inside theta they are similar: weights 2, 3, 2 (total 7)
    inside = [LedgerEvent("purchase", 0, 1, 0, a), LedgerEvent("purchase", 0, 2, 0, b - 1e-9),
              LedgerEvent("purchase", 0, 3, 0, c), LedgerEvent("deposit", 0)]
    out = replay_events(inside, 4, scheme="outlier", params={"theta": 30.0})
    assert list(out.balances) == pytest.approx([1.5, 1 + 0.5 * 2 / 7, 1 + 0.5 * 3 / 7, 1 + 0.5 * 2 / 7], abs=1e-12)
