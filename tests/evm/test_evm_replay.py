"""Replaying a ledger event log through the contract (infomarket.evm.replay)."""
from __future__ import annotations

import json
from fractions import Fraction
from pathlib import Path

import pytest

from infomarket.errors import ArgumentError
from infomarket.evm.errors import ChainError
from infomarket.evm.market import MarketParams
from infomarket.evm.evm_replay import BalanceRow, replay_market, replay_on_chain

from .exact_ledger import SELLER_POSITION, ExactLedger, vector_for

CASES = json.loads((Path(__file__).parents[1] / "fixtures" / "payment_vectors.json").read_text())["cases"]


def purchase(buyer, seller, site=0, direction=10.0, kind="purchase", step=1, age=2):
    x, y = vector_for(direction)
    return {"kind": kind, "buyer": buyer, "seller": seller, "site": site, "direction_deg": direction,
            "x": x, "y": y, "seller_x": SELLER_POSITION[0], "seller_y": SELLER_POSITION[1], "age": age, "step": step}


def deposit(robot, step=2):
    return {"kind": "deposit", "buyer": robot, "seller": -1, "site": -1, "direction_deg": 0.0,
            "x": 0.0, "y": 0.0, "age": 0, "step": step}


def test_replay_of_a_two_trip_log_matches_the_exact_ledger_within_the_rounding_bound():
    events = [purchase(0, 1, 0, 10.0), purchase(0, 2, 0, 25.0), purchase(0, 3, 0, 200.0), purchase(1, 0, 1, 5.0),
              deposit(0), purchase(0, 3, 1, 90.0, step=2), purchase(2, 1, 0, 359.0, step=2), deposit(2, 3),
              deposit(1, 3), deposit(3, 3)]
    exact = ExactLedger(4, "outlier", Fraction(1), Fraction(1, 2), Fraction(1, 25), Fraction(30), Fraction(1))
    for ev in events:
        if ev["kind"] == "deposit":
            exact.deposit(ev["buyer"])
        else:
            assert exact.purchase(ev["buyer"], ev["seller"], ev["site"], Fraction(ev["direction_deg"]))
    report = replay_on_chain(events, robots=4, params=MarketParams.from_floats("outlier", stake=0.04),
                             initial_wealth=1.0)
    assert report.conserved() and not report.disagreements
    # one block per step, steps 0 to 3
    assert report.items == 4 and len(report.reveal_gas) == 6 and report.blocks_used == 3
    assert report.rounding_bound == exact.bound
    rows = report.compare([float(b) for b in exact.balance])
    assert all(r.ok for r in rows), rows
    assert report.pots == [40_000_000, 0, 0, 0]  # robot 0 bought again after its deposit: its pot holds the stake


def test_fixture_cases_replayed_as_event_logs_confirm_every_refusal():
    staking = [c for c in CASES if c["stake"] > 0 and not all(t["accepted"] for t in c["transactions"])][:2]
    for case in staking:
        events = [purchase(0, t["seller"], 0 if t["site"] == "food" else 1, t["direction_deg"],
                           "purchase" if t["accepted"] else "refused", age=k)
                  for k, t in enumerate(case["transactions"])]
        report = replay_on_chain(events + [deposit(0)], robots=case["robots"],
                                 params=MarketParams.from_floats("outlier", stake=0.04),
                                 initial_wealth=case["initial_wealth"])
        refused = sum(not t["accepted"] for t in case["transactions"])
        assert report.refusals_confirmed == refused
        expected = [case["balances_after_deposit"][str(i)] for i in range(case["robots"])]
        assert all(r.ok for r in report.compare(expected))


def test_disagreements_are_reported_not_hidden():
    params = MarketParams.from_floats("outlier", stake=0.04)
    # Robot 1 starts with 0.05: the simulator claims a second sale went through, which cannot be;
    # and a sale robot 2 (plenty of money) could make is claimed refused.
    events = [purchase(0, 1), purchase(0, 1, direction=11.0, age=3), purchase(0, 2, kind="refused")]
    report = replay_on_chain(events, robots=3, params=params, initial_wealth=0.05)
    assert len(report.disagreements) == 2
    assert "InfoMarketInsufficientStake" in report.disagreements[0]
    assert "accepted on chain" in report.disagreements[1]
    assert report.conserved()


def test_replay_with_stake_expiry_settles_at_the_start_of_the_step_like_the_simulation():
    """T = 5: robot 0's purchase at step 1 expires its round trip at the start of step 6 (before robot 0's
    deposit in step 6): both records, 10 and 12 degrees (weight 2 each), share the 0.5 robot 0 pays from
    its balance and their stakes; the deposit then finds an empty round trip and keeps the reward."""
    params = MarketParams.from_floats("outlier", stake=0.04, stake_expiry=5)
    events = [purchase(0, 1, step=1), purchase(0, 2, direction=12.0, step=2), deposit(0, step=6)]
    report = replay_on_chain(events, robots=3, params=params, initial_wealth=1.0)
    assert report.expired == 2 and not report.disagreements and report.conserved()
    assert report.balances == [1_500_000_000, 1_250_000_000, 1_250_000_000]
    # one step earlier, both are paid: weight 2 each (10 and 12 degrees), 0.5 + 0.08 shared
    events[-1] = deposit(0, step=5)
    report = replay_on_chain(events, robots=3, params=params, initial_wealth=1.0)
    assert report.expired == 0
    assert report.balances == [1_500_000_000, 1_250_000_000, 1_250_000_000]


def test_balance_rows_allow_the_rounding_bound_and_nothing_more():
    assert BalanceRow(0, 1_000_000_003, 1.0, 3).ok
    assert not BalanceRow(0, 1_000_000_004, 1.0, 3).ok
    assert not BalanceRow(0, 1_000_000_001, 1.0, 0).ok
    assert BalanceRow(0, 999_999_998, 1.0, 2).diff_units == pytest.approx(-2.0)


def test_unknown_event_kinds_stop_the_replay():
    with pytest.raises(ChainError, match="unknown kind"):
        replay_on_chain([{"kind": "gift", "buyer": 0}], robots=1,
                        params=MarketParams.from_floats("delayed"), initial_wealth=1.0)


def test_a_market_made_for_another_swarm_size_is_refused():
    params = MarketParams.from_floats("delayed")
    start = replay_market(robots=2, params=params, initial_wealth=1.0)
    with pytest.raises(ArgumentError, match="registers 2 robots, not 3"):
        replay_on_chain([deposit(0)], robots=3, params=params, initial_wealth=1.0, start=start)
    assert replay_on_chain([deposit(0)], robots=2, params=params, initial_wealth=1.0, start=start).conserved()
