"""The trust model (docs/chain.md, "Trust model"): roles instead of one market key.

The exploit: one market key registered any address with any wealth, without limit, minted rewards for
deposits nobody could check, and could be neither rotated, shared nor paused. Now: a robot is
registered by `registrarThreshold` distinct registrars (2 of 3 by default), each within a quota per
period; a deposit carries the robot's signature over its round trip and a nest's acknowledgement; an
admin rotates keys; a pauser stops registrations, reveals and deposits, never refunds or settlements;
every registration locks a bond out of the grant (1 token by default), returned `bondDelay` blocks
after a clean exit and burned when the registrars revoke the robot.
"""
from __future__ import annotations

import math
from fractions import Fraction

import pytest
from eth_account import Account

from infomarket.evm.errors import ContractRevert
from infomarket.evm.market import ROLES
from infomarket.evm.protocol import SECP256K1_N

from .helpers import refused, sell, settle_all


def test_one_registrar_cannot_register_a_robot_alone(fresh):
    market, (robot, *_) = fresh()
    first, second, _ = market.registrars
    assert market.view("policy") == (2, 32, 5_000, 10**9, 5_000)
    market.approve(first, robot.address, 2 * 10**9)
    assert not market.view("isRegistered", robot.address) and market.balance_of(robot.address) == 0
    refused(lambda: market.approve(first, robot.address, 2 * 10**9), "InfoMarketAlreadyApproved",
            registrar=first.address, robot=robot.address)
    market.approve(second, robot.address, 3 * 10**9 // 2)  # another grant: a separate request, 1 approval
    assert not market.view("isRegistered", robot.address)
    refused(lambda: market.approve(second, robot.address, 10**9 - 1), "InfoMarketGrantBelowBond",
            amount=10**9 - 1, bond=10**9)
    done = market.approve(second, robot.address, 2 * 10**9)
    assert done.of("WealthGranted") == [{"robot": robot.address, "amount": 2 * 10**9}]
    assert done.of("BondLocked") == [{"robot": robot.address, "amount": 10**9}]
    assert market.view("isRegistered", robot.address) and market.balance_of(robot.address) == 10**9
    assert market.bond_of(robot.address) == 10**9 and market.total_supply() == 2 * 10**9


def test_only_registrars_approve_and_each_within_its_quota(fresh):
    market, robots = fresh(accounts=4, registrar_quota=2, registrar_period=1_000)
    registrar = market.registrars[0]
    refused(lambda: market.approve(robots[0], robots[1].address, 0), "InfoMarketUnauthorized",
            caller=robots[0].address, role=ROLES["registrar"])
    refused(lambda: market.approve(market.market, robots[1].address, 0), "InfoMarketUnauthorized",
            caller=market.market.address, role=ROLES["registrar"])  # the market key is no registrar
    backend = market.backend
    backend.advance_to((backend.block_number // 1_000 + 1) * 1_000)  # the start of a period
    for robot in robots[:2]:
        market.approve(registrar, robot.address, 10**9)
    refused(lambda: market.approve(registrar, robots[2].address, 10**9), "InfoMarketRegistrarQuotaExceeded",
            registrar=registrar.address, limit=2)
    backend.advance_to(backend.block_number + 1_000)  # the next period
    market.approve(registrar, robots[2].address, 10**9)


def test_a_single_compromised_registrar_registers_no_cartel(fresh):
    """At the default policy (2 of 3 registrars) one compromised registrar key approving 8 identities
    registers none of them: none may sell, so a cartel's share is nothing."""
    market, robots = fresh(accounts=10)
    cartel, buyer, honest = robots[:8], robots[8], robots[9]
    rogue = market.registrars[0]
    for member in cartel:
        market.approve(rogue, member.address, 10**9)
    market.grant_wealth(buyer, 10**9)
    market.grant_wealth(honest, 10**9)
    assert not any(market.view("isRegistered", m.address) for m in cartel)
    refused(lambda: sell(market, cartel[0], buyer, 100.0), "InfoMarketUnregistered", robot=cartel[0].address)
    sell(market, honest, buyer, 10.0)
    market.deposit(buyer)
    assert market.balance_of(honest.address) == 10**9 + 500_000_000


@pytest.mark.parametrize("colluders, cartel_share, trips", [(3, (9, 18), 12), (8, (64, 73), 16)])
def test_a_registered_cartel_outvotes_three_honest_sellers(fresh, colluders, cartel_share, trips):
    """What registration must keep out (docs/chain.md): c registered colluders agreeing on a false
    direction against 3 honest sellers under outlier_distinct. By hand: each honest record weighs 3
    voices, each colluder's c, so the cartel takes c^2 / (c^2 + 9) of 0.5 + (c + 3) * 0.04 token; less
    its own stakes, it nets 0.25 token per round trip at c = 3 and 0.504 at c = 8, while its c bonds
    (1 token each) are locked: the bonds are repaid after 12 and 16 such round trips, so a cartel that
    the registrars revoke (burning its bonds) before that loses money."""
    market, robots = fresh(stake=0.04, accounts=colluders + 4, label=f"cartel{colluders}")
    buyer, honest, cartel = robots[0], robots[1:4], robots[4:]
    for robot in robots:
        market.grant_wealth(robot, 10**9)
    for age, (seller, direction) in enumerate(zip(honest, (10.0, 15.0, 20.0))):
        sell(market, seller, buyer, direction, age)
    for age, member in enumerate(cartel):
        sell(market, member, buyer, 100.0, 10 + age)
    market.deposit(buyer)
    amount = 500_000_000 + (colluders + 3) * 40_000_000
    took = sum(market.balance_of(m.address) - 960_000_000 for m in cartel)
    num, den = cartel_share
    assert amount * num // den - colluders <= took <= amount * num // den
    net = Fraction(amount * num, den) - colluders * 40_000_000  # what the cartel gains by a round trip
    assert net - colluders <= took - colluders * 40_000_000 <= net
    bonds = sum(market.bond_of(m.address) for m in cartel)
    assert bonds == colluders * 10**9 and math.ceil(bonds / net) == trips
    market.revoke(cartel[0].address)  # found out: its bond is burned
    assert market.bond_of(cartel[0].address) == 0 and market.balance_of(cartel[0].address) < 10**9 + net


def test_a_bond_comes_back_only_after_a_clean_exit_and_its_delay(fresh):
    market, (robot, buyer, other, _) = fresh(bond_delay=20)
    for account in (robot, buyer):
        market.grant_wealth(account, 10**9)  # one token free, one (the bond) locked
    supply = market.total_supply()
    refused(lambda: market.withdraw_bond(robot.address), "InfoMarketNotExiting", robot=robot.address)
    refused(lambda: market.exit(other), "InfoMarketUnregistered", robot=other.address)
    unlock = market.exit(robot).of("ExitRequested")[0]["unlockBlock"]
    assert not market.view("isRegistered", robot.address) and market.bond_of(robot.address) == 10**9
    refused(lambda: sell(market, robot, buyer, 10.0), "InfoMarketUnregistered", robot=robot.address)
    refused(lambda: market.exit(robot), "InfoMarketUnregistered", robot=robot.address)
    market.backend.advance_to(unlock - 2)  # the withdrawal lands in block unlock - 1
    refused(lambda: market.withdraw_bond(robot.address), "InfoMarketBondLocked", robot=robot.address,
            unlockBlock=unlock)
    market.backend.advance_to(unlock)
    assert market.withdraw_bond(robot.address, sender=other).of("BondReturned") == [
        {"robot": robot.address, "amount": 10**9}]
    assert market.balance_of(robot.address) == 2 * 10**9 and market.bond_of(robot.address) == 0
    assert market.total_supply() == supply
    refused(lambda: market.withdraw_bond(robot.address), "InfoMarketNotExiting", robot=robot.address)
    refused(lambda: market.grant_wealth(robot, 10**9), "InfoMarketAlreadyRegistered", robot=robot.address)


def test_the_registrars_revoke_a_robot_and_burn_its_bond_even_during_its_exit(fresh):
    market, (robot, leaving, buyer, stranger) = fresh(bond_delay=50)
    for account in (robot, leaving, buyer):
        market.grant_wealth(account, 10**9)
    supply = market.total_supply()
    first, second, _ = market.registrars
    refused(lambda: market.transact(stranger, "revokeRegistration", robot.address), "InfoMarketUnauthorized",
            caller=stranger.address, role=ROLES["registrar"])
    refused(lambda: market.revoke(stranger.address, [first]), "InfoMarketUnregistered", robot=stranger.address)
    assert market.revoke(robot.address, [first]).of("RevocationApproved")[0]["approvals"] == 1
    assert market.view("isRegistered", robot.address)  # one registrar alone revokes no one
    refused(lambda: market.revoke(robot.address, [first]), "InfoMarketAlreadyApproved", registrar=first.address,
            robot=robot.address)
    done = market.revoke(robot.address, [second])
    assert done.of("BondForfeited") == [{"robot": robot.address, "amount": 10**9}]
    assert not market.view("isRegistered", robot.address) and market.bond_of(robot.address) == 0
    refused(lambda: sell(market, robot, buyer, 10.0), "InfoMarketUnregistered", robot=robot.address)
    refused(lambda: market.grant_wealth(robot, 10**9), "InfoMarketAlreadyRegistered", robot=robot.address)
    unlock = market.exit(leaving).of("ExitRequested")[0]["unlockBlock"]
    market.revoke(leaving.address)  # within its exit delay: still revocable
    market.backend.advance_to(unlock)
    refused(lambda: market.withdraw_bond(leaving.address), "InfoMarketNotExiting", robot=leaving.address)
    assert market.balance_of(robot.address) == market.balance_of(leaving.address) == 10**9
    assert market.total_supply() == supply - 2 * 10**9  # both bonds burned


def test_a_deposit_needs_the_robots_signed_trip_and_a_nests_acknowledgement(fresh):
    market, (buyer, seller, stranger, _) = fresh()
    for robot in (buyer, seller):
        market.grant_wealth(robot, 10**9)
    sell(market, seller, buyer, 10.0)
    trip = market.round_trip(buyer.address)
    good = market.deposit_evidence(buyer, market.nest, trip)
    forged = (*market.deposit_evidence(stranger, market.nest, trip)[:3], *good[3:])  # the robot's part by another
    refused(lambda: market.buy_item(buyer.address, evidence=forged), "InfoMarketInvalidDepositSignature",
            robot=buyer.address, recovered=_signer(market, buyer.address, trip, forged[:3]))
    unacknowledged = market.deposit_evidence(buyer, stranger, trip)  # acknowledged by no nest
    refused(lambda: market.buy_item(buyer.address, evidence=unacknowledged), "InfoMarketUnacknowledgedDeposit",
            robot=buyer.address, signer=stranger.address)
    stale = market.deposit_evidence(buyer, market.nest, trip + 1)  # signed for another round trip
    with pytest.raises(ContractRevert) as info:
        market.buy_item(buyer.address, evidence=stale)
    assert info.value.name == "InfoMarketInvalidDepositSignature"
    high_s = (SECP256K1_N - int.from_bytes(good[5], "big")).to_bytes(32, "big")
    refused(lambda: market.buy_item(buyer.address, evidence=(*good[:3], 55 - good[3], good[4], high_s)),
            "InfoMarketMalleableSignature", s=high_s)
    assert market.balance_of(buyer.address) == 10**9
    market.buy_item(buyer.address, evidence=good)
    assert market.balance_of(buyer.address) == 10**9 + 500_000_000
    refused(lambda: market.buy_item(buyer.address, evidence=good), "InfoMarketInvalidDepositSignature",
            robot=buyer.address, recovered=_signer(market, buyer.address, trip + 1, good[:3]))  # no replay


def _signer(market, robot: str, trip: int, vrs: tuple) -> str:
    digest = market.view("depositDigest", robot, trip)
    v, r, s = vrs
    return Account._recover_hash(digest, vrs=(v, int.from_bytes(r, "big"), int.from_bytes(s, "big")))


def test_the_admin_rotates_keys_and_a_role_may_be_shared(fresh):
    market, (buyer, seller, new_key, _) = fresh()
    for robot in (buyer, seller):
        market.grant_wealth(robot, 10**9)
    old = market.market
    refused(lambda: market.grant_role("depositor", new_key.address, sender=new_key), "InfoMarketUnauthorized",
            caller=new_key.address, role=ROLES["admin"])
    market.grant_role("depositor", new_key.address)
    assert market.has_role("depositor", new_key.address) and market.has_role("depositor", old.address)
    market.revoke_role("depositor", old.address)
    sell(market, seller, buyer, 10.0)
    refused(lambda: market.buy_item(buyer.address), "InfoMarketUnauthorized", caller=old.address,
            role=ROLES["depositor"])
    market.buy_item(buyer.address, sender=new_key)
    retired = market.registrars[0]
    market.revoke_role("registrar", retired.address)
    refused(lambda: market.approve(retired, new_key.address, 0), "InfoMarketUnauthorized",
            caller=retired.address, role=ROLES["registrar"])
    market.transact(market.nest, "renounceRole", ROLES["nest"])
    assert not market.has_role("nest", market.nest.address)


def test_a_pause_stops_registrations_reveals_and_deposits_but_never_refunds_or_settlements(fresh):
    market, (buyer, seller, late, _) = fresh(stake=0.04, settle_batch=1, stake_expiry=3)
    for robot in (buyer, seller):
        market.grant_wealth(robot, 10**9)
    sell(market, seller, buyer, 10.0, age=1)
    sell(market, seller, buyer, 12.0, age=2)
    market.buy_item(buyer.address)  # pending
    sell(market, seller, buyer, 14.0, age=3)  # the next round trip
    refused(lambda: market.set_paused(True, sender=seller), "InfoMarketUnauthorized", caller=seller.address,
            role=ROLES["pauser"])
    assert market.set_paused(True).of("PauseSet") and market.view("paused")
    assert market.set_paused(True).of("PauseSet") == []  # nothing changed: no event
    refused(lambda: sell(market, seller, buyer, 10.0, age=4), "InfoMarketPaused")
    refused(lambda: market.grant_wealth(late, 0), "InfoMarketPaused")
    settle_all(market, buyer.address, 1)  # settling goes on
    refused(lambda: market.buy_item(buyer.address), "InfoMarketPaused")
    market.backend.advance_to(market.backend.block_number + 3)
    (closed,) = market.expire(buyer.address)[0].of("RoundTripExpired")  # so does an expiry
    assert closed["transactions"] == 1
    market.set_paused(False)
    sell(market, seller, buyer, 10.0, age=4)


def test_a_signature_that_recovers_to_no_one_is_no_robots(fresh):
    """ecrecover gives the zero address for a bad signature: even a registered zero address gets no deposit."""
    market, _ = fresh()
    zero = "0x" + "00" * 20
    market.grant_wealth(zero, 0)
    good = market.deposit_evidence(market.nest, market.nest, market.round_trip(zero))
    bad = (27, bytes(32), (1).to_bytes(32, "big"), *good[3:])  # r = 0: recovers to no one
    refused(lambda: market.buy_item(zero, evidence=bad), "InfoMarketInvalidDepositSignature", robot=zero,
            recovered=zero)
