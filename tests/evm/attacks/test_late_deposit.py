"""A buyer that waits for its records to expire before depositing still pays the share.

The exploit: a record expires `stakeExpiry` blocks after its reveal; its stake went back to its seller
and it took no part in the deposit. A buyer that held its item until every record of its round trip
had expired and then deposited kept the whole reward, share included (+1 token instead of +0.5 at the
paper's terms), and its sellers got only their stakes back. Now every record of the round trip is
paid at the deposit: an expired one an equal part of the share, share / n for the round trip's n
records (its stake already went back), the live ones the rest (share * live / n, plus their stakes) by
the scheme's weights, however late the settlement is finished. By hand (outlier_distinct, stake 0.04, share 0.5
of a reward of 1, wealth 1 each).
"""
from __future__ import annotations

from .helpers import sell, settle_all

TOKEN = 1_000_000_000
EXPIRY = 20  # blocks; on py-evm every transaction is a block


def _market(make_market, **options):
    return make_market("outlier_distinct", stake=0.04, stake_expiry=EXPIRY, settlement_deadline=10**6, **options)


def _wait(market):
    market.backend.advance_to(market.backend.block_number + EXPIRY)


def test_a_buyer_that_waits_until_every_record_expired_pays_the_share(make_market, robots):
    market = _market(make_market)
    buyer, sellers = robots[0], robots[1:5]
    for age, (seller, direction) in enumerate(zip(sellers, (10.0, 15.0, 20.0, 100.0))):
        sell(market, seller, buyer, direction, age=age)
    _wait(market)  # every record has expired: the buyer deposits only now
    results = market.deposit(buyer.address)
    assert len([e for r in results for e in r.of("RecordExpired")]) == 4
    # the buyer gains what it gains by depositing at once: the reward less the share
    assert market.balance_of(buyer.address) == TOKEN + TOKEN // 2
    # each of the 4 records is paid 0.5 / 4 token, its stake back besides (the outlier too: not weighed)
    for seller in sellers:
        assert market.balance_of(seller.address) == TOKEN + TOKEN // 8
    shares = [e for r in results for e in r.of("RewardShared")]
    assert [(e["weight"], e["amount"]) for e in shares] == [(0, TOKEN // 8)] * 4


def test_expired_records_are_paid_equal_parts_and_the_live_ones_the_rest_by_weight(make_market, robots):
    market = _market(make_market)
    buyer = robots[0]
    sell(market, robots[1], buyer, 10.0, age=0)
    sell(market, robots[2], buyer, 15.0, age=1)
    _wait(market)  # the first two expire
    for age, (seller, direction) in enumerate(zip(robots[3:6], (20.0, 25.0, 100.0))):
        sell(market, seller, buyer, direction, age=2 + age)
    market.deposit(buyer.address)
    assert market.balance_of(buyer.address) == TOKEN + TOKEN // 2
    # n = 5: an expired record gets 0.5 / 5 = 0.1; the 3 live ones share 0.5 * 3 / 5 + 3 * 0.04 = 0.42 by
    # one voice per distinct similar seller: 2, 2 and 1 of 5
    expected = [1.1, 1.1, 1 - 0.04 + 0.42 * 2 / 5, 1 - 0.04 + 0.42 * 2 / 5, 1 - 0.04 + 0.42 / 5]
    assert [market.balance_of(r.address) for r in robots[1:6]] == [round(v * TOKEN) for v in expected]
    supply = sum(market.balance_of(r.address) + market.bond_of(r.address) for r in robots)
    supply += market.locked_stake(buyer.address)
    assert supply == market.total_supply()


def test_past_the_deadline_expired_records_get_equal_parts_and_the_live_ones_their_weight(make_market, robots):
    market = make_market("outlier_distinct", stake=0.04, stake_expiry=EXPIRY, settlement_deadline=5, settle_batch=1)
    buyer = robots[0]
    sell(market, robots[1], buyer, 10.0, age=0)
    sell(market, robots[2], buyer, 15.0, age=1)
    _wait(market)
    for age, (seller, direction) in enumerate(zip(robots[3:6], (20.0, 25.0, 100.0))):
        sell(market, seller, buyer, direction, age=2 + age)
    market.buy_item(buyer.address)  # one unit of work (one refund): the settlement stays pending
    market.backend.advance_to(market.backend.block_number + 5)  # nobody settled in time
    settle_all(market, buyer.address, 1)  # the market's node: past the deadline it earns the bounty
    assert market.balance_of(buyer.address) == TOKEN + TOKEN // 2
    # one refund and 3 weighings paid from the escrow (0.5 + 3 * 0.04 - 40 000 units), an expired record
    # a fifth of what is left past the 3 live stakes, the live ones the rest by voices 2, 2 and 1 of 5,
    # each payment less its 10 000 units of bounty
    amount = 620_000_000 - 40_000
    expired = (amount - 120_000_000) // 5
    live = amount - 2 * expired
    expected = [TOKEN + expired - 10_000] * 2 + [TOKEN - 40_000_000 + live * w // 5 - 10_000 for w in (2, 2, 1)]
    assert [market.balance_of(r.address) for r in robots[1:6]] == expected
