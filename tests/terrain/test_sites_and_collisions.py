"""Line of sight, collisions and per-site item counts, by hand."""
import pytest

from infomarket.config import validate
from infomarket.engine import Simulation
from infomarket.engine.world import FOOD

from .conftest import place, seek_food, simulation, terrain_config

WALL = {"shape": "segment", "x0": 120.0, "y0": 250.0, "x1": 120.0, "y1": 350.0}
SHORT = {"shape": "segment", "x0": 120.0, "y0": 310.0, "x1": 120.0, "y1": 350.0}


@pytest.mark.parametrize("line_of_sight, wall, expected", [
    (True, WALL, 0),    # the wall cuts the line between (100, 300) and (140, 300)
    (False, WALL, 1),   # without line of sight the wall does not matter
    (True, SHORT, 1),   # a wall that ends below the line does not cut it
])
def test_line_of_sight_drops_neighbours_behind_a_wall(line_of_sight, wall, expected):
    sim = simulation(terrain_config(robots=2, obstacles=[wall], line_of_sight=line_of_sight))
    place(sim, 0, 100.0, 300.0, 0.0)
    place(sim, 1, 140.0, 300.0, 0.0)
    sim._kernel.find_neighbours(sim._view)
    assert sim.world.nbr_count.tolist() == [expected, expected]


def _head_on(b_x: float, collisions: bool):
    """Robot 0 at (100, 300) heading +x and robot 1 at (b_x, 300) heading -x, both seeking straight on."""
    sim = simulation(terrain_config(robots=2, collisions=collisions))
    place(sim, 0, 100.0, 300.0, 0.0)
    place(sim, 1, b_x, 300.0, 180.0)
    sim.world.hdir[1] = (-1.0, 0.0)
    for i in (0, 1):
        seek_food(sim, i, 1000.0, 0.0)
    sim.step(1)
    return sim.world


def test_collision_moves_that_would_overlap_are_not_made():
    # 18 apart: robot 0 moving first would end 15.5 from robot 1 (< 16); then robot 1 would end 15.5
    # from robot 0, which has not moved.  Neither moves.
    w = _head_on(118.0, collisions=True)
    assert w.pos.tolist() == [[100.0, 300.0], [118.0, 300.0]]
    # odometry counts the move each believed it made
    assert w.tab_vec[:, FOOD, 0].tolist() == [997.5, 997.5]


def test_collision_rule_allows_touching_and_goes_in_id_order():
    # 21 apart: robot 0 moves to 102.5 (18.5 from robot 1); robot 1 then moves to 118.5, exactly 16
    # from robot 0: touching is allowed.
    w = _head_on(121.0, collisions=True)
    assert w.pos[:, 0].tolist() == [102.5, 118.5]


def test_without_collisions_robots_pass_through_each_other():
    w = _head_on(118.0, collisions=False)
    assert w.pos[:, 0].tolist() == [102.5, 115.5]


def test_no_two_robots_ever_overlap_with_collisions_on():
    import numpy as np

    cfg = validate({"steps": 2000, "swarm": {"robots": 60, "groups": [{"behaviour": "naive", "count": 60}]},
                    "robot": {"collisions": True}})
    sim = Simulation(cfg, seed=5)
    closest = np.inf
    for _ in range(20):
        sim.step(100)
        p = sim.world.pos
        d = np.sqrt(((p[:, None, :] - p[None, :, :]) ** 2).sum(-1))
        np.fill_diagonal(d, np.inf)
        closest = min(closest, d.min())
    assert closest >= 16.0 - 1e-9


SMALL_SITES = {"food": [{"x": 300.0, "y": 100.0, "radius": 5.0}, {"x": 700.0, "y": 100.0, "radius": 5.0}],
               "nest": [{"x": 300.0, "y": 500.0, "radius": 5.0}, {"x": 700.0, "y": 500.0, "radius": 5.0}]}


