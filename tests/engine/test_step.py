"""Hand-computed checks of the step's pieces: sensing, walls, spots, odometry, random-walk tables."""
import math

import numpy as np
import pytest
from scipy import stats

from infomarket.engine import step
from infomarket.engine.step import variant
from infomarket.engine.params import cauchy_cdf, guide_table, levy_cdf
from infomarket.engine.neighbours import find_all_neighbours as find_neighbours
from infomarket.engine.world import EXPLORING, FOOD, NEST, SEEKING_FOOD, headings

from ..conftest import Handle, make_config

K = step
P = variant(terrain=False, paths=False)  # the paper's plane


def test_neighbours_strict_range_and_id_order():
    h = Handle(make_config(4))
    h.world.pos[:] = [[100, 100], [149.999, 100], [150, 100], [120, 110]]
    find_neighbours(h.view)
    w = h.world
    assert list(w.nbr[0, :w.nbr_count[0]]) == [1, 3]  # robot 2 is exactly 50 away: not a neighbour
    assert list(w.nbr[3, :w.nbr_count[3]]) == [0, 1, 2]
    assert list(w.nbr[1, :w.nbr_count[1]]) == [0, 2, 3]


def test_wall_sensors_and_reflection_use_the_reflected_move():
    h = Handle(make_config(1, robot={"noise_sd": 0.0}))
    w = h.world
    h.place(0, 1200 - 8 - 1.0, 300, 0.0)  # facing the right wall, one unit away
    w.levy[0] = 50  # no turn this step: intended move is (v, 0)
    w.tab_vec[0, FOOD] = (-100.0, 0.0)  # some entry to check the odometry update with
    dx, dy = P.behaviour_step(h.view, 0, h.rng)
    assert (dx, dy) == (-2.5, 0.0)  # FRONT wall: x component negated
    # table updated with the reflected move: (-100 - (-2.5), 0) turned by -180 degrees
    assert w.tab_vec[0, FOOD, 0] == pytest.approx(97.5)
    assert w.tab_vec[0, FOOD, 1] == pytest.approx(0.0, abs=1e-9)
    assert w.tab_age[0, FOOD] == 1
    # the robot moves by the reflected vector: with no odometry noise, exactly 2.5 away from the wall
    w.bias[0] = 0.0
    P.move(h.view, 0, dx, dy, np.random.default_rng(1))
    assert w.pos[0] == pytest.approx([1200 - 8 - 1.0 - 2.5, 300.0], abs=1e-12)
    assert headings(w)[0] == pytest.approx(180.0, abs=1e-12)


def test_walls_report_each_side():
    front, right, back, left = K.walls(10.0, 300.0, 0.0, 2.5, 8.0, 1200.0, 600.0)  # heading +y, near x=0
    assert (front, right, back, left) == (False, False, False, True)


def test_sensing_a_site_sets_the_exact_target_in_the_robot_frame():
    h = Handle(make_config(1))
    w = h.world
    h.place(0, 210, 300, 90.0)  # inside food, facing +y
    P.sense_sites(h.view, 0)
    assert w.tab_valid[0, FOOD] and w.tab_age[0, FOOD] == 0
    # the centre is at (-10, 0) in the world: in a frame whose x axis is +y that is (0, +10)
    assert w.tab_vec[0, FOOD] == pytest.approx([0.0, 10.0], abs=1e-12)
    assert not w.tab_valid[0, NEST]
    assert w.last_site[0] == FOOD


def test_spot_pick_up_and_deposit():
    h = Handle(make_config(1))
    w, view = h.world, h.view
    h.place(0, 200, 300, 0.0)
    assert not P.forage(view, 0, h.rng)
    assert w.has_spot[0, FOOD] and not w.carrying[0]
    sx, sy = w.spot[0, FOOD]
    assert math.hypot(sx - 200, sy - 300) < 50
    w.pos[0] = (sx + 7.9, sy)  # within r = 8 of the spot: picks up, spot removed
    assert not P.forage(view, 0, h.rng)
    assert w.carrying[0] and not w.has_spot[0, FOOD]
    h.place(0, 1000, 300, 0.0)
    assert not P.forage(view, 0, h.rng)  # nest spot drawn
    assert w.has_spot[0, NEST]
    w.pos[0] = w.spot[0, NEST]
    w.clock[0] = 1
    assert P.forage(view, 0, h.rng)  # deposit
    assert not w.carrying[0] and w.items[0] == 1 and not w.has_spot[0, NEST]


def test_deposit_in_transitory_period_pays_but_does_not_count():
    h = Handle(make_config(1, transitory=10, steps=20))
    w = h.world
    w.carrying[0] = True
    w.has_spot[0, NEST] = True
    w.spot[0, NEST] = (1000, 300)
    h.place(0, 1000, 300, 0.0)
    w.clock[0] = 9  # the last step of the transitory period (the step equal to it counts in the original)
    assert P.forage(h.view, 0, h.rng)
    assert w.items[0] == 0


