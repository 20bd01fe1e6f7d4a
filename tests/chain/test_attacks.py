"""Every way to cheat the market that the contract must refuse, each with its custom error and values.

Each test also checks that nothing changed on a refusal. tests/chain/mutation.py removes each check
from a copy of the contract in turn and shows that the test guarding it then fails.
"""
from __future__ import annotations

from dataclasses import replace

import pytest
from eth_account import Account
from eth_account.messages import encode_typed_data

from infomarket.chain.errors import ContractRevert
from infomarket.chain.protocol import (
    FOOD,
    SECP256K1_N,
    Domain,
    PathInfo,
    accept_offer,
    acceptance_typed_data,
    sign_offer,
)


@pytest.fixture
def market(make_market):
    return make_market("outlier", stake=0.04)


def deal(market, seller, buyer, blocks_valid=8, domain=None, info=None):
    info = info or PathInfo.from_floats(5.0, -2.0)
    return market.light_contract(seller, buyer, FOOD, 9, info, (0.5, 0.5), blocks_valid, domain), info


def refused(call, name: str, **expected) -> ContractRevert:
    with pytest.raises(ContractRevert) as info:
        call()
    assert info.value.name == name
    assert info.value.args_by_name == expected
    return info.value


def untouched(market, *accounts, wealth=1_000_000_000):
    """Nothing moved: each account has its initial wealth, no locked stake and no records."""
    for a in accounts:
        assert market.balance_of(a.address) == wealth
        assert market.locked_stake(a.address) == 0
        assert market.contributors(a.address) == []


def test_reveal_after_the_max_block_is_refused_and_the_last_block_is_still_allowed(market, robots):
    seller, buyer = robots[1], robots[0]
    on_time, info = deal(market, seller, buyer, blocks_valid=1)  # the very next block is the last one
    market.reveal(seller, on_time, info)
    late, info = deal(market, seller, buyer, blocks_valid=0)  # expired as soon as it is signed
    now = market.backend.block_number
    refused(lambda: market.reveal(seller, late, info), "InfoMarketExpiredContract",
            maxBlock=now - 1, currentBlock=now)
    assert len(market.contributors(buyer.address)) == 1


def test_forged_buyer_signature_is_refused(market, robots):
    seller, buyer, forger = robots[1], robots[0], robots[6]
    info = PathInfo.from_floats(5.0, -2.0)
    offer = market.light_contract(seller, forger, FOOD, 9, info, (0.0, 0.0)).offer
    # The forger signs an acceptance and claims it comes from the buyer, to charge the buyer's reward.
    forged = replace(accept_offer(forger.key, market.domain, offer, sign_offer(seller.key, market.domain, offer),
                                  (0.0, 0.0), 0), buyer=buyer.address)
    refused(lambda: market.reveal(seller, forged, info), "InfoMarketInvalidBuyerSignature",
            buyer=buyer.address, recovered=_recover(market.domain, forged))
    untouched(market, seller, buyer)


def test_the_same_light_contract_cannot_be_revealed_twice(market, robots):
    seller, buyer = robots[1], robots[0]
    lc, info = deal(market, seller, buyer)
    market.reveal(seller, lc, info)
    key = market.view("revealKey", FOOD, 9, lc.offer.max_block, buyer.address, seller.address, info.digest())
    refused(lambda: market.reveal(seller, lc, info), "InfoMarketAlreadyRevealed", key=key)
    # The same sale with a fresh buyer signature (another seller position): still the same sale.
    again = accept_offer(buyer.key, market.domain, lc.offer, lc.offer_signature, (0.25, 0.5), 0)
    refused(lambda: market.reveal(seller, again, info), "InfoMarketAlreadyRevealed", key=key)
    assert len(market.contributors(buyer.address)) == 1
    assert market.balance_of(seller.address) == 960_000_000


def test_a_second_different_sale_with_the_same_site_age_and_max_block_is_allowed(market, robots):
    """Finding: the uniqueness key omitted pathHash, so a second, different sale with the same
    (site, age, maxBlock) was refused as a replay. The key now includes the committed information."""
    seller, buyer = robots[1], robots[0]
    lc, info = deal(market, seller, buyer)
    market.reveal(seller, lc, info)
    other = PathInfo.from_floats(50.0, 20.0)
    offer = replace(lc.offer, path_hash=other.digest())
    second = accept_offer(buyer.key, market.domain, offer, sign_offer(seller.key, market.domain, offer), (0.5, 0.5), 0)
    market.reveal(seller, second, other)
    assert len(market.contributors(buyer.address)) == 2
    assert market.balance_of(seller.address) == 1_000_000_000 - 2 * 40_000_000


