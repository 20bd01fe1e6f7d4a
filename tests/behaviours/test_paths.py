"""Waypoint paths, by hand: a bought polyline in the buyer's frame, the first leg's direction in the
transaction, and which corners survive shortening."""
import math

import numpy as np
import pytest

from infomarket.behaviours import paths
from infomarket.engine import specialise
from infomarket.engine.world import FOOD, NEST, PATH_POINTS, open_transactions

from ..conftest import Handle, make_config


def _seller_path(h, seller, site, first, rest, age):
    """The seller offers ``first`` (its first leg) and holds the further waypoints ``rest`` (its frame)."""
    h.offer(seller, site, *first, age=age)
    w = h.world
    for j, p in enumerate(rest):
        w.path_vec[seller, site, j] = p
    w.path_count[seller, site] = len(rest)


def test_bought_path_is_the_sellers_polyline_in_the_buyers_frame():
    h = Handle(make_config(2))
    h.place(0, 100, 100, 90.0)  # buyer faces +y: a world vector (x, y) is (y, -x) in its frame
    h.place(1, 130, 100, 0.0)  # seller faces +x: its frame is the world's
    # seller: first waypoint 40 to its left (world (130, 140)), then 50 further along +x (world (180, 140))
    _seller_path(h, 1, FOOD, (0.0, 40.0), [(50.0, 40.0)], age=7)
    ok, age = paths.buy_path(h.view, 0, 1, FOOD)
    assert ok and age == 7
    w = h.world
    # relative to the buyer: seller (30, 0), waypoints (30, 40) and (80, 40), world -> frame (y, -x)
    assert tuple(w.new_vec[0, FOOD]) == pytest.approx((0.0, -30.0), abs=1e-9)
    assert w.new_path_count[0, FOOD] == 2
    np.testing.assert_allclose(w.new_path_vec[0, FOOD, :2], [[40.0, -30.0], [40.0, -80.0]], atol=1e-9)
    assert w.new_valid[0, FOOD] and w.new_age[0, FOOD] == 7
    # the transaction's direction is the seller's first leg, (0, 40) world = (40, 0) for the buyer: 0
    # degrees -- not the buyer's own first leg towards the seller (270) nor towards the waypoint (323.13)
    _, _, directions = open_transactions(w, 0)
    assert directions[0] == pytest.approx(0.0, abs=1e-9)
    assert w.new_path_count[0, NEST] == 0  # the other site is untouched


def test_a_refused_purchase_installs_nothing():
    h = Handle(make_config(2, robot={"cooldown": 10}))
    h.place(0, 100, 100, 0.0)
    h.place(1, 110, 100, 0.0)
    _seller_path(h, 1, NEST, (5.0, 0.0), [(9.0, 9.0)], age=3)
    h.world.cool_timer[1] = 4  # a seller in cooldown cannot trade
    ok, _ = paths.buy_path(h.view, 0, 1, NEST)
    assert not ok and h.world.new_path_count[0, NEST] == 0 and not h.world.new_valid[0, NEST]


def test_shorten_drops_the_straightest_corner_and_keeps_the_site():
    # from the origin: (10, 0) lies on the way to (20, 0): detour 0; (20, 0) turns to (20, 10):
    # detour 10 + 10 - sqrt(500) = 2.64; so (10, 0) goes first
    pts = np.array([[10.0, 0.0], [20.0, 0.0], [20.0, 10.0]])
    assert paths.shorten(pts, 3, 2) == 2
    assert pts[:2].tolist() == [[20.0, 0.0], [20.0, 10.0]]
    # a detour around a wall: (0, -50) then (100, -50) then the site at (100, 0); corners cost
    # 50 + 100 - sqrt(12500) = 38.2 and 100 + 50 - sqrt(12500) = 38.2 -> equal, the first goes
    pts = np.array([[0.0, -50.0], [100.0, -50.0], [100.0, 0.0]])
    assert paths.shorten(pts, 3, 2) == 2
    assert pts[:2].tolist() == [[100.0, -50.0], [100.0, 0.0]]
    pts = np.array([[3.0, 4.0]])
    assert paths.shorten(pts, 1, 0) == 1  # the site itself never goes


def test_a_long_bought_path_is_shortened_to_path_points():
    h = Handle(make_config(2))
    h.place(0, 100, 100, 0.0)  # both face +x: frames are the world's
    h.place(1, 120, 100, 0.0)
    # seller's waypoints (its frame = world, relative to it): a straight run to (60, 0), a corner at
    # (60, 80), the site at (0, 80); with the seller's position that is 5 points, one too many
    _seller_path(h, 1, FOOD, (20.0, 0.0), [(40.0, 0.0), (60.0, 0.0), (60.0, 80.0), (0.0, 80.0)][:PATH_POINTS - 1],
                 age=2)
    assert PATH_POINTS == 4
    ok, _ = paths.buy_path(h.view, 0, 1, FOOD)
    assert ok
    w = h.world
    pts = [tuple(w.new_vec[0, FOOD])] + [tuple(p) for p in w.new_path_vec[0, FOOD, :w.new_path_count[0, FOOD]]]
    # buyer frame: (20, 0), (40, 0), (60, 0), (80, 0), (80, 80): the three collinear points before the
    # corner cost 0 each; the first of them (the seller's position) is dropped
    np.testing.assert_allclose(pts, [(40.0, 0.0), (60.0, 0.0), (80.0, 0.0), (80.0, 80.0)], atol=1e-9)


def test_only_path_behaviours_get_the_path_step():
    assert not specialise.uses_paths(("naive", "sceptical"))
    assert specialise.uses_paths(("naive", "waypoint"))
    from infomarket.registry import get_behaviour, get_payment
    naive, way, delayed = get_behaviour("naive"), get_behaviour("waypoint"), get_payment("delayed")
    plane = specialise.generate_source([naive], delayed)
    assert "TERRAIN = False " in plane and "PATHS = False " in plane  # the paper's kernel
    terrain = specialise.generate_source([naive], delayed, terrain=True)
    assert "TERRAIN = True " in terrain and "PATHS = False " in terrain  # terrain without paths
    with_paths = specialise.generate_source([naive, way], delayed, paths=True)  # on the plane as well
    assert "TERRAIN = True " in with_paths and "PATHS = True " in with_paths
    for source in (plane, terrain, with_paths):  # one step: no step piece is rebound by a later import
        assert "noqa: F811" not in source and "engine.terrain import" not in source


def test_detour_is_zero_on_the_segment():
    assert paths.detour(0.0, 0.0, 1.0, 1.0, 2.0, 2.0) == pytest.approx(0.0, abs=1e-12)
    assert paths.detour(0.0, 0.0, 0.0, 3.0, 4.0, 3.0) == pytest.approx(3 + 4 - 5)
    assert math.isclose(paths.detour(0.0, 0.0, 5.0, 5.0, 10.0, 0.0), 2 * math.sqrt(50) - 10)