def test_state_machine_gives_up_on_arrival_without_site():
    h = Handle(make_config(1))
    w = h.world
    w.state[0] = SEEKING_FOOD
    w.tab_valid[0, FOOD] = True
    w.tab_vec[0, FOOD] = (3.0, 4.0)  # |v| = 5 < r: it arrived where it believed the food was
    K.update_state(h.view, 0, False)
    assert w.state[0] == EXPLORING and not w.tab_valid[0, FOOD]


def test_front_wall_while_seeking_invalidates_the_sought_site():
    h = Handle(make_config(1))
    w = h.world
    w.state[0] = SEEKING_FOOD
    w.tab_valid[0, FOOD] = True
    w.tab_vec[0, FOOD] = (300.0, 0.0)
    K.update_state(h.view, 0, True)
    assert w.state[0] == EXPLORING and not w.tab_valid[0, FOOD]


def test_odometry_update_moves_and_turns_every_entry():
    h = Handle(make_config(1))
    w = h.world
    w.tab_vec[0, NEST] = (10.0, 0.0)
    w.pend_count[0, NEST] = 1
    w.pend_vec[0, NEST, 0] = (0.0, 10.0)
    K.odometry_update(h.view, 0, 0.0, 2.5)  # moved 2.5 along its +y: the frame turns by +90 degrees
    assert w.tab_vec[0, NEST] == pytest.approx([-2.5, -10.0])
    assert w.pend_vec[0, NEST, 0] == pytest.approx([7.5, 0.0])
    assert w.tab_age[0, NEST] == 1 and w.pend_age[0, NEST, 0] == 1


def test_wrapped_cauchy_table_by_sampling():
    """Turns drawn with the kernel's own sampler follow eq. 2.  On whole degrees the mass of k degrees is
    the density times one degree, (1 - rho^2) / (360 (1 + rho^2 - 2 rho cos k)); for rho = 0.9 that is
    0.19 / 3.6 = 0.05278 at 0, 0.19 / (360 x 1.81) = 2.916e-4 at 90 and 0.19 / (360 x 3.61) = 1.462e-4 at 180."""
    rho = 0.9
    cdf = cauchy_cdf(rho)
    guide = guide_table(cdf)
    n = 200_000
    u = np.random.default_rng(3).random(n)
    draws = np.array([K.draw_index(cdf, guide, x) for x in u])
    assert draws.min() >= 0 and draws.max() <= 359
    observed = np.bincount(draws, minlength=360) / n
    for k, p in ((0, 0.19 / 3.6), (90, 0.19 / (360 * 1.81)), (180, 0.19 / (360 * 3.61))):
        assert abs(observed[k] - p) < 5 * math.sqrt(p / n), (k, observed[k], p)
    # symmetric: turning k degrees left is as likely as k degrees right (k and 360 - k)
    left, right = observed[1:180].sum(), observed[181:].sum()
    assert abs(left - right) < 5 * math.sqrt(0.5 / n)
    # the whole distribution, against the density written above (tail bins pooled for the chi-square)
    k = np.arange(360)
    pmf = (1 - rho**2) / (360 * (1 + rho**2 - 2 * rho * np.cos(np.radians(k))))
    order = np.argsort(pmf)[::-1]
    head = order[:60]
    obs = np.append(observed[head], observed[order[60:]].sum()) * n
    exp = np.append(pmf[head], pmf[order[60:]].sum()) * n
    exp *= obs.sum() / exp.sum()  # the Riemann sum of the density is 1 to within 1e-15
    assert stats.chisquare(obs, exp).pvalue > 1e-3


def test_levy_table_by_sampling():
    alpha = 1.4
    cdf = levy_cdf(alpha, 15000)
    assert len(cdf) == 15001 and cdf[-1] == 1.0
    u = np.random.default_rng(4).random(400_000)
    k = np.searchsorted(cdf, u, side="right") + 1
    p1, p2, p3 = (np.mean(k == j) for j in (1, 2, 3))
    assert p1 / p2 == pytest.approx(2 ** (alpha + 1), rel=0.03)
    assert p1 / p3 == pytest.approx(3 ** (alpha + 1), rel=0.06)
    assert k.max() > 100  # heavy tail


def test_random_walk_turns_only_when_the_counter_runs_out():
    h = Handle(make_config(1))
    w = h.world
    w.state[0] = EXPLORING
    w.levy[0] = 3
    assert K.intended_move(h.view, 0, h.rng) == (2.5, 0.0)  # counter 3 -> 2, no turn
    assert w.levy[0] == 2
    assert K.intended_move(h.view, 0, h.rng) == (2.5, 0.0)  # 2 -> 1
    K.intended_move(h.view, 0, h.rng)  # counter 1: turn drawn, then 0 -> redrawn (>= 1)
    assert w.levy[0] >= 1


def test_guided_sampling_equals_the_inverse_cdf_everywhere():
    cdf = levy_cdf(1.4, 15000)
    guide = guide_table(cdf)
    u = np.concatenate([np.random.default_rng(5).random(20_000), cdf[:50], np.nextafter(cdf[:50], 0), [0.0]])
    u = u[u < 1.0]
    got = np.array([K.draw_index(cdf, guide, x) for x in u])
    assert np.array_equal(got, np.searchsorted(cdf, u, side="right"))