def test_a_signature_for_another_market_contract_is_refused(make_market, market, robots):
    seller, buyer = robots[1], robots[0]
    elsewhere = make_market("outlier", stake=0.04)
    lc, info = deal(elsewhere, seller, buyer)  # signed for the other contract's domain
    refused(lambda: market.reveal(seller, lc, info), "InfoMarketInvalidBuyerSignature",
            buyer=buyer.address, recovered=_recover(market.domain, lc))
    untouched(market, seller, buyer)
    elsewhere.reveal(seller, lc, info)  # where it was signed for, it is good


def test_a_signature_for_another_chain_id_is_refused(market, robots):
    seller, buyer = robots[1], robots[0]
    mainnet = Domain(1, market.address)
    assert market.domain.chain_id != 1
    lc, info = deal(market, seller, buyer, domain=mainnet)
    refused(lambda: market.reveal(seller, lc, info), "InfoMarketInvalidBuyerSignature",
            buyer=buyer.address, recovered=_recover(market.domain, lc))
    untouched(market, seller, buyer)


def test_a_third_party_cannot_submit_someone_elses_light_contract(market, robots):
    seller, buyer, thief = robots[1], robots[0], robots[5]
    lc, info = deal(market, seller, buyer)
    refused(lambda: market.reveal(thief, lc, info), "InfoMarketUnauthorizedSeller",
            caller=thief.address, seller=seller.address)
    untouched(market, seller, buyer, thief)


def test_revealed_information_must_match_its_committed_hash(market, robots):
    seller, buyer = robots[1], robots[0]
    lc, info = deal(market, seller, buyer)
    swapped = replace(info, x=info.y, y=-info.x)  # a saboteur's switch: the vector turned by 90 degrees
    refused(lambda: market.reveal(seller, lc, swapped), "InfoMarketInformationMismatch",
            committed=info.digest(), revealed=swapped.digest())
    untouched(market, seller, buyer)


@pytest.mark.parametrize("wealth", [0.0, 0.03], ids=["missing", "insufficient"])
def test_a_seller_that_cannot_lock_the_stake_is_refused(make_market, robots, wealth):
    market = make_market("outlier", stake=0.04, wealth=[1.0, wealth] + [1.0] * (len(robots) - 2))
    seller, buyer = robots[1], robots[0]
    lc, info = deal(market, seller, buyer)
    refused(lambda: market.reveal(seller, lc, info), "InfoMarketInsufficientStake",
            robot=seller.address, balance=round(wealth * 1e9), needed=40_000_000)
    assert market.contributors(buyer.address) == [] and market.locked_stake(buyer.address) == 0


def test_only_the_market_account_may_buy_items(market, robots):
    seller, buyer = robots[1], robots[0]
    lc, info = deal(market, seller, buyer)
    market.reveal(seller, lc, info)
    refused(lambda: market.buy_item(buyer.address, sender=buyer), "InfoMarketUnauthorizedMarket",
            caller=buyer.address)
    assert market.balance_of(buyer.address) == 1_000_000_000
    assert len(market.contributors(buyer.address)) == 1


def test_a_malleated_high_s_signature_is_refused(market, robots):
    seller, buyer = robots[1], robots[0]
    lc, info = deal(market, seller, buyer)
    high_s = (SECP256K1_N - int.from_bytes(lc.s, "big")).to_bytes(32, "big")
    twin = replace(lc, s=high_s, v=55 - lc.v)
    # The twin is a valid signature by the buyer: only the low-s rule tells it apart.
    assert _recover(market.domain, twin) == buyer.address
    refused(lambda: market.reveal(seller, twin, info), "InfoMarketMalleableSignature", s=high_s)
    untouched(market, seller, buyer)


def test_selling_to_oneself_is_refused(market, robots):
    robot = robots[2]
    lc, info = deal(market, robot, robot)
    refused(lambda: market.reveal(robot, lc, info), "InfoMarketSelfDealing", robot=robot.address)


