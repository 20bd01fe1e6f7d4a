"""Registrars' approvals: bound to the key that gave them and to a time window, cancellable; the
quota over a sliding window; revocation within the same quota; a revoked buyer's sellers refunded at once.

The exploits (the third audit): the admin moved registrar R0's role to a new key R0', which approved
again the robot R0 had approved: registered by one person's consent counted twice. A compromised
registrar's approvals kept counting after its role was revoked. No approval could be cancelled. The
quota reset at each period's boundary, so two registrars could register twice their quota in two
blocks. Revocation had no quota, and a revoked buyer's sellers waited for expiry to get their stakes
back. By hand, at a quota of 2 per 100 blocks and a threshold of 2 of 3.
"""
from __future__ import annotations

from .helpers import refused, sell

GRANT = 2 * 10**9


def test_an_approval_by_a_key_whose_role_moved_does_not_count(fresh):
    market, (robot, new_key, other, _) = fresh()
    r0, r1, _ = market.registrars
    market.approve(r0, robot.address, GRANT)
    market.grant_role("registrar", new_key.address)  # the admin moves R0's role to a new key
    market.revoke_role("registrar", r0.address)
    market.approve(new_key, robot.address, GRANT)  # one person's second approval
    assert not market.view("isRegistered", robot.address)
    assert market.view("approvals", robot.address, GRANT) == 1
    market.approve(r1, robot.address, GRANT)  # a second person's: registered
    assert market.view("isRegistered", robot.address)
    # a revoked registrar's approvals stop counting, and come back with no new grant of the role
    market.approve(r1, other.address, GRANT)
    market.revoke_role("registrar", r1.address)
    assert market.view("approvals", other.address, GRANT) == 0
    market.grant_role("registrar", r1.address)
    assert market.view("approvals", other.address, GRANT) == 0


def test_an_approval_lapses_after_its_window_and_can_be_cancelled(fresh):
    market, (robot, other, _, _) = fresh(registrar_period=100)
    r0, r1, _ = market.registrars
    market.approve(r0, robot.address, GRANT)
    market.backend.advance_to(market.backend.block_number + 100)  # R0's approval lapsed
    market.approve(r1, robot.address, GRANT)
    assert not market.view("isRegistered", robot.address)
    market.approve(r0, other.address, GRANT)
    done = market.cancel_approval(r0, other.address, GRANT)
    assert done.of("ApprovalCancelled")[0]["registrar"] == r0.address
    market.approve(r1, other.address, GRANT)
    assert not market.view("isRegistered", other.address)
    refused(lambda: market.cancel_approval(r0, other.address, GRANT), "InfoMarketNotApproved",
            registrar=r0.address, robot=other.address)  # nothing standing to cancel


def test_the_quota_holds_in_every_window_not_only_in_each_period(fresh):
    """Two approvals at the last block of a period and a third at the first of the next: three within two
    blocks used to pass, over the quota of 2 per 100 blocks."""
    market, robots = fresh(accounts=4, registrar_quota=2, registrar_period=100)
    registrar, backend = market.registrars[0], market.backend
    last = (backend.block_number // 100 + 2) * 100 - 1  # the last block of a period
    backend.advance_to(last - 1)
    market.approve(registrar, robots[0].address, GRANT)
    market.approve(registrar, robots[1].address, GRANT)  # both within blocks last - 1 .. last
    for block in (last + 1, last + 50):
        backend.advance_to(block)  # a new period began, but the window still holds two approvals
        refused(lambda: market.approve(registrar, robots[2].address, GRANT), "InfoMarketRegistrarQuotaExceeded",
                registrar=registrar.address, limit=2)
    backend.advance_to(last + 150)
    market.approve(registrar, robots[2].address, GRANT)


def test_revocations_count_against_the_quota_and_a_revoked_buyers_sellers_are_paid_at_once(fresh):
    market, robots = fresh(accounts=4, registrar_quota=2, registrar_period=100, stake=0.04)
    buyer, seller, *others = robots
    for pair in (robots[:2], robots[2:]):  # two registrations per registrar and window
        for robot in pair:
            market.grant_wealth(robot, 10**9)
        market.backend.advance_to(market.backend.block_number + 100)
    r0, r1, _ = market.registrars
    sell(market, seller, buyer, 10.0)
    assert market.locked_stake(buyer.address) == 40_000_000
    market.transact(r0, "revokeRegistration", buyer.address)
    market.transact(r0, "revokeRegistration", others[0].address)
    refused(lambda: market.transact(r0, "revokeRegistration", others[1].address),
            "InfoMarketRegistrarQuotaExceeded", registrar=r0.address, limit=2)
    market.transact(r1, "revokeRegistration", buyer.address)  # revoked
    assert not market.view("isRegistered", buyer.address)
    market.expire(buyer.address)  # at once, not after the stake expiry: settled as a deposit would be
    assert market.locked_stake(buyer.address) == 0
    # the seller's record, alone, gets the share (paid from the revoked buyer's balance) and its stake
    assert market.balance_of(seller.address) == 10**9 + 500_000_000
    assert market.balance_of(buyer.address) == 500_000_000
