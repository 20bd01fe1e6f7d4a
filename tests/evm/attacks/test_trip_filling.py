"""Colluding sellers cannot fill a buyer's round trip, and one party's records bound its settlement.

The exploit: two registered colluders sold one buyer 256 records each through the project's own
client, which capped acceptances per round trip (4 096), not per seller: the round trip held its 512
live records and every honest seller who met that buyer afterwards was refused (`InfoMarketTripFull`).
A 25-robot, 15 000-step paper run reaches at most 82 records per seller and buyer: the default cap is
96, so filling a round trip took ceil(512 / 96) = 6 registered identities; now a seller's further
records in a round trip may take at most half of the room its first records leave, and filling it takes
at least 257.
"""
from __future__ import annotations

import pytest

from infomarket.evm.errors import ContractRevert
from infomarket.evm.market import DEFAULT_MAX_RECORDS_PER_SELLER, DEFAULT_MAX_RECORDS_PER_TRIP
from infomarket.evm.protocol import PathInfo, ProtocolError

from .helpers import sell


def test_the_default_caps_leave_room_for_honest_sellers():
    assert 82 < DEFAULT_MAX_RECORDS_PER_SELLER <= DEFAULT_MAX_RECORDS_PER_TRIP // 4


def test_two_colluders_selling_all_they_can_leave_the_round_trip_open(make_market, robots):
    market = make_market("outlier_distinct", stake=0.0)
    buyer, colluders, honest = robots[0], robots[1:3], robots[3]
    landed = {}
    for c, colluder in enumerate(colluders):
        landed[colluder.address] = 0
        for k in range(DEFAULT_MAX_RECORDS_PER_TRIP // 2):
            try:
                sell(market, colluder, buyer, 100.0, age=1000 * c + k)
            except ContractRevert as refusal:
                assert refusal.name == "InfoMarketTooManyRecords"
                assert refusal.args_by_name == {"buyer": buyer.address, "seller": colluder.address,
                                                "limit": DEFAULT_MAX_RECORDS_PER_SELLER}
                break
            landed[colluder.address] += 1
    assert list(landed.values()) == [DEFAULT_MAX_RECORDS_PER_SELLER] * 2
    sell(market, honest, buyer, 10.0, age=5000)  # an honest seller still sells
    assert len(market.contributors(buyer.address)) == 2 * DEFAULT_MAX_RECORDS_PER_SELLER + 1


def test_the_buyers_client_caps_its_acceptances_per_seller(make_market, robots):
    market = make_market("outlier_distinct", stake=0.0, max_records_per_seller=2)
    assert market.max_acceptances_per_seller == 16
    market.max_acceptances_per_seller = 2
    buyer, seller, other = robots[0], robots[1], robots[2]
    info = PathInfo.from_floats(1.0, 1.0)
    for age in range(2):
        market.light_contract(seller, buyer, 0, age, info, (0.0, 0.0))
    with pytest.raises(ProtocolError, match="at most 2 per seller"):
        market.light_contract(seller, buyer, 0, 2, info, (0.0, 0.0))
    market.light_contract(other, buyer, 0, 2, info, (0.0, 0.0))  # another seller: still accepted


def _sell_all(market, seller, buyer, start: int, errors: set[str]) -> int:
    """``seller`` sells ``buyer`` records until refused (the refusal's name into ``errors``); how many landed."""
    for k in range(DEFAULT_MAX_RECORDS_PER_SELLER):
        try:
            sell(market, seller, buyer, 100.0, age=start + k)
        except ContractRevert as refusal:
            errors.add(refusal.name)
            return k
    return DEFAULT_MAX_RECORDS_PER_SELLER


def test_six_colluders_selling_all_they_can_leave_room_for_an_honest_seller(make_market, robots):
    """Six registered colluders used to fill the 512 records (96 each, the per-seller cap) and the honest
    seller was refused (`InfoMarketTripFull`). A seller's further records in a round trip may take at most
    half of the room its first records leave: 2 * (repeats + 1) + first records <= 512. By hand: the first
    two colluders land 96 each (1 first record and 95 repeats), the third 1 + 64 (2 * 254 + 3 = 511; one
    more would make 513), the last three 1 each: 260 records, and room for 252 sellers more. To fill the
    round trip, colluders need at least 257 registered identities (docs/chain.md)."""
    market = make_market("outlier_distinct", stake=0.0)
    buyer, colluders, honest = robots[0], robots[1:7], robots[7]
    errors: set[str] = set()
    landed = [_sell_all(market, c, buyer, 1000 * i, errors) for i, c in enumerate(colluders)]
    assert landed == [96, 96, 65, 1, 1, 1] and errors == {"InfoMarketTripReserved"}
    sell(market, honest, buyer, 10.0, age=10_000)  # an honest seller still sells
    assert len(market.contributors(buyer.address)) == 261
