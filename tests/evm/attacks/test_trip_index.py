"""A buyer's record indices are never reset under a round trip that holds records.

The exploit: a settlement left pending for `stakeExpiry` blocks while the buyer's next round trip
receives a record that then expires and is refunded (anyone could call `refundExpired`). When that
settlement finished, the contract saw an empty open round trip and restarted the buyer's indices at
0, but the refunded seller's per-buyer link (`_sold`) still held its old index: its next reveal
underflowed (`Panic(0x11)`), or its link pointed at another seller's record, and under
`outlier_distinct` the two sellers were counted as one voice and paid half a share each. An expiry
now closes the whole round trip (a new round trip number, so no link of it counts again), and only
once the pending settlement is finished.
"""
from __future__ import annotations

import pytest

from .helpers import refused, sell, settle_all


@pytest.mark.parametrize("order", ["linked-to-another", "revealed-first"])
def test_a_refunded_record_under_a_pending_settlement_keeps_its_sellers_link(make_market, robots, order):
    # expiry 10 blocks: on py-evm every transaction is a block, and the 5 transactions of the last round
    # trip must not see its first record expire
    market = make_market("outlier_distinct", stake=0.0, settle_batch=1, stake_expiry=10, settlement_deadline=10**6)
    buyer, refunded, honest = robots[0], robots[4], robots[1:4]
    sell(market, robots[5], buyer, 10.0, age=0)  # round trip 0: records 0 and 1
    sell(market, robots[6], buyer, 12.0, age=1)
    market.buy_item(buyer.address)  # one unit of work: the settlement stays pending
    sell(market, refunded, buyer, 11.0, age=2)  # round trip 1: record 2
    market.backend.advance_to(market.backend.block_number + 10)
    refused(lambda: market.refund_expired(buyer.address), "InfoMarketSettlementPending", robot=buyer.address,
            remaining=1)  # round trip 0 first: 1 of its 2 records weighed
    settle_all(market, buyer.address, 1)  # round trip 0 settles
    (closed,) = market.expire(buyer.address)[0].of("RoundTripExpired")  # round trip 1: its one record gets 0.5
    assert closed["transactions"] == 1 and market.balance_of(refunded.address) == 10**9 + 500_000_000
    sellers = [*honest, refunded] if order == "linked-to-another" else [refunded, *honest]
    for age, seller in enumerate(sellers):
        sell(market, seller, buyer, 10.0 + age, age=10 + age)
    shares = [e for r in market.deposit(buyer.address) for e in r.of("RewardShared")]
    # Four distinct sellers, every pair within theta, share 0.5: four equal voices, 0.125 token each.
    expected = [(s.address, 4 * 10**27, 125_000_000) for s in sellers]
    assert sorted((e["seller"], e["weight"], e["amount"]) for e in shares) == sorted(expected)
