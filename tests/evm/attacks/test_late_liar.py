"""A liar gains nothing when its buyer's settlement is left past the deadline.

The exploit: one seller sells a buyer 10 false records, then 3 honest sellers one true record each.
Weighed, the liar's records count as one voice against three and it loses most of its stakes. When
nobody finished the weighing within `settlementDeadline` blocks of the deposit, the contract stopped
weighing and paid every record an equal part of the share plus the stakes, so the liar's 10 records
took 10 / 13 of the amount. Now weighing goes on whenever anyone settles, and the records are paid by
weight however late (less the bounty, which past the deadline any caller earns). By hand, at the paper's terms
(reward 1 token, share 0.5, stake 0.04), the amount
is 0.5 + 13 * 0.04 = 1.02 token:

- `outlier_distinct`: the liar's records weigh 1/10 of a voice each (1 in all), each honest record 3
  voices: the liar gets 1.02 / 10 = 0.102 of its 0.4 in stakes (-0.298), an honest seller
  1.02 * 3 / 10 - 0.04 = +0.266. The equal parts paid 1.02 / 13 a record: +0.384615380 to the liar.
- `capped_outlier`, cap 1: the liar's first record counts, alone (weight 1), the 9 others are void and
  get their stakes back; C = 1 + 3 * 3 = 10; the counted records share 0.5 + 4 * 0.04 = 0.66 by weight:
  the liar 0.066 - 0.04 = +0.026, an honest seller 0.198 - 0.04 = +0.158.
"""
from __future__ import annotations

import pytest

from .helpers import sell, settle_all

TOKEN = 1_000_000_000
WEALTH = TOKEN
DEADLINE = 100  # blocks: the prompt settlement (25 calls of one unit, a block each on py-evm) ends within it

#: scheme -> (the liar's net, each honest seller's net), by hand (above)
PROMPT = {"outlier_distinct": (-298_000_000, 266_000_000), "capped_outlier": (26_000_000, 158_000_000)}


def _round_trip(make_market, robots, scheme):
    options = {"cap": 1} if scheme == "capped_outlier" else {}
    market = make_market(scheme, stake=0.04, settle_batch=1, settlement_deadline=DEADLINE, **options)
    buyer, liar, honest = robots[0], robots[1], robots[2:5]
    for age in range(10):
        sell(market, liar, buyer, 100.0, age=age)
    for age, (seller, direction) in enumerate(zip(honest, (10.0, 15.0, 20.0))):
        sell(market, seller, buyer, direction, age=100 + age)
    market.buy_item(buyer.address)  # one unit of work: the settlement stays pending
    return market, buyer, liar, honest


def _nets(market, liar, honest):
    return (market.balance_of(liar.address) - WEALTH, [market.balance_of(s.address) - WEALTH for s in honest])


@pytest.mark.parametrize("scheme", sorted(PROMPT))
def test_a_liar_is_paid_by_weight_however_late_its_buyers_settlement_finishes(make_market, robots, scheme):
    liar_net, honest_net = PROMPT[scheme]
    market, buyer, liar, honest = _round_trip(make_market, robots, scheme)
    settle_all(market, buyer.address, 48)  # settled at once
    assert _nets(market, liar, honest) == (liar_net, [honest_net] * 3)

    market, buyer, liar, honest = _round_trip(make_market, robots, scheme)
    market.backend.advance_to(market.backend.block_number + 10 * DEADLINE)  # nobody settled in time
    results = settle_all(market, buyer.address, 48)  # the market's node, unregistered, finishes it
    bounty = sum(e["amount"] for r in results for e in r.of("SettlementBountyPaid"))
    late_liar, late_honest = _nets(market, liar, honest)
    assert liar_net - bounty <= late_liar <= liar_net  # not +384 615 380: weighed as before, less the bounty
    assert all(honest_net - bounty <= net <= honest_net for net in late_honest)
    # past the deadline anyone earns it, 10 000 units per unit of work: 12 records left to weigh, 13 to pay
    assert bounty == (12 + 13) * 10_000
    # the reward less the share, as ever, and the rounding dust (under a unit a record)
    assert 0 <= market.balance_of(buyer.address) - (WEALTH + TOKEN // 2) < 13


EXPIRY = 20  # blocks: more than the 13 reveals take on py-evm (a block each), so none expires before the last


def _expiring_round_trip(make_market, robots, scheme):
    options = {"cap": 1} if scheme == "capped_outlier" else {}
    market = make_market(scheme, stake=0.04, stake_expiry=EXPIRY, settlement_deadline=10**6, **options)
    buyer, liar, honest = robots[0], robots[1], robots[2:5]
    for age in range(10):
        sell(market, liar, buyer, 100.0, age=age)
    for age, (seller, direction) in enumerate(zip(honest, (10.0, 15.0, 20.0))):
        sell(market, seller, buyer, direction, age=100 + age)
    market.backend.advance_to(market.backend.block_number + EXPIRY)  # every record has expired
    return market, buyer, liar, honest


@pytest.mark.parametrize("scheme", sorted(PROMPT))
@pytest.mark.parametrize("trigger", ["refundExpired", "deposit"])
def test_a_liar_is_no_better_off_when_its_buyers_records_expire(make_market, robots, scheme, trigger):
    """The third audit's M1 past expiry: records that expired were refunded their stakes and paid
    share / 13 each at the deposit, +384 615 380 to the liar under both schemes. The expiry is reached
    either by anyone's ``refundExpired`` (then the buyer deposits later) or by the deposit itself."""
    liar_net, honest_net = PROMPT[scheme]
    market, buyer, liar, honest = _expiring_round_trip(make_market, robots, scheme)
    if trigger == "refundExpired":
        market.expire(buyer.address)  # the market's node, unregistered: no bounty
    market.deposit(buyer.address)
    late_liar, late_honest = _nets(market, liar, honest)
    assert late_liar <= liar_net, late_liar  # never better off late than prompt
    assert (late_liar, late_honest) == (liar_net, [honest_net] * 3)  # weighed exactly as a prompt deposit
    # the buyer gains the reward less the share either way, and the rounding dust (under a unit a record)
    assert 0 <= market.balance_of(buyer.address) - (WEALTH + TOKEN // 2) < 13
