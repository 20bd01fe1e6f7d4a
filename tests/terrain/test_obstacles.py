"""Obstacles: distances, proximity sensing, reflection and 'never inside' for each shape, by hand.

Robots have radius 8 and speed 2.5 and no odometry noise.  A sensor fires when the probed centre (the
robot's position moved by 2.5 towards heading, -90, 180, +90 degrees) is at most 8 from an obstacle; a
move whose end point is closer than 8 is not made."""
import math

import numpy as np
import pytest

from infomarket.space.obstacles import CIRCLE, RECT, SEGMENT, cuts, distance
from infomarket.engine.world import EXPLORING, FOOD, SEEKING_FOOD, headings

from .conftest import place, seek_food, simulation, terrain_config

RECT_G = (0.0, 0.0, 10.0, 10.0)
CIRCLE_G = (0.0, 0.0, 5.0, 0.0)
SEGMENT_G = (0.0, 0.0, 10.0, 0.0)


@pytest.mark.parametrize("kind, g, x, y, want", [
    (RECT, RECT_G, 13.0, 14.0, 5.0),      # beyond a corner: hypot(3, 4)
    (RECT, RECT_G, 5.0, -2.0, 2.0),       # below an edge
    (RECT, RECT_G, 5.0, 5.0, 0.0),        # inside
    (CIRCLE, CIRCLE_G, 6.0, 8.0, 5.0),    # 10 from the centre, radius 5
    (CIRCLE, CIRCLE_G, 1.0, 1.0, 0.0),    # inside
    (SEGMENT, SEGMENT_G, 5.0, 3.0, 3.0),  # beside the middle
    (SEGMENT, SEGMENT_G, 13.0, 4.0, 5.0), # beyond the end (10, 0)
    (SEGMENT, SEGMENT_G, -3.0, -4.0, 5.0),
])
def test_distance_to_each_shape(kind, g, x, y, want):
    assert distance.py_func(kind, *g, x, y) == pytest.approx(want, abs=1e-12)


@pytest.mark.parametrize("kind, g, a, b, want", [
    (CIRCLE, (5.0, 0.0, 1.0, 0.0), (0.0, 0.0), (10.0, 0.0), True),
    (CIRCLE, (5.0, 0.0, 1.0, 0.0), (0.0, 2.0), (10.0, 2.0), False),
    (CIRCLE, (5.0, 0.0, 1.0, 0.0), (0.0, 1.0), (10.0, 1.0), True),    # tangent: touching cuts
    (CIRCLE, (5.0, 0.0, 1.0, 0.0), (0.0, 0.0), (3.0, 0.0), False),    # stops short
    (RECT, (4.0, -1.0, 6.0, 1.0), (0.0, 0.0), (10.0, 0.0), True),
    (RECT, (4.0, -1.0, 6.0, 1.0), (0.0, 2.0), (10.0, 2.0), False),
    (RECT, (4.0, -1.0, 6.0, 1.0), (0.0, 0.0), (3.0, 0.0), False),
    (RECT, (4.0, -1.0, 6.0, 1.0), (0.0, -3.0), (10.0, 3.0), True),    # crosses y = 0 at x = 5
    (RECT, (4.0, -1.0, 6.0, 1.0), (0.0, 3.0), (3.0, 0.0), False),     # x + y = 3 passes the corner by
    (RECT, (4.0, -1.0, 6.0, 1.0), (5.0, 5.0), (5.0, 1.0), True),      # ends on the edge
    (SEGMENT, (5.0, -1.0, 5.0, 1.0), (0.0, 0.0), (10.0, 0.0), True),
    (SEGMENT, (5.0, -1.0, 5.0, 1.0), (0.0, 2.0), (10.0, 2.0), False),
    (SEGMENT, (11.0, 0.0, 12.0, 0.0), (0.0, 0.0), (10.0, 0.0), False),  # collinear, apart
    (SEGMENT, (10.0, 0.0, 12.0, 0.0), (0.0, 0.0), (10.0, 0.0), True),   # collinear, sharing an end
])
def test_line_of_sight_cut_by_each_shape(kind, g, a, b, want):
    assert cuts.py_func(kind, *g, *a, *b) is want
    assert cuts.py_func(kind, *g, *b, *a) is want


# A robot at (x, 300) heading +x: its FRONT probe is at (x + 2.5, 300).  Each obstacle's nearest point
# to that probe lies on the line x = 100 (rect and segment) or 10 from the centre (110, 300) of a
# circle of radius 10; at x = 90 the probe is 7.5 away (fires), at x = 89 it is 8.5 away (does not).
FRONT_OBSTACLES = {
    "rect": {"shape": "rect", "x0": 100.0, "y0": 250.0, "x1": 140.0, "y1": 350.0},
    "circle": {"shape": "circle", "x": 110.0, "y": 300.0, "radius": 10.0},
    "segment": {"shape": "segment", "x0": 100.0, "y0": 250.0, "x1": 100.0, "y1": 350.0},
}


@pytest.mark.parametrize("shape", FRONT_OBSTACLES)
def test_front_sensor_invalidates_the_sought_site_and_reflects(shape):
    sim = simulation(terrain_config(obstacles=[FRONT_OBSTACLES[shape]]))
    place(sim, 0, 90.0, 300.0, 0.0)
    seek_food(sim, 0, 1000.0, 0.0)
    sim.world.levy[0] = 5  # no random-walk turn this step: the exploring move is (2.5, 0)
    sim.step(1)
    w = sim.world
    assert w.state[0] == EXPLORING and not w.tab_valid[0, FOOD]   # bumped while seeking
    assert tuple(w.pos[0]) == (87.5, 300.0)                       # reflected: moved 2.5 backwards
    assert headings(w)[0] == pytest.approx(180.0)


