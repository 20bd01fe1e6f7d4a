"""A buyer that waits for its records to expire before depositing still pays the share, and its sellers
are weighed as at a prompt deposit.

The first exploit: a record expired `stakeExpiry` blocks after its reveal, its stake went back to its
seller and it took no part in the deposit: a buyer that held its item until every record had expired
kept the whole reward (+1 token instead of +0.5 at the paper's terms). The second: expired records were
then paid an equal part of the share each, unweighed, so an outlier was paid like an honest seller. Now
the first record's expiry closes the whole round trip, which anyone may settle as a deposit settles it,
the buyer paying the share from its balance; a deposit on an expired round trip nobody closed is a
prompt deposit. By hand (outlier_distinct, stake 0.04, share 0.5 of a reward of 1, wealth 1 each).
"""
from __future__ import annotations

import pytest

from .helpers import sell, settle_all

TOKEN = 1_000_000_000
EXPIRY = 20  # blocks; on py-evm every transaction is a block


def _market(make_market, **options):
    return make_market("outlier_distinct", stake=0.04, stake_expiry=EXPIRY, settlement_deadline=10**6, **options)


def _wait(market):
    market.backend.advance_to(market.backend.block_number + EXPIRY)


@pytest.mark.parametrize("closed_by", ["deposit", "refundExpired"])
def test_a_buyer_that_waits_until_every_record_expired_pays_the_share_by_weight(make_market, robots, closed_by):
    market = _market(make_market)
    buyer, sellers = robots[0], robots[1:5]
    for age, (seller, direction) in enumerate(zip(sellers, (10.0, 15.0, 20.0, 100.0))):
        sell(market, seller, buyer, direction, age=age)
    _wait(market)  # every record has expired: the buyer deposits only now
    if closed_by == "refundExpired":
        market.expire(buyer.address)  # anyone: the buyer pays the share from its balance now
    market.deposit(buyer.address)
    # the buyer gains what it gains by depositing at once: the reward less the share
    assert market.balance_of(buyer.address) == TOKEN + TOKEN // 2
    # weighed as at once: 3 agreeing voices each for the honest, 1 for the outlier, of 10: 0.66 shared
    honest, outlier = TOKEN - 40_000_000 + 198_000_000, TOKEN - 40_000_000 + 66_000_000
    assert [market.balance_of(s.address) for s in sellers] == [honest] * 3 + [outlier]


def test_an_expired_round_trip_is_settled_alone_and_the_next_one_at_the_deposit(make_market, robots):
    market = _market(make_market)
    buyer = robots[0]
    sell(market, robots[1], buyer, 10.0, age=0)
    sell(market, robots[2], buyer, 15.0, age=1)
    _wait(market)
    market.expire(buyer.address)  # 10 and 15 agree: 0.5 + 0.08 shared equally, the buyer pays 0.5
    assert [market.balance_of(r.address) for r in robots[1:3]] == [TOKEN + 250_000_000] * 2
    assert market.balance_of(buyer.address) == TOKEN // 2
    for age, (seller, direction) in enumerate(zip(robots[3:6], (20.0, 25.0, 100.0))):
        sell(market, seller, buyer, direction, age=2 + age)
    market.deposit(buyer.address)
    # a new round trip: 0.5 + 0.12 by one voice per distinct similar seller, 2, 2 and 1 of 5; the buyer
    # paid the share twice for one reward
    assert market.balance_of(buyer.address) == TOKEN
    expected = [TOKEN - 40_000_000 + 620_000_000 * w // 5 for w in (2, 2, 1)]
    assert [market.balance_of(r.address) for r in robots[3:6]] == expected
    supply = sum(market.balance_of(r.address) + market.bond_of(r.address) for r in robots)
    supply += market.locked_stake(buyer.address)
    assert supply == market.total_supply()


def test_an_expired_round_trip_left_past_the_deadline_is_still_weighed(make_market, robots):
    market = make_market("outlier_distinct", stake=0.04, stake_expiry=EXPIRY, settlement_deadline=5, settle_batch=1)
    buyer = robots[0]
    for age, (seller, direction) in enumerate(zip(robots[1:4], (10.0, 15.0, 100.0))):
        sell(market, seller, buyer, direction, age=age)
    _wait(market)
    market.refund_expired(buyer.address, 1)  # the market's node: one unit of work (one weighing), no bounty
    market.backend.advance_to(market.backend.block_number + 5)  # nobody settled in time
    settle_all(market, buyer.address, 1)  # the market's node: past the deadline it earns the bounty
    assert market.balance_of(buyer.address) == TOKEN // 2
    # two weighings paid from the escrow (0.5 + 3 * 0.04 - 20 000 units), shared by voices 2, 2 and 1 of
    # 5, each payment less its 10 000 units of bounty
    amount = 620_000_000 - 20_000
    expected = [TOKEN - 40_000_000 + amount * w // 5 - 10_000 for w in (2, 2, 1)]
    assert [market.balance_of(r.address) for r in robots[1:4]] == expected


def test_a_buyer_that_cannot_pay_the_whole_share_pays_its_balance(make_market, robots):
    """The share of an expired round trip comes from the buyer's balance as far as it goes: with 0.2
    token, its one seller gets 0.2 and its stake back. With nothing and no stakes, the escrow is empty:
    a registered robot that settles it, batch by batch, earns no bounty (there is none to take), and the
    settlement still ends."""
    market = make_market("outlier_distinct", stake=0.04, stake_expiry=EXPIRY, wealth=[0.2] + [1.0] * 7)
    buyer, seller = robots[0], robots[1]
    sell(market, seller, buyer, 10.0)
    _wait(market)
    (closed,) = market.expire(buyer.address)[0].of("RoundTripExpired")
    assert (closed["share"], closed["pot"]) == (200_000_000, 40_000_000)
    assert (market.balance_of(buyer.address), market.balance_of(seller.address)) == (0, TOKEN + 200_000_000)

    market = make_market("outlier", stake=0.0, stake_expiry=EXPIRY, settle_batch=1, wealth=[0.0] + [1.0] * 7)
    for age, seller in enumerate(robots[1:3]):
        sell(market, seller, buyer, 10.0, age=age)
    _wait(market)
    keeper = robots[6]  # registered: it earns the bounty where there is one
    results = market.expire(buyer.address, batch=1, sender=keeper)
    assert [e["amount"] for r in results for e in r.of("RewardShared")] == [0, 0]
    assert not market.pending_settlement(buyer.address)[0] and market.balance_of(keeper.address) == TOKEN