def test_malformed_site_and_vector_out_of_range_are_refused(market, robots):
    seller, buyer = robots[1], robots[0]
    info = PathInfo.from_floats(1.0, 1.0)
    lc = market.light_contract(seller, buyer, 2, 9, info, (0.0, 0.0))
    refused(lambda: market.reveal(seller, lc, info), "InfoMarketInvalidSite", site=2)
    far = PathInfo(2**47, 0)  # 2^47 micro units from the seller: beyond the exact similarity test
    lc = market.light_contract(seller, buyer, FOOD, 9, far, (0.0, 0.0))
    refused(lambda: market.reveal(seller, lc, far), "InfoMarketVectorOutOfRange", dx=2**47, dy=0)
    near = PathInfo(2**47 - 1, -(2**47 - 1))
    lc = market.light_contract(seller, buyer, FOOD, 10, near, (0.0, 0.0))
    market.reveal(seller, lc, near)


def test_one_seller_cannot_fill_a_buyers_round_trip(make_market, robots):
    market = make_market("delayed", stake=0.0, max_records_per_seller=2)
    seller, other, buyer = robots[1], robots[2], robots[0]
    for age in (1, 2):
        info = PathInfo.from_floats(1.0, 1.0)
        market.reveal(seller, market.light_contract(seller, buyer, FOOD, age, info, (0.0, 0.0)), info)
    info = PathInfo.from_floats(1.0, 1.0)
    lc = market.light_contract(seller, buyer, FOOD, 3, info, (0.0, 0.0))
    refused(lambda: market.reveal(seller, lc, info), "InfoMarketTooManyRecords",
            buyer=buyer.address, seller=seller.address, limit=2)
    market.reveal(other, market.light_contract(other, buyer, FOOD, 3, info, (0.0, 0.0)), info)  # others still can
    market.deposit(buyer.address)
    fresh = market.light_contract(seller, buyer, FOOD, 4, info, (0.0, 0.0))  # signed for the new round trip
    market.reveal(seller, fresh, info)


def test_a_light_contract_cannot_stay_open_for_longer_than_max_validity(make_market, robots):
    market = make_market("outlier", stake=0.04, max_validity=4)
    seller, buyer = robots[1], robots[0]
    lc, info = deal(market, seller, buyer, blocks_valid=6)  # last block 5 blocks after the next one
    now = market.backend.block_number
    refused(lambda: market.reveal(seller, lc, info), "InfoMarketValidityTooLong",
            maxBlock=now + 5, limit=now + 4)
    untouched(market, seller, buyer)
    lc, info = deal(market, seller, buyer, blocks_valid=5)
    market.reveal(seller, lc, info)


def test_a_saboteurs_rotated_vector_gets_the_outliers_weight_whatever_it_says(market, robots):
    """The bypass of the old contract: a saboteur commits its vector rotated by 90 degrees but
    declared the honest direction, and the contract weighed the declaration. Now there is nothing to
    declare: the weight comes from the committed vector minus the buyer-signed seller position."""
    buyer, saboteur = robots[0], robots[4]
    # The seller stands far from the buyer, so the purchased vectors (position + rotated vector) all
    # point roughly the same way: only the seller's own vector tells the saboteur apart.
    position = (-30.0, 40.0)
    honest = [(10.0, 1.0), (9.0, 2.5), (11.0, 0.0)]  # directions 5.7, 15.5 and 0 degrees from the seller
    for seller, (dx, dy) in zip(robots[1:4], honest):
        info = PathInfo.from_floats(position[0] + dx, position[1] + dy)
        market.reveal(seller, market.light_contract(seller, buyer, FOOD, 3, info, position), info)
    # The honest direction is 5.7 degrees; the saboteur's vector (-1, 10) points at 95.7 degrees.
    rotated = PathInfo.from_floats(position[0] - 1.0, position[1] + 10.0)
    market.reveal(saboteur, market.light_contract(saboteur, buyer, FOOD, 3, rotated, position), rotated)
    shares = [e for r in market.deposit(buyer.address) for e in r.of("RewardShared")]
    assert [(e["seller"], e["weight"]) for e in shares] == [(r.address, w) for r, w in
                                                             zip(robots[1:5], (3, 3, 3, 1))]
    amount = 500_000_000 + 4 * 40_000_000  # the share of the reward plus the four stakes
    assert shares[3]["amount"] == amount * 1 // 10  # the outlier's tenth, not a quarter
    assert market.balance_of(saboteur.address) == 1_000_000_000 - 40_000_000 + amount // 10


def _recover(domain, lc) -> str:
    """Who the light contract's buyer signature recovers to under ``domain``."""
    typed = acceptance_typed_data(domain, lc.offer, lc.buyer, lc.seller_x, lc.seller_y, lc.trip)
    return Account.recover_message(encode_typed_data(full_message=typed),
                                   vrs=(lc.v, int.from_bytes(lc.r, "big"), int.from_bytes(lc.s, "big")))