@pytest.mark.parametrize("shape", FRONT_OBSTACLES)
def test_front_sensor_quiet_half_a_unit_further(shape):
    sim = simulation(terrain_config(obstacles=[FRONT_OBSTACLES[shape]]))
    place(sim, 0, 89.0, 300.0, 0.0)
    seek_food(sim, 0, 1000.0, 0.0)
    sim.step(1)
    w = sim.world
    assert w.state[0] == SEEKING_FOOD and w.tab_valid[0, FOOD]
    assert tuple(w.pos[0]) == (91.5, 300.0)


def test_right_sensor_reflects_the_sideways_component():
    # heading +x at (300, 290); a wall along y = 280: the RIGHT probe (300, 287.5) is 7.5 from it, the
    # others 10 or more.  The intended move (1000, -1000) scaled to 2.5 has dy < 0: reflected to dy > 0.
    sim = simulation(terrain_config(obstacles=[{"shape": "segment", "x0": 250.0, "y0": 280.0,
                                                "x1": 350.0, "y1": 280.0}]))
    place(sim, 0, 300.0, 290.0, 0.0)
    seek_food(sim, 0, 1000.0, -1000.0)
    sim.step(1)
    w = sim.world
    d = 2.5 / math.sqrt(2.0)
    assert w.state[0] == SEEKING_FOOD
    assert w.pos[0] == pytest.approx([300.0 + d, 290.0 + d], abs=1e-12)
    assert headings(w)[0] == pytest.approx(45.0)


# Robot at (100, 100) heading +x, seeking (1000, 1000): it moves diagonally by 2.5 to
# (101.768, 101.768).  Each obstacle below is more than 8 from every probe (so no sensor fires) but
# closer than 8 to that end point, so the move is not made.
DIAGONAL = {
    # circle centre (112, 112) radius 7: probes hypot(9.5, 12) - 7 = 8.305; end point 14.471 - 7 = 7.471
    "circle": {"shape": "circle", "x": 112.0, "y": 112.0, "radius": 7.0},
    # corner (107.4, 107.4): probes hypot(4.9, 7.4) = 8.876; end point sqrt(2) * 5.632 = 7.965
    "rect": {"shape": "rect", "x0": 107.4, "y0": 107.4, "x1": 130.0, "y1": 130.0},
    "segment": {"shape": "segment", "x0": 107.4, "y0": 107.4, "x1": 130.0, "y1": 107.4},
}


@pytest.mark.parametrize("shape", DIAGONAL)
def test_a_move_into_an_obstacle_is_not_made(shape):
    sim = simulation(terrain_config(obstacles=[DIAGONAL[shape]]))
    place(sim, 0, 100.0, 100.0, 0.0)
    seek_food(sim, 0, 1000.0, 1000.0)
    sim.step(1)
    w = sim.world
    assert w.state[0] == SEEKING_FOOD                      # no sensor fired
    assert tuple(w.pos[0]) == (100.0, 100.0)               # stayed
    assert headings(w)[0] == pytest.approx(45.0)           # but turned to where it tried to go
    # its odometry counts the whole intended move: (1000, 1000) - (d, d), turned by -45 degrees
    assert w.tab_vec[0, FOOD] == pytest.approx([1000.0 * math.sqrt(2.0) - 2.5, 0.0], abs=1e-9)


def test_without_the_obstacle_the_same_move_is_made():
    sim = simulation(terrain_config(obstacles=[{"shape": "circle", "x": 500.0, "y": 500.0, "radius": 7.0}]))
    place(sim, 0, 100.0, 100.0, 0.0)
    seek_food(sim, 0, 1000.0, 1000.0)
    sim.step(1)
    d = 2.5 / math.sqrt(2.0)
    assert sim.world.pos[0] == pytest.approx([100.0 + d, 100.0 + d], abs=1e-12)


def test_positions_never_enter_an_obstacle_in_a_long_noisy_run():
    from infomarket.config import validate
    from infomarket.engine import Simulation
    from infomarket.space.obstacles import nearest

    obstacles = [{"shape": "rect", "x0": 300.0, "y0": 100.0, "x1": 420.0, "y1": 500.0},
                 {"shape": "circle", "x": 700.0, "y": 300.0, "radius": 60.0},
                 {"shape": "segment", "x0": 850.0, "y0": 0.0, "x1": 850.0, "y1": 250.0},
                 {"shape": "segment", "x0": 850.0, "y0": 350.0, "x1": 850.0, "y1": 600.0}]
    cfg = validate({"steps": 3000, "swarm": {"robots": 25, "groups": [{"behaviour": "naive", "count": 25}]},
                    "obstacles": obstacles})
    sim = Simulation(cfg, seed=7)
    w = sim.world
    closest = np.inf
    for _ in range(30):
        sim.step(100)
        d = [nearest(w.obs_kind, w.obs_geom, x, y) for x, y in sim.world.pos]
        closest = min(closest, min(d))
    assert closest >= 8.0
    assert sim.world.items.sum() > 0  # they still forage round the obstacles
