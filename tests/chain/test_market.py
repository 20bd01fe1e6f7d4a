"""The contract's payment rules through infomarket.chain.market: reveals, buys, and the 32 conformance
cases computed by the original simulator (tests/fixtures/payment_vectors.json)."""
from __future__ import annotations

import json
from fractions import Fraction
from pathlib import Path

import pytest
from web3.logs import DISCARD

from infomarket.chain.errors import ContractRevert
from infomarket.chain.protocol import FOOD, NEST, PathInfo
from infomarket.chain.replay import FLOAT_SLACK_UNITS
from infomarket.chain.units import TOKEN_UNIT, to_units

from .exact_ledger import ExactLedger

CASES = json.loads((Path(__file__).parents[1] / "fixtures" / "payment_vectors.json").read_text())["cases"]
SCHEMES = {"delayed": ("delayed", 0.0), "outlier": ("outlier", 0.0), "outlier+stake": ("outlier", 0.04)}


def logs(market, event: str, result):
    """The ``event`` logs of a transaction (its other events are skipped, not warned about)."""
    return getattr(market.contract.events, event)().process_receipt(result.receipt, errors=DISCARD)


def sell(market, seller, buyer, site=FOOD, direction=10.0, age=5):
    info = PathInfo.from_floats(3.0, 4.0, direction)
    lc = market.light_contract(seller, buyer, site, age, info, (1.0, 1.0))
    return market.reveal(seller, lc, info), lc, info


def test_reveal_records_the_sale_and_moves_the_stake_into_the_buyers_pot(make_market, robots):
    market = make_market("outlier", stake=0.04)
    buyer, seller = robots[0], robots[1]
    result, lc, info = sell(market, seller, buyer, NEST, 123.456789, age=17)

    (revealed,) = logs(market, "InformationRevealed", result)
    key = market.view("revealKey", NEST, 17, lc.offer.max_block, buyer.address, seller.address)
    assert dict(revealed.args) == {"buyer": buyer.address, "seller": seller.address, "key": key, "index": 0,
                                   "site": NEST, "age": 17, "x": info.x, "y": info.y, "direction": 123_456_789}
    (locked,) = logs(market, "StakeLocked", result)
    assert dict(locked.args) == {"seller": seller.address, "buyer": buyer.address, "amount": 40_000_000}
    assert market.contributors(buyer.address) == [(seller.address, NEST, 123_456_789)]
    assert market.locked_stake(buyer.address) == 40_000_000
    assert market.balance_of(seller.address) == 960_000_000
    assert market.view("isRevealed", key)


def test_buy_item_without_records_pays_only_the_reward(make_market, robots):
    market = make_market("outlier", stake=0.04)
    result = market.buy_item(robots[3].address)
    (bought,) = logs(market, "ItemBought", result)
    assert dict(bought.args) == {"robot": robots[3].address, "reward": TOKEN_UNIT, "pot": 0, "shared": 0,
                                 "transactions": 0}
    assert market.balance_of(robots[3].address) == 2 * TOKEN_UNIT
    assert market.total_supply() == len(robots) * TOKEN_UNIT + TOKEN_UNIT


def test_a_deposit_clears_the_round_trip_and_the_next_one_starts_from_nothing(make_market, robots):
    """Records are cleared by resetting a count, so stale slots must never leak into the next trip."""
    market = make_market("delayed", stake=0.0)
    buyer = robots[0]
    sell(market, robots[1], buyer)
    sell(market, robots[2], buyer, age=6)
    market.buy_item(buyer.address)
    assert market.contributors(buyer.address) == []
    sell(market, robots[3], buyer, NEST, 250.0)
    assert market.contributors(buyer.address) == [(robots[3].address, NEST, 250_000_000)]
    result = market.buy_item(buyer.address)
    shares = logs(market, "RewardShared", result)
    assert [(e.args.seller, e.args.amount) for e in shares] == [(robots[3].address, 500_000_000)]
    assert market.balance_of(robots[3].address) == 1_500_000_000
    assert market.balance_of(robots[1].address) == 1_250_000_000


