"""A revocation is reversible by more registrars than made it, within an appeal window.

The exploit (third audit, M3): two compromised registrar keys of three revoke honest robots, one
approval each per robot, and each revocation burns the robot's 1-token bond for good: 8 honest robots
revoked in 16 transactions, nothing to undo it. Now a revoked robot may be reinstated within `bondDelay`
blocks of its revocation by `registrarThreshold` + 1 distinct registrars (3 of 3 by default), its bond
minted back. The two keys that revoked cannot block it for ever: approvals stand only while their key
holds the role, so once the admin has replaced them, the new keys and the honest one reinstate.
Reinstatement approvals count against the registrars' sliding quota, as revocations do.
"""
from __future__ import annotations

from infomarket.evm.market import ROLES, derived_account

from .helpers import refused, sell

BOND = 10**9


def test_a_revocation_by_two_compromised_registrars_is_reversed_by_three(fresh):
    market, (honest, buyer, _, _) = fresh(bond_delay=200, stake=0.04)
    for robot in (honest, buyer):
        market.grant_wealth(robot, 10**9)
    supply = market.total_supply()
    bad0, bad1, good = market.registrars
    market.revoke(honest.address, [bad0, bad1])  # the compromised keys revoke an honest robot
    assert not market.view("isRegistered", honest.address) and market.total_supply() == supply - BOND
    # two registrars, even honest ones, do not reverse what two made
    assert market.transact(good, "reinstate", honest.address).of("ReinstatementApproved")[0]["approvals"] == 1
    assert not market.transact(bad0, "reinstate", honest.address).of("RegistrationReinstated")
    # the admin replaces the compromised keys: their approvals (of revoking and reinstating) stop standing
    fresh_keys = [derived_account("new-registrar", i) for i in range(2)]
    market.backend.fund([k.address for k in fresh_keys])
    for old, new in zip((bad0, bad1), fresh_keys):
        market.grant_role("registrar", new.address)
        market.revoke_role("registrar", old.address)
    assert market.transact(fresh_keys[0], "reinstate", honest.address).of("RegistrationReinstated") == []
    done = market.transact(fresh_keys[1], "reinstate", honest.address)  # the third standing approval
    assert done.of("RegistrationReinstated") == [{"robot": honest.address, "bond": BOND}]
    assert market.view("isRegistered", honest.address) and market.bond_of(honest.address) == BOND
    assert market.total_supply() == supply
    sell(market, honest, buyer, 10.0)  # it trades again
    # the revocation's approvals do not count again: one new approval revokes no one
    assert not market.revoke(honest.address, [good]).of("BondForfeited")
    refused(lambda: market.transact(good, "reinstate", honest.address), "InfoMarketNotRevoked",
            robot=honest.address, until=0)


def test_a_revocation_stands_after_its_appeal_window_and_only_registrars_reinstate(fresh):
    market, (robot, leaving, stranger, again) = fresh(bond_delay=50)
    for account in (robot, leaving, again):
        market.grant_wealth(account, 10**9)
    first, second, third = market.registrars
    # revoked and reinstated by the same keys: their earlier revocation approvals count no more
    market.revoke(again.address, [first, second])
    for registrar in (first, second, third):
        market.transact(registrar, "reinstate", again.address)
    assert not market.revoke(again.address, [third]).of("BondForfeited")
    revoked_at = market.revoke(robot.address, [first, second]).block_number
    refused(lambda: market.transact(stranger, "reinstate", robot.address), "InfoMarketUnauthorized",
            caller=stranger.address, role=ROLES["registrar"])
    market.backend.advance_to(revoked_at + 50)  # the window ends
    refused(lambda: market.transact(third, "reinstate", robot.address), "InfoMarketNotRevoked",
            robot=robot.address, until=revoked_at + 50)
    # a robot revoked during its exit comes back exiting, its bond withdrawable a delay later
    market.exit(leaving)
    market.revoke(leaving.address, [first, second])
    for registrar in (first, second, third):
        done = market.transact(registrar, "reinstate", leaving.address)
    assert not market.view("isRegistered", leaving.address) and market.bond_of(leaving.address) == BOND
    refused(lambda: market.withdraw_bond(leaving.address), "InfoMarketBondLocked", robot=leaving.address,
            unlockBlock=done.block_number + 50)
    market.backend.advance_to(done.block_number + 50)
    market.withdraw_bond(leaving.address)
    assert market.balance_of(leaving.address) == 10**9 + BOND
