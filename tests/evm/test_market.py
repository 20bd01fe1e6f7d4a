"""The contract's payment rules through infomarket.evm.market: reveals, buys, and the 32 conformance
cases computed by the original simulator (tests/fixtures/payment_vectors.json)."""
from __future__ import annotations

import json
import random
import math
from dataclasses import replace
from fractions import Fraction
from pathlib import Path

import pytest
from infomarket.errors import ConfigError
from infomarket.evm.errors import ContractRevert
from infomarket.evm.market import ChainMarket, MarketParams
from infomarket.evm.protocol import FOOD, NEST, PathInfo
from infomarket.evm.evm_replay import FLOAT_SLACK_UNITS
from infomarket.evm.units import TOKEN_UNIT, to_units

from .exact_ledger import SELLER_POSITION, ExactLedger, vector_for

CASES = json.loads((Path(__file__).parents[1] / "fixtures" / "payment_vectors.json").read_text())["cases"]
SCHEMES = {"delayed": ("delayed", 0.0), "outlier": ("outlier", 0.0), "outlier+stake": ("outlier", 0.04)}


def sell(market, seller, buyer, site=FOOD, direction=10.0, age=5):
    """A sale whose rotated vector points at ``direction`` (degrees) from the seller's position."""
    info = PathInfo.from_floats(*vector_for(direction))
    lc = market.light_contract(seller, buyer, site, age, info, SELLER_POSITION)
    return market.reveal(seller, lc, info), lc, info


def shares_of(results) -> list[dict]:
    return [e for r in results for e in r.of("RewardShared")]


def test_reveal_records_the_sale_and_moves_the_stake_into_the_buyers_pot(make_market, robots):
    market = make_market("outlier", stake=0.04)
    buyer, seller = robots[0], robots[1]
    result, lc, info = sell(market, seller, buyer, NEST, 123.456789, age=17)

    (revealed,) = result.of("InformationRevealed")
    key = market.view("revealKey", NEST, 17, lc.offer.max_block, buyer.address, seller.address, info.digest())
    assert revealed == {"buyer": buyer.address, "seller": seller.address, "key": key, "index": 0, "site": NEST,
                        "age": 17, "x": info.x, "y": info.y, "sellerX": 1_500_000, "sellerY": -500_000,
                        "pathHash": info.digest()}
    (locked,) = result.of("StakeLocked")
    assert locked == {"seller": seller.address, "buyer": buyer.address, "amount": 40_000_000}
    assert market.contributors(buyer.address) == [
        (seller.address, result.block_number, NEST, info.x - 1_500_000, info.y + 500_000, 0, 0)]
    assert market.locked_stake(buyer.address) == 40_000_000
    assert market.balance_of(seller.address) == 960_000_000
    assert market.view("isRevealed", key)


def test_buy_item_without_records_pays_only_the_reward(make_market, robots):
    market = make_market("outlier", stake=0.04)
    result = market.buy_item(robots[3].address)
    assert result.of("ItemBought") == [{"robot": robots[3].address, "reward": TOKEN_UNIT, "pot": 0, "transactions": 0}]
    assert market.balance_of(robots[3].address) == 2 * TOKEN_UNIT
    # every robot was granted one token of free wealth and its bond (locked), then one reward
    assert market.total_supply() == len(robots) * (TOKEN_UNIT + market.bond) + TOKEN_UNIT
    assert market.pending_settlement(robots[3].address) == (False, 0, 0)


def test_a_deposit_clears_the_round_trip_and_the_next_one_starts_from_nothing(make_market, robots):
    """Records are cleared by resetting a count, so stale slots must never leak into the next trip."""
    market = make_market("delayed", stake=0.0)
    buyer = robots[0]
    sell(market, robots[1], buyer)
    sell(market, robots[2], buyer, age=6)
    market.deposit(buyer.address)
    assert market.contributors(buyer.address) == []
    sell(market, robots[3], buyer, NEST, 250.0)
    assert [r[0] for r in market.contributors(buyer.address)] == [robots[3].address]
    shares = shares_of(market.deposit(buyer.address))
    assert [(e["seller"], e["amount"]) for e in shares] == [(robots[3].address, 500_000_000)]
    assert market.balance_of(robots[3].address) == 1_500_000_000
    assert market.balance_of(robots[1].address) == 1_250_000_000