def test_shares_follow_the_outlier_weights_and_the_stakes_are_shared(make_market, robots):
    market = make_market("outlier", stake=0.04)
    buyer = robots[0]
    for seller, direction in ((robots[1], 350.0), (robots[2], 15.0), (robots[3], 120.0)):
        sell(market, seller, buyer, FOOD, direction)
    sell(market, robots[4], buyer, NEST, 10.0)  # same direction, other site: not similar to the others
    result = market.buy_item(buyer.address)
    shares = logs(market, "RewardShared", result)
    # 350 and 15 are 25 degrees apart across north: weight 2 each; 120 and the nest record weigh 1.
    assert [e.args.weight for e in shares] == [2, 2, 1, 1]
    amount = 500_000_000 + 4 * 40_000_000
    assert [e.args.amount for e in shares] == [amount * w // 6 for w in (2, 2, 1, 1)]
    assert market.balance_of(buyer.address) == TOKEN_UNIT + TOKEN_UNIT + 160_000_000 - sum(amount * w // 6 for w in (2, 2, 1, 1))


def test_similarity_is_strictly_within_theta_and_wraps_around_north(make_market, robots):
    """MODEL.md: directions differing by *less than* Theta, circularly, are similar."""
    market = make_market("outlier", stake=0.0)
    buyer = robots[0]
    # 0 and 30 are exactly Theta apart (not similar); 330.000001 is 29.999999 from 0 (similar);
    # 330.000001 and 30 are 59.999999 apart.
    for seller, direction in ((robots[1], 0.0), (robots[2], 30.0), (robots[3], 330.000001)):
        sell(market, seller, buyer, FOOD, direction)
    shares = logs(market, "RewardShared", market.buy_item(buyer.address))
    assert [e.args.weight for e in shares] == [2, 1, 2]


def test_constructor_refuses_stakes_under_delayed_payment(make_market):
    with pytest.raises(ContractRevert) as refused:
        make_market("delayed", stake=0.04)
    assert refused.value.name == "InfoMarketInvalidParameter"
    assert refused.value.args_by_name == {"parameter": b"stake".ljust(32, b"\0"), "value": 40_000_000}


@pytest.fixture(scope="module")
def vector_markets(w3, robots, make_market):
    """One market per (scheme, robots, initial wealth, theta) of the cases, deployed once; each case
    starts from this snapshot of the chain."""
    markets = {}
    for case in CASES:
        key = (case["scheme"], case["robots"], case["initial_wealth"], case["theta_deg"])
        if key not in markets:
            scheme, stake = SCHEMES[case["scheme"]]
            wealth = [case["initial_wealth"]] * case["robots"] + [0.0] * (len(robots) - case["robots"])
            markets[key] = make_market(scheme, stake=stake, wealth=wealth, theta_deg=case["theta_deg"])
    tester = w3.provider.ethereum_tester
    return markets, tester, tester.take_snapshot()


@pytest.mark.parametrize("case", CASES, ids=[f"{i}-{c['scheme']}" for i, c in enumerate(CASES)])
def test_contract_reproduces_the_original_simulators_payments(case, vector_markets, robots):
    scheme, stake = SCHEMES[case["scheme"]]
    assert stake == case["stake"]
    n = case["robots"]
    markets, tester, snapshot = vector_markets
    tester.revert_to_snapshot(snapshot)
    market = markets[(case["scheme"], n, case["initial_wealth"], case["theta_deg"])]
    exact = ExactLedger(n, scheme, Fraction(case["reward"]), Fraction(str(case["information_share"])),
                        Fraction(str(stake)), Fraction(case["theta_deg"]), Fraction(str(case["initial_wealth"])))
    buyer = robots[case["buyer"]]
    for tx in case["transactions"]:
        seller = robots[tx["seller"]]
        site = FOOD if tx["site"] == "food" else NEST
        assert exact.purchase(case["buyer"], tx["seller"], site, Fraction(str(tx["direction_deg"]))) == tx["accepted"]
        if tx["accepted"]:
            sell(market, seller, buyer, site, tx["direction_deg"])
        else:
            balance = market.balance_of(seller.address)
            with pytest.raises(ContractRevert) as refused:
                sell(market, seller, buyer, site, tx["direction_deg"])
            assert refused.value.name == "InfoMarketInsufficientStake"
            assert refused.value.args_by_name == {"robot": seller.address, "balance": balance,
                                                  "needed": to_units(stake)}

    # Stakes are whole units: before the deposit the balances are exact.
    chain = [market.balance_of(robots[i].address) for i in range(n)]
    assert chain == [to_units(case["balances_after_transactions"][str(i)]) for i in range(n)]

    market.buy_item(buyer.address)
    exact.deposit(case["buyer"])
    chain = [market.balance_of(robots[i].address) for i in range(n)]
    for i in range(n):
        expected = case["balances_after_deposit"][str(i)]
        # The exact model is the original simulator's rule (the fixture has 12 decimals).
        assert float(exact.balance[i]) == pytest.approx(expected, abs=1e-9)
        # Each share is floored to a unit; the depositing robot keeps the dust. So a seller is below
        # the exact value and the buyer above it, each by less than one unit per share it took part in.
        gap = chain[i] - exact.balance[i] * TOKEN_UNIT
        if i == case["buyer"]:
            assert 0 <= gap < max(exact.bound[i], 1)
        else:
            assert -max(exact.bound[i], 1) < gap <= 0
        assert abs(chain[i] - expected * TOKEN_UNIT) <= exact.bound[i] + FLOAT_SLACK_UNITS
    pots = sum(market.locked_stake(robots[i].address) for i in range(n))
    assert sum(chain) + pots == market.total_supply() == to_units(case["initial_wealth"]) * n + TOKEN_UNIT
