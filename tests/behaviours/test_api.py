"""The information exchange, by hand: frames, offsets, eqs. (4)-(6), the sceptic's pending list."""
import numpy as np
import pytest

from infomarket.behaviours import api
from infomarket.engine.world import FOOD, NEST, open_transactions

from ..conftest import Handle, make_config


def test_purchase_rotates_into_buyer_frame_and_adds_seller_offset(world2):
    h = world2
    h.place(0, 100, 100, 90.0)  # buyer faces +y
    h.place(1, 130, 100, 0.0)  # seller faces +x, 30 units to the buyer's right in the world
    h.offer(1, FOOD, 10.0, 0.0, age=5)  # the seller believes the food is 10 ahead of it
    ok, x, y, age = api.buy(h.view, 0, 1, FOOD)
    assert ok and age == 5
    # offer (10, 0) world -> buyer frame (0, -10); seller at (30, 0) world -> (0, -30) in buyer frame
    assert (x, y) == pytest.approx((0.0, -40.0), abs=1e-9)
    w = h.world
    sellers, sites, directions = open_transactions(w, 0)
    assert list(sellers) == [1] and list(sites) == [FOOD]
    assert directions[0] == pytest.approx(270.0)  # direction of the rotated vector, before the offset
    assert w.ev_count[0] == 1 and w.ev_kind[0] == 0


def test_eq4_eq5_age_weighted_average():
    x, y, age = api.weighted(10.0, 0.0, 30, 0.0, 10.0, 10)  # own (age 30), bought (age 10)
    assert (x, y) == pytest.approx((2.5, 7.5))  # 30/40 of the bought vector + 10/40 of the own one
    assert age == 20
    x, y, age = api.weighted(1.0, 1.0, 4, 3.0, 3.0, 1)
    assert age == 2  # floor(5 / 2)


def test_combine_replaces_an_invalid_entry(world2):
    h = world2
    w = h.world
    w.new_valid[0, NEST] = False
    w.new_age[0, NEST] = 40
    w.new_vec[0, NEST] = (99.0, 99.0)
    api.combine(h.view, 0, NEST, 5.0, 6.0, 10)
    assert w.new_valid[0, NEST] and tuple(w.new_vec[0, NEST]) == (5.0, 6.0) and w.new_age[0, NEST] == 25
    api.combine(h.view, 0, NEST, 15.0, 6.0, 25)  # equal ages: equal weights
    assert tuple(w.new_vec[0, NEST]) == (10.0, 6.0) and w.new_age[0, NEST] == 25


def test_eq6_difference_score():
    assert api.diff(3.0, 4.0, 3.0, 0.0) == pytest.approx(0.8)
    assert api.diff(0.0, 0.0, 1.0, 1.0) == api.DIFF_OF_ZERO == 1000.0


def test_next_candidate_orders_by_age_then_id():
    h = Handle(make_config(4))
    for s, age in ((1, 7), (2, 3), (3, 3)):
        h.offer(s, FOOD, 1.0, 0.0, age)
    nbrs = np.array([1, 2, 3])
    order = []
    a, s = -1, -1
    while (s := api.next_candidate(h.view, nbrs, FOOD, a, s)) >= 0:
        order.append(s)
        a = h.world.off_age[s, FOOD]
    assert order == [2, 3, 1]


def test_naive_buys_the_freshest_younger_offer_once_per_site():
    h = Handle(make_config(3))
    w = h.world
    for i in range(3):
        h.place(i, 100 + 10 * i, 100, 0.0)
    w.new_age[0, FOOD] = 50
    h.offer(1, FOOD, 20.0, 0.0, 30)
    h.offer(2, FOOD, 20.0, 0.0, 10)
    h.kernel.buy_dispatch(0, h.view, 0, np.array([1, 2]), h.rng)
    assert list(open_transactions(w, 0)[0]) == [2]  # only the freshest, one purchase
    assert w.new_valid[0, FOOD] and w.new_age[0, FOOD] == 30


def test_sceptic_waits_for_confirmation():
    h = Handle(make_config(4, behaviour="sceptical"))
    w = h.world
    for i in range(4):
        h.place(i, 100, 100 + i, 0.0)
    w.pos[1:] = w.pos[0]  # sellers at the buyer's position: no offset, to keep numbers simple
    w.new_valid[0, FOOD] = True
    w.new_vec[0, FOOD] = (100.0, 0.0)
    w.new_age[0, FOOD] = 100
    h.offer(1, FOOD, 0.0, 100.0, 10)  # disagrees with the own entry (diff = 1.41 > 0.25)
    h.kernel.buy_dispatch(0, h.view, 0, np.array([1]), h.rng)
    assert w.tx_count[0] == 1 and w.pend_count[0, FOOD] == 1
    assert tuple(w.new_vec[0, FOOD]) == (100.0, 0.0)  # not used yet
    w.tab_age[0] = w.new_age[0]
    h.offer(2, FOOD, 5.0, 101.0, 20)  # confirms the pending one (diff ~ 0.05)
    h.kernel.buy_dispatch(0, h.view, 0, np.array([1, 2]), h.rng)  # 1 is pending already: not bought again
    assert w.tx_count[0] == 2 and open_transactions(w, 0)[0][1] == 2
    assert w.pend_count[0, FOOD] == 0
    # pending (0, 100) age 10 averaged with bought (5, 101) age 20: 10/30 * bought + 20/30 * pending
    assert w.new_vec[0, FOOD] == pytest.approx([5 / 3, 100 + 1 / 3])
    assert w.new_age[0, FOOD] == 15


def test_sceptic_uses_information_that_agrees_with_its_own():
    h = Handle(make_config(2, behaviour="sceptical"))
    w = h.world
    h.place(0, 100, 100, 0.0)
    h.place(1, 100, 100, 0.0)
    w.new_valid[0, NEST] = True
    w.new_vec[0, NEST] = (100.0, 0.0)
    w.new_age[0, NEST] = 30
    h.offer(1, NEST, 110.0, 0.0, 10)  # diff = 0.1 < 0.25
    h.kernel.buy_dispatch(0, h.view, 0, np.array([1]), h.rng)
    assert w.new_vec[0, NEST] == pytest.approx([107.5, 0.0]) and w.new_age[0, NEST] == 20


def test_saboteur_sells_rotated_and_keeps_the_truth():
    h = Handle(make_config(2, behaviour="saboteur"))
    w = h.world
    w.tab_valid[1, FOOD] = True
    w.tab_vec[1, FOOD] = (10.0, 0.0)
    w.tab_age[1, FOOD] = 4
    valid, x, y, age = h.kernel.sell_dispatch(0, h.view, 1, FOOD, h.rng)
    assert valid and age == 4 and (x, y) == pytest.approx((0.0, 10.0), abs=1e-12)
    assert tuple(w.tab_vec[1, FOOD]) == (10.0, 0.0)