def test_shares_follow_the_outlier_weights_and_the_stakes_are_shared(make_market, robots):
    market = make_market("outlier", stake=0.04)
    buyer = robots[0]
    for seller, direction in ((robots[1], 350.0), (robots[2], 15.0), (robots[3], 120.0)):
        sell(market, seller, buyer, FOOD, direction)
    sell(market, robots[4], buyer, NEST, 10.0)  # same direction, other site: not similar to the others
    shares = shares_of(market.deposit(buyer.address))
    # 350 and 15 are 25 degrees apart across north: weight 2 each; 120 and the nest record weigh 1.
    assert [e["weight"] for e in shares] == [2, 2, 1, 1]
    amount = 500_000_000 + 4 * 40_000_000
    assert [e["amount"] for e in shares] == [amount * w // 6 for w in (2, 2, 1, 1)]
    assert market.balance_of(buyer.address) == (TOKEN_UNIT + TOKEN_UNIT + 160_000_000
                                                - sum(amount * w // 6 for w in (2, 2, 1, 1)))


@pytest.mark.parametrize(("theta", "a", "b", "expected"), [
    (90.0, (1, 0), (0, 1), False),          # exactly 90 degrees apart: not strictly within 90
    (90.0, (1, 0), (1, 1_000_000), True),   # a hair under 90
    (90.0, (5, 0), (7, 0), True),           # parallel, any lengths
    (60.0, (1000, 0), (1000, 1732), True),  # cos = 1000 / 1999.956 > 1/2
    (60.0, (1000, 0), (1000, 1733), False),  # cos = 1000 / 2000.822 < 1/2
    (120.0, (1000, 0), (-1000, 1732), False),  # cos = -0.500011 < -1/2: 120.0013 degrees
    (120.0, (1000, 0), (-1000, 1733), True),  # cos = -0.499795 > -1/2
    (180.0, (3, 4), (-3, -4), False),       # exactly opposite: 180 is not less than 180
    (180.0, (3, 4), (-3, -5), True),
    (0.0, (3, 4), (3, 4), False),           # nothing is within 0 degrees of another record
    (30.0, (0, 0), (1000, 1), True),        # a zero vector counts as direction 0, like atan2(0, 0)
    (30.0, (0, 0), (0, 1000), False),
])
def test_similarity_is_an_exact_integer_test_on_the_vectors(make_market, theta, a, b, expected):
    """Hand-computed cosines on both sides of the window; no trigonometry in the contract."""
    market = make_market("outlier", stake=0.0, theta_deg=theta, wealth=0.0)
    assert market.view("similar", *a, *b) is expected
    assert market.view("similar", *b, *a) is expected


def test_constructor_refuses_stakes_under_delayed_payment(make_market):
    with pytest.raises(ContractRevert) as refused:
        make_market("delayed", stake=0.04)
    assert refused.value.name == "InfoMarketInvalidParameter"
    assert refused.value.args_by_name == {"parameter": b"stake".ljust(32, b"\0"), "value": 40_000_000}


def test_a_long_round_trip_settles_across_transactions_and_pays_what_the_rules_say(make_market, robots):
    """60 records with a batch of 8: buyItem settles 8 records of work, settle() continues where it
    stopped; the result is the exact ledger's, within the rounding bound."""
    market = make_market("outlier", stake=0.04, settle_batch=8, wealth=10.0)
    exact = ExactLedger(len(robots), "outlier", Fraction(1), Fraction(1, 2), Fraction(1, 25), Fraction(30),
                        Fraction(10))
    buyer = 0
    rng = random.Random(1)
    for k in range(60):
        seller, site, direction = 1 + k % 7, k % 2, round(rng.uniform(0.0, 360.0), 3)
        sell(market, robots[seller], robots[buyer], site, direction, age=k)
        assert exact.purchase(buyer, seller, site, Fraction(direction))
    results = market.deposit(robots[buyer].address, batch=8)
    exact.deposit(buyer)
    # 60 records weighed and 60 paid in batches of 8 (the expiry scan finds nothing): 15 transactions.
    assert len(results) == 15
    assert all(r.gas_used < 3_000_000 for r in results)
    (done,) = results[-1].of("SettlementCompleted")
    assert sum(e["amount"] for e in shares_of(results)) == done["shared"]
    for i, account in enumerate(robots):
        gap = market.balance_of(account.address) - exact.balance[i] * TOKEN_UNIT
        assert abs(gap) < max(exact.bound[i], 1)
    assert market.total_supply() == sum(market.balance_of(a.address) + market.bond_of(a.address) for a in robots)


def test_a_pending_settlement_blocks_the_next_deposit_until_settled(make_market, robots):
    market = make_market("delayed", stake=0.0, settle_batch=1)
    buyer = robots[0]
    sell(market, robots[1], buyer)
    sell(market, robots[2], buyer, age=6)
    market.buy_item(buyer.address)
    assert market.pending_settlement(buyer.address)[0]
    with pytest.raises(ContractRevert) as refused:
        market.buy_item(buyer.address)
    assert refused.value.name == "InfoMarketSettlementPending"
    sell(market, robots[3], buyer, age=7)  # the buyer may buy again meanwhile: a new round trip
    while market.pending_settlement(buyer.address)[0]:
        market.settle(buyer.address, 1, sender=robots[5])  # anyone may push the settlement on
    # buyItem (the depositor, no bounty) paid robot 1 a half share; robot 5 paid robot 2 and earned the
    # bounty, 500_000_000 // 50_000 units per unit of work, out of robot 2's share.
    assert market.balance_of(robots[1].address) == 1_250_000_000
    assert market.balance_of(robots[2].address) == 1_250_000_000 - 10_000
    assert market.balance_of(robots[5].address) == 1_000_000_000 + 10_000
    assert [r[0] for r in market.contributors(buyer.address)] == [robots[3].address]
    with pytest.raises(ContractRevert) as refused:
        market.settle(buyer.address, 1)
    assert refused.value.name == "InfoMarketNothingToSettle"


def test_a_robot_that_dies_mid_trip_strands_nobodys_stake(make_market, robots):
    """Robot 0 buys from three sellers and never deposits again. stakeExpiry blocks after its first
    record anyone can settle the round trip, as a deposit would: the three agreeing records (10, 20 and
    30 degrees, eq. 7 counts 3 each) share the dead robot's 0.5 share and their 0.12 of stakes equally,
    floor(620 000 000 / 3) = 206 666 666 each, and the dead robot keeps the 2 units of dust. Before,
    nothing moves."""
    market = make_market("outlier", stake=0.04, stake_expiry=10)
    dead = robots[0]
    opened = [sell(market, robots[k], dead, FOOD, 10.0 * k)[0].block_number for k in (1, 2, 3)]
    assert market.locked_stake(dead.address) == 3 * 40_000_000
    market.backend.advance_to(opened[0] + 9)  # one block short for the first record
    assert market.refund_expired(dead.address).of("RoundTripExpired") == []
    market.backend.advance_to(opened[0] + 10)
    results = market.expire(dead.address)  # the market's key: an outside caller, unregistered, no bounty
    (closed,) = results[0].of("RoundTripExpired")
    assert (closed["share"], closed["pot"], closed["transactions"]) == (500_000_000, 120_000_000, 3)
    assert market.locked_stake(dead.address) == 0
    assert [market.balance_of(robots[k].address) for k in (1, 2, 3)] == [TOKEN_UNIT + 166_666_666] * 3
    assert market.balance_of(dead.address) == TOKEN_UNIT - 500_000_000 + 2
    assert market.contributors(dead.address) == []
    assert market.total_supply() == sum(market.balance_of(a.address) + market.bond_of(a.address) for a in robots)


def test_a_deposit_on_an_expired_round_trip_nobody_closed_is_a_prompt_deposit(make_market, robots):
    """Deposit at block t + T: the record opened at t has expired the round trip, but nobody called
    refundExpired; the deposit weighs both records as it would have promptly (10 and 12 degrees agree:
    0.5 + 0.08 shared equally), and the buyer pays the share once, from the reward."""
    market = make_market("outlier", stake=0.04, stake_expiry=5)
    buyer = robots[0]
    first = sell(market, robots[1], buyer, FOOD, 10.0)[0].block_number
    market.backend.advance_to(first + 1)
    sell(market, robots[2], buyer, FOOD, 12.0)
    market.backend.advance_to(first + 5)
    results = market.deposit(buyer.address)
    assert [e for r in results for e in r.of("RoundTripExpired")] == []
    assert [(e["seller"], e["weight"], e["amount"]) for e in shares_of(results)] == [
        (robots[1].address, 2, 290_000_000), (robots[2].address, 2, 290_000_000)]
    assert market.balance_of(robots[1].address) == TOKEN_UNIT + 250_000_000
    assert market.balance_of(robots[2].address) == TOKEN_UNIT + 250_000_000
    assert market.balance_of(buyer.address) == TOKEN_UNIT + 500_000_000


def test_a_settlement_can_be_recomputed_from_the_logs_alone(make_market, robots):
    """An auditor with nothing but the events: vectors, seller positions and path hashes from
    InformationRevealed, the weights recomputed in floats with atan2, the shares from ItemBought's pot."""
    market = make_market("outlier", stake=0.04)
    buyer = robots[0]
    revealed = []
    for k, direction in enumerate((5.0, 20.0, 31.0, 200.0, 215.0, 90.0)):
        result, lc, info = sell(market, robots[1 + k % 6], buyer, k % 2, direction, age=k)
        revealed += result.of("InformationRevealed")
    results = market.deposit(buyer.address)
    (bought,) = results[0].of("ItemBought")
    logged = shares_of(results)

    def direction_of(e):
        return math.degrees(math.atan2(e["y"] - e["sellerY"], e["x"] - e["sellerX"])) % 360

    assert len({e["pathHash"] for e in revealed}) == len(revealed)  # each commitment is in its event
    weights = [sum(1 for o in revealed if o["site"] == e["site"]
                   and min(abs(direction_of(o) - direction_of(e)) % 360,
                           360 - abs(direction_of(o) - direction_of(e)) % 360) < 30)
               for e in revealed]
    amount = 500_000_000 + bought["pot"]
    assert [e["weight"] for e in logged] == weights
    assert [e["amount"] for e in logged] == [amount * w // sum(weights) for w in weights]
    assert [e["seller"] for e in logged] == [e["seller"] for e in revealed]


@pytest.fixture(scope="module")
def vector_markets(chain, robots, make_market):
    """One market per (scheme, robots, initial wealth, theta) of the cases, deployed once; each case
    starts from this snapshot of the chain."""
    markets = {}
    for case in CASES:
        key = (case["scheme"], case["robots"], case["initial_wealth"], case["theta_deg"])
        if key not in markets:
            scheme, stake = SCHEMES[case["scheme"]]
            wealth = [case["initial_wealth"]] * case["robots"] + [0.0] * (len(robots) - case["robots"])
            markets[key] = make_market(scheme, stake=stake, wealth=wealth, theta_deg=case["theta_deg"])
    return markets, chain, chain.snapshot()


@pytest.mark.parametrize("case", CASES, ids=[f"{i}-{c['scheme']}" for i, c in enumerate(CASES)])
def test_contract_reproduces_the_original_simulators_payments(case, vector_markets, robots):
    scheme, stake = SCHEMES[case["scheme"]]
    assert stake == case["stake"]
    n = case["robots"]
    markets, chain, snapshot = vector_markets
    chain.revert(snapshot)
    market = markets[(case["scheme"], n, case["initial_wealth"], case["theta_deg"])]
    exact = ExactLedger(n, scheme, Fraction(case["reward"]), Fraction(str(case["information_share"])),
                        Fraction(str(stake)), Fraction(case["theta_deg"]), Fraction(str(case["initial_wealth"])))
    buyer = robots[case["buyer"]]
    for age, tx in enumerate(case["transactions"]):
        seller = robots[tx["seller"]]
        site = FOOD if tx["site"] == "food" else NEST
        assert exact.purchase(case["buyer"], tx["seller"], site, Fraction(str(tx["direction_deg"]))) == tx["accepted"]
        if tx["accepted"]:
            sell(market, seller, buyer, site, tx["direction_deg"], age)
        else:
            balance = market.balance_of(seller.address)
            with pytest.raises(ContractRevert) as refused:
                sell(market, seller, buyer, site, tx["direction_deg"], age)
            assert refused.value.name == "InfoMarketInsufficientStake"
            assert refused.value.args_by_name == {"robot": seller.address, "balance": balance,
                                                  "needed": to_units(stake)}

    # Stakes are whole units: before the deposit the balances are exact.
    chain = [market.balance_of(robots[i].address) for i in range(n)]
    assert chain == [to_units(case["balances_after_transactions"][str(i)]) for i in range(n)]

    market.deposit(buyer.address)
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
    bonds = sum(market.bond_of(a.address) for a in robots)  # every robot registered, each locked its bond
    assert sum(chain) + pots + bonds == market.total_supply() == (to_units(case["initial_wealth"]) * n + TOKEN_UNIT
                                                                  + bonds)


def test_the_cap_is_a_constructor_parameter_validated_like_the_others(chain, artifact, make_market):
    """OutlierCapped needs a cap of at least 1 and every other scheme a cap of 0; under OutlierCapped the
    reward and the stake stay below 2^96 units (so that no payment product overflows)."""
    capped = MarketParams.from_floats("capped_outlier", stake=0.04, cap=2)
    for params, name, value in ((replace(capped, cap=0), "cap", 0),
                                (replace(MarketParams.from_floats("outlier"), cap=3), "cap", 3),
                                (replace(capped, reward=2**96), "reward", 2**96),
                                (replace(capped, stake=2**96), "stake", 2**96)):
        with pytest.raises(ContractRevert) as refused:
            ChainMarket.deploy(params, backend=chain, artifact=artifact)
        assert refused.value.name == "InfoMarketInvalidParameter"
        assert refused.value.args_by_name == {"parameter": name.encode().ljust(32, b"\0"), "value": value}
    market = make_market("capped_outlier", stake=0.04, cap=2, wealth=0.0)
    config = market.view("configuration")
    assert (config[0], config[3], config[-1]) == (3, 40_000_000, 2)  # Scheme.OutlierCapped, the stake, the cap
    assert make_market("outlier", wealth=0.0).view("configuration")[-1] == 0


def test_the_client_encodes_the_rules_cap():
    """The rule counts a record while fewer than ``cap`` of its seller's came before it, so a cap of 2.5
    counts 3; a cap beyond the 512 records a round trip holds is 512; only capped_outlier takes one."""
    assert MarketParams.from_floats("capped_outlier").cap == 3  # the rule's default
    assert MarketParams.from_floats("capped_outlier", cap=2.5).cap == 3
    assert MarketParams.from_floats("capped_outlier", cap=1).cap == 1
    assert MarketParams.from_floats("capped_outlier", cap=1e12).cap == 512
    assert MarketParams.from_floats("outlier").cap == 0
    with pytest.raises(ConfigError, match="cap must be at least 1, not 0.5"):
        MarketParams.from_floats("capped_outlier", cap=0.5)
    with pytest.raises(ConfigError, match="cap is a parameter of the capped_outlier scheme, not of 'outlier'"):
        MarketParams.from_floats("outlier", cap=2)


def test_a_capped_round_trip_settles_across_transactions_and_pays_what_the_rules_say(make_market, robots):
    """60 records of 7 sellers on both sites with cap 3 (39 of them void) and a batch of 8: weighing and
    paying resume across calls, and the result is the exact ledger's, within the rounding bound."""
    market = make_market("capped_outlier", stake=0.04, cap=3, settle_batch=8, wealth=10.0)
    exact = ExactLedger(len(robots), "capped_outlier", Fraction(1), Fraction(1, 2), Fraction(1, 25), Fraction(30),
                        Fraction(10), cap=3)
    buyer = 0
    rng = random.Random(2)
    for k in range(60):
        seller, site, direction = 1 + k % 7, k % 2, round(rng.uniform(0.0, 90.0), 3)
        sell(market, robots[seller], robots[buyer], site, direction, age=k)
        assert exact.purchase(buyer, seller, site, Fraction(direction))
    results = market.deposit(robots[buyer].address, batch=8)
    exact.deposit(buyer)
    assert len(results) > 2
    shares = shares_of(results)
    (done,) = results[-1].of("SettlementCompleted")
    # the total weight is C, the counted records' counts, and a void record (each seller's records after
    # its first 3) weighs stake x C
    c = done["totalWeight"]
    assert sum(1 for e in shares if e["weight"] == 40_000_000 * c) == 60 - 3 * 7
    assert sum(e["amount"] for e in shares) == done["shared"]
    for i, account in enumerate(robots):
        gap = market.balance_of(account.address) - exact.balance[i] * TOKEN_UNIT
        assert abs(gap) < max(exact.bound[i], 1)
    assert market.total_supply() == sum(market.balance_of(a.address) + market.bond_of(a.address) for a in robots)


def test_funding_on_py_evm_tops_an_account_up_and_sends_nothing_to_one_funded_already():
    from infomarket.evm.market import connect, derived_account

    chain = connect(backend="py-evm")
    account = derived_account("fund-check", 0).address
    chain.fund([account], 5)
    assert chain.balance(account) == 5
    block = chain.block_number
    chain.fund([account], 5)
    assert chain.block_number == block and chain.balance(account) == 5
    chain.fund([account], 7)
    assert chain.block_number == block + 1 and chain.balance(account) == 7


def test_a_refused_transaction_or_deployment_spends_no_block_and_names_the_error(make_market, chain, artifact):
    market = make_market("outlier")
    block = chain.block_number
    with pytest.raises(ContractRevert) as refused:
        market.settle(market.market.address, 1)
    assert refused.value.name == "InfoMarketNothingToSettle"
    assert chain.block_number == block
    refused_params = MarketParams.from_floats("delayed", stake=0.04)
    with pytest.raises(ContractRevert):  # its accounts are topped up with gas money first
        ChainMarket.deploy(refused_params, backend=chain, artifact=artifact)
    block = chain.block_number
    with pytest.raises(ContractRevert) as refused:
        ChainMarket.deploy(refused_params, backend=chain, artifact=artifact)
    assert refused.value.name == "InfoMarketInvalidParameter"
    assert chain.block_number == block