def _per_site_run(transitory: int):
    """One robot standing on the centre of the second food site, then of the second nest.  Sites of
    radius 5 put every spot within 8 (the robot's radius) of the centre: pick-up and deposit happen
    in the first step there."""
    cfg = validate({"steps": 100, "transitory": transitory,
                    "swarm": {"robots": 1, "groups": [{"behaviour": "naive", "count": 1}]}, **SMALL_SITES})
    sim = Simulation(cfg, seed=1)
    place(sim, 0, 700.0, 100.0, 0.0)
    sim.step(1)
    w = sim.world
    picked = (bool(w.carrying[0]), bool(w.tab_valid[0, FOOD]), int(w.last_site[0]))
    place(sim, 0, 700.0, 500.0, 0.0)
    sim.step(1)
    return sim, picked


def test_items_are_counted_at_the_site_where_they_were_picked_and_dropped():
    sim, picked = _per_site_run(transitory=0)
    assert picked == (True, True, FOOD)  # carrying, and its food entry points at the site it is in
    w = sim.world
    assert not w.carrying[0] and w.items[0] == 1
    assert w.site_items.tolist() == [0, 1, 0, 1]  # food 0, food 1, nest 0, nest 1
    counts = sim.site_counts()
    assert [(c["kind"], c["x"], c["items"]) for c in counts] == [
        ("food", 300.0, 0), ("food", 700.0, 1), ("nest", 300.0, 0), ("nest", 700.0, 1)]


def test_items_before_the_transitory_period_are_not_counted_per_site():
    sim, picked = _per_site_run(transitory=5)
    assert picked[0] and not sim.world.carrying[0]  # it did pick up and deposit
    assert sim.world.site_items.tolist() == [0, 0, 0, 0] and sim.world.items[0] == 0


def test_sensing_robots_reflects_off_a_robot_ahead():
    # robot 0 at (100, 300) heading +x, robot 1 at (117, 300): robot 0's FRONT probe (102.5, 300) is
    # 14.5 from robot 1 (<= 16): with sense_robots it fires, robot 0 (seeking) drops its food entry,
    # explores and reflects its (2.5, 0) move to (-2.5, 0); robot 1, heading -x, probes (114.5, 300),
    # 14.5 from robot 0's start... but robot 0 has moved to 97.5 first (id order): 17 away, no fire.
    from infomarket.engine.world import EXPLORING, SEEKING_FOOD

    sim = simulation(terrain_config(robots=2, collisions=True, sense_robots=True))
    place(sim, 0, 100.0, 300.0, 0.0)
    place(sim, 1, 117.0, 300.0, 180.0)
    sim.world.hdir[1] = (-1.0, 0.0)
    for i in (0, 1):
        seek_food(sim, i, 1000.0, 0.0)
    sim.world.levy[:] = 5
    sim.step(1)
    w = sim.world
    assert w.state.tolist() == [EXPLORING, SEEKING_FOOD]
    assert w.pos[:, 0].tolist() == [97.5, 114.5]


def test_without_sensing_robots_the_same_pair_is_blocked_not_reflected():
    from infomarket.engine.world import SEEKING_FOOD

    sim = simulation(terrain_config(robots=2, collisions=True))
    place(sim, 0, 100.0, 300.0, 0.0)
    place(sim, 1, 117.0, 300.0, 180.0)
    sim.world.hdir[1] = (-1.0, 0.0)
    for i in (0, 1):
        seek_food(sim, i, 1000.0, 0.0)
    sim.step(1)
    w = sim.world
    assert w.state.tolist() == [SEEKING_FOOD, SEEKING_FOOD]
    assert w.pos[:, 0].tolist() == [100.0, 117.0]  # each would end 14.5 from the other


def test_items_per_site_add_up_to_the_items_deposited():
    """Every deposit is counted at its nest and every pick-up at its food site (after the transitory
    period).  The per-site count is written through ``unlock`` next to the spot's random draws, where
    numba's dead-code elimination once deleted it (state.view._unlock_aliases): the counts stayed 0."""
    import infomarket as im
    from infomarket.runner.plan import conditions

    cond = next(c for c in conditions(im.load_experiment("two_food")) if c.id == "food_sites=2")
    res = im.Simulation(cond.config, seed=1).run(1500)
    sites = res.totals["sites"]
    deposits = sum(s["items"] for s in sites if s["kind"] == "nest")
    pickups = sum(s["items"] for s in sites if s["kind"] == "food")
    assert deposits == int(res.robots.items_collected.sum()) > 0
    assert pickups >= deposits
    assert all(s["items"] > 0 for s in sites if s["kind"] == "food")  # both food sites were used
