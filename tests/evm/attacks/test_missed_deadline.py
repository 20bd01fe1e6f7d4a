"""A settlement left unfinished pays the sellers, not the buyer, and settling is worth doing.

The exploit: if nobody paid for the `settle` calls within `settlementDeadline` blocks, the contract
refunded the stakes and handed the whole share back to the buyer: the buyer gained by doing nothing
and the sellers lost their payment, while the settlement's gas fell on whoever called `settle`.
Now the records are weighed however late the settlement is finished (paying them equal parts past the
deadline, as the contract did next, paid a liar's many records like honest ones:
test_late_liar.py), a registered robot that settles earns `settleBounty` per unit of work, from the
share, and past the deadline any caller does. By hand (staking 0.04, share 0.5, 3 honest sellers at
10, 15, 20 degrees and an outlier at 100): the amount is 0.5 + 4 * 0.04 = 0.66 token; the bounty is
500_000_000 // 50_000 = 10_000 units per unit of work.
"""
from __future__ import annotations

from .helpers import sell, settle_all

AMOUNT = 500_000_000 + 4 * 40_000_000
BOUNTY = 10_000


def _pending(make_market, robots, batch=1):
    market = make_market("outlier_distinct", stake=0.04, settle_batch=batch, settlement_deadline=5)
    buyer = robots[0]
    for age, (seller, direction) in enumerate(zip(robots[1:5], (10.0, 15.0, 20.0, 100.0))):
        sell(market, seller, buyer, direction, age=age)
    market.buy_item(buyer.address)  # the depositor does one unit of work and leaves the rest
    return market, buyer


def test_past_the_deadline_the_buyer_keeps_only_its_reward_and_the_sellers_are_weighed(make_market, robots):
    market, buyer = _pending(make_market, robots)
    market.backend.advance_to(market.backend.block_number + 5)  # nobody settled in time
    settle_all(market, buyer.address, 1)  # the market's node, unregistered, now earns the bounty
    assert market.balance_of(buyer.address) == 1_000_000_000 + 500_000_000  # the reward less the share
    # 3 records left to weigh (30 000 from the escrow), then 4 payments (10 000 cut from each): the
    # honest records weigh 3 voices of 10, the outlier 1
    amount = AMOUNT - 3 * BOUNTY
    for seller in robots[1:4]:
        assert market.balance_of(seller.address) == 1_000_000_000 - 40_000_000 + amount * 3 // 10 - BOUNTY
    assert market.balance_of(robots[4].address) == 1_000_000_000 - 40_000_000 + amount // 10 - BOUNTY


def test_a_robot_that_settles_earns_the_bounty_from_the_share(make_market, robots):
    market, buyer = _pending(make_market, robots)
    settler = robots[6]
    results = settle_all(market, buyer.address, 1, sender=settler)
    paid = sum(e["amount"] for r in results for e in r.of("SettlementBountyPaid"))
    units = len(results)  # one unit of work per call: three weighings left, then four payments
    assert units == 3 + 4 and paid == BOUNTY * units
    assert market.balance_of(settler.address) == 1_000_000_000 + paid
    (done,) = results[-1].of("SettlementCompleted")
    gains = sum(market.balance_of(s.address) - 960_000_000 for s in robots[1:5])
    assert gains + paid + done["kept"] == AMOUNT  # the bounty came out of what the sellers share
    supply = sum(market.balance_of(r.address) + market.bond_of(r.address) for r in robots)
    supply += market.locked_stake(buyer.address)
    assert supply == market.total_supply()


def test_the_depositor_earns_no_bounty_so_the_simulated_ledgers_payments_stand(make_market, robots):
    market, buyer = _pending(make_market, robots, batch=48)  # buyItem settles everything
    assert not market.pending_settlement(buyer.address)[0]
    shares = {market.balance_of(s.address) - 960_000_000 for s in robots[1:4]}
    # outlier_distinct: the honest records weigh 3 voices each, the outlier 1: 3 / 10 and 1 / 10 of 0.66
    assert shares == {AMOUNT * 3 // 10}
    assert market.balance_of(robots[4].address) - 960_000_000 == AMOUNT // 10
