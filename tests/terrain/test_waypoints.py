"""Following a waypoint path in the terrain-aware step, by hand (no odometry noise): legs in order,
waypoints dead-reckoned with the entry, a bump marks the site blocked, a site clears it."""
import math

import numpy as np
import pytest

from infomarket.config import validate
from infomarket.engine.world import EXPLORING, FOOD, NEST

from ..shared_kernel import simulation as shared_simulation
from .conftest import FAR_SITES, place, seek_food


def simulation(cfg):
    # on the kernel the rule check of waypoint compiles (naive and waypoint, paths): nothing new to compile
    return shared_simulation(cfg, 3)


def waypoint_config(robots, obstacles=()):
    return validate({"steps": 100, "swarm": {"robots": robots, "groups": [{"behaviour": "waypoint", "count": robots}]},
                     "robot": {"noise_sd": 0.0, "bias_mean": 0.0, "bias_sd": 0.0},
                     "obstacles": list(obstacles), **FAR_SITES})


def test_a_robot_follows_the_legs_in_order():
    sim = simulation(waypoint_config(1))
    w = sim.world
    place(sim, 0, 300.0, 300.0, 0.0)
    seek_food(sim, 0, 20.0, 0.0)  # first waypoint 20 ahead: world (320, 300)
    w.path_vec[0, FOOD, 0] = (20.0, 30.0)  # then world (320, 330), in the robot's frame
    w.path_count[0, FOOD] = 1
    sim.step(5)  # 5 moves of 2.5 straight ahead
    assert tuple(w.pos[0]) == pytest.approx((312.5, 300.0))
    assert w.path_count[0, FOOD] == 1
    assert tuple(w.tab_vec[0, FOOD]) == pytest.approx((7.5, 0.0))
    assert tuple(w.path_vec[0, FOOD, 0]) == pytest.approx((7.5, 30.0))  # moved with the robot
    # step 6: the first waypoint is 7.5 < radius 8 away: the robot takes the next and heads for it
    sim.step(1)
    leg = math.hypot(7.5, 30.0)
    assert w.path_count[0, FOOD] == 0 and w.tab_valid[0, FOOD]
    assert tuple(w.pos[0]) == pytest.approx((312.5 + 2.5 * 7.5 / leg, 300.0 + 2.5 * 30.0 / leg))
    # the robot now faces the waypoint (320, 330): it lies straight ahead, 2.5 closer
    assert tuple(w.tab_vec[0, FOOD]) == pytest.approx((leg - 2.5, 0.0))


def test_a_bump_while_seeking_marks_the_site_blocked_and_being_there_clears_it():
    wall = {"shape": "segment", "x0": 310.0, "y0": 200.0, "x1": 310.0, "y1": 400.0}
    sim = simulation(waypoint_config(2, [wall]))
    w = sim.world
    place(sim, 0, 300.0, 300.0, 0.0)  # FRONT probes (302.5, 300): 7.5 from the wall, within radius 8
    seek_food(sim, 0, 100.0, 0.0)
    w.path_vec[0, FOOD, 0] = (100.0, 50.0)
    w.path_count[0, FOOD] = 1
    place(sim, 1, 600.0, 80.0, 0.0)  # inside the food site (600, 60), radius 50
    w.blocked[1, FOOD] = True
    w.tab_valid[1, FOOD] = True
    w.path_count[1, FOOD] = 2
    sim.step(1)
    assert w.state[0] == EXPLORING and not w.tab_valid[0, FOOD]
    assert w.blocked[0, FOOD] and not w.blocked[0, NEST]
    assert w.path_count[0, FOOD] == 0
    assert not w.blocked[1, FOOD] and w.path_count[1, FOOD] == 0


def test_waypoints_turn_with_the_robot():
    """Dead reckoning of a waypoint is the entry's: the robot moves (0, 2.5) in its frame (towards an
    entry straight to its left) and its frame turns by +90 degrees."""
    sim = simulation(waypoint_config(1))
    w = sim.world
    place(sim, 0, 300.0, 300.0, 0.0)
    seek_food(sim, 0, 0.0, 40.0)  # entry 40 to the left: the robot moves (0, 2.5) and turns +90
    w.path_vec[0, FOOD, 0] = (10.0, 40.0)
    w.path_count[0, FOOD] = 1
    sim.step(1)
    # new frame: x along +y world.  The waypoint (10, 40) minus the move (0, 2.5) is (10, 37.5) in the
    # old frame; turned by -90: (37.5, -10)
    np.testing.assert_allclose(w.path_vec[0, FOOD, 0], (37.5, -10.0), atol=1e-9)
    np.testing.assert_allclose(w.tab_vec[0, FOOD], (37.5, 0.0), atol=1e-9)


def _world_points(w, i, site):
    """Robot i's path for ``site`` as world positions (its frame: x along its heading)."""
    c, s = w.hdir[i]
    pts = [w.tab_vec[i, site]] + list(w.path_vec[i, site, :w.path_count[i, site]])
    return [(w.pos[i, 0] + c * x - s * y, w.pos[i, 1] + s * x + c * y) for x, y in pts]


def test_a_blocked_robot_buys_and_installs_its_neighbours_path():
    sim = simulation(waypoint_config(2))
    w = sim.world
    place(sim, 0, 300.0, 300.0, 0.0)
    w.blocked[0, FOOD] = True
    w.tab_age[0, FOOD] = 100  # invalid and old: anything younger is bought
    place(sim, 1, 320.0, 300.0, 90.0)  # faces +y: its frame's (x, y) is (-y, x) in the world
    seek_food(sim, 1, 0.0, -50.0)  # first waypoint world (370, 300)
    w.tab_age[1, FOOD] = 1
    w.path_vec[1, FOOD, 0] = (60.0, -50.0)  # then world (320 + 50, 300 + 60) = (370, 360)
    w.path_count[1, FOOD] = 1
    sim.step(1)
    assert w.tab_valid[0, FOOD] and w.path_count[0, FOOD] == 2 and w.tab_age[0, FOOD] in (1, 2)
    # bought in the buyer's frame, installed, then dead-reckoned: the same world points
    np.testing.assert_allclose(_world_points(w, 0, FOOD), [(320.0, 300.0), (370.0, 300.0), (370.0, 360.0)],
                               atol=1e-9)


def test_only_a_robot_that_bumped_turns_a_plain_vector_into_a_path():
    sim = simulation(waypoint_config(4))
    w = sim.world
    for buyer, seller, y in ((0, 1, 300.0), (2, 3, 450.0)):  # two pairs, 150 apart: no trade across
        place(sim, buyer, 300.0, y, 0.0)
        w.tab_age[buyer, FOOD] = 100
        place(sim, seller, 320.0, y, 0.0)
        seek_food(sim, seller, 50.0, 0.0)  # a plain vector: food at (370, y)
        w.tab_age[seller, FOOD] = 1
    w.blocked[0, FOOD] = True
    sim.step(1)
    # the robot that bumped goes via the seller's position; the other averages the vector in (naive)
    assert w.path_count[0, FOOD] == 1
    np.testing.assert_allclose(_world_points(w, 0, FOOD), [(320.0, 300.0), (370.0, 300.0)], atol=1e-9)
    assert w.path_count[2, FOOD] == 0
    np.testing.assert_allclose(_world_points(w, 2, FOOD), [(370.0, 450.0)], atol=1e-9)
