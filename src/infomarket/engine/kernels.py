"""Compiled pieces of one time step that do not depend on the configured rules (MODEL.md §2-3, §6).

The rule-dependent glue (which behaviour buys and sells how, which scheme pays) is generated per
configuration by ``engine.specialise`` around ``engine._loop``; everything here is shared and cached.
"""
import math

import numpy as np
from numba import njit

from .draws import normal, uniform
from .geometry import DEG, norm, rotate
from .world import EXPLORING, FOOD, NEST, SEEKING_FOOD, SEEKING_NEST


@njit
def begin_communication(w):
    """Start-of-phase copy: purchases go to the new table; sellers keep selling the old one."""
    tab_vec, new_vec, tab_age, new_age, tab_valid, new_valid = (w.tab_vec, w.new_vec, w.tab_age, w.new_age,
                                                                w.tab_valid, w.new_valid)
    for i in range(tab_age.shape[0]):  # arrays read once: a field read per element costs a reference count
        for s in range(2):
            new_vec[i, s, 0] = tab_vec[i, s, 0]
            new_vec[i, s, 1] = tab_vec[i, s, 1]
            new_age[i, s] = tab_age[i, s]
            new_valid[i, s] = tab_valid[i, s]


@njit(inline="always")
def install_table(w, i):
    for s in range(2):
        w.tab_vec[i, s, 0] = w.new_vec[i, s, 0]
        w.tab_vec[i, s, 1] = w.new_vec[i, s, 1]
        w.tab_age[i, s] = w.new_age[i, s]
        w.tab_valid[i, s] = w.new_valid[i, s]


@njit(inline="always")
def within(x, y, cx, cy, r):
    """Strictly inside the circle of centre (cx, cy) and radius r."""
    dx = x - cx
    dy = y - cy
    return dx * dx + dy * dy < r * r


@njit(inline="always")
def draw_spot(w, i, site, rng):
    """A pick-up / drop point uniform in the site's disc."""
    a = uniform(rng) * 2.0 * math.pi
    r = w.site_r[site] * math.sqrt(uniform(rng))
    w.spot[i, site, 0] = w.site_pos[site, 0] + r * math.cos(a)
    w.spot[i, site, 1] = w.site_pos[site, 1] + r * math.sin(a)
    w.has_spot[i, site] = True


@njit(inline="always")
def forage(w, i, rng):
    """Pick-up and drop spots (MODEL.md §6).  Returns True when robot i deposits an item this step
    (the caller then pays and shares the reward)."""
    x = w.pos[i, 0]
    y = w.pos[i, 1]
    site = NEST if w.carrying[i] else FOOD
    if not w.has_spot[i, site] and within(x, y, w.site_pos[site, 0], w.site_pos[site, 1], w.site_r[site]):
        draw_spot(w, i, site, rng)
    if not (w.has_spot[i, site] and within(x, y, w.spot[i, site, 0], w.spot[i, site, 1], w.radius)):
        return False
    w.has_spot[i, site] = False
    if site == FOOD:
        w.carrying[i] = True
        return False
    w.carrying[i] = False
    if w.clock[0] >= w.transitory:  # from step == transitory on, as the original counts
        w.items[i] += 1
    return True


@njit(inline="always")
def outside(x, y, r, width, height):
    """Would a robot disc centred at (x, y) leave the arena?"""
    return x + r >= width or x - r < 0.0 or y + r >= height or y - r < 0.0


@njit(inline="always")
def to_frame(w, i, x, y):
    """A world-frame vector in robot i's frame (rotated by -heading)."""
    c = w.hdir[i, 0]
    s = w.hdir[i, 1]
    return c * x + s * y, c * y - s * x


@njit(inline="always")
def to_world(w, i, x, y):
    """A vector in robot i's frame in the world frame (rotated by +heading)."""
    c = w.hdir[i, 0]
    s = w.hdir[i, 1]
    return c * x - s * y, s * x + c * y


@njit(inline="always")
def walls(x, y, c, s, r, width, height):
    """Wall sensors FRONT, RIGHT, BACK, LEFT: would a move of (c, s) (the heading times the speed),
    turned by 0, -90, 180, +90 degrees, put the robot's disc outside the arena?
    (Scalar arguments: this runs for every robot every step.)"""
    return (outside(x + c, y + s, r, width, height), outside(x + s, y - c, r, width, height),
            outside(x - c, y - s, r, width, height), outside(x - s, y + c, r, width, height))


@njit(inline="always")
def sense_sites(w, i):
    """A robot inside a site knows exactly where its target point there is (its spot, else the centre)."""
    x = w.pos[i, 0]
    y = w.pos[i, 1]
    for s in range(2):
        if within(x, y, w.site_pos[s, 0], w.site_pos[s, 1], w.site_r[s]):
            if w.has_spot[i, s]:
                tx = w.spot[i, s, 0]
                ty = w.spot[i, s, 1]
            else:
                tx = w.site_pos[s, 0]
                ty = w.site_pos[s, 1]
            vx, vy = to_frame(w, i, tx - x, ty - y)
            w.tab_vec[i, s, 0] = vx
            w.tab_vec[i, s, 1] = vy
            w.tab_age[i, s] = 0
            w.tab_valid[i, s] = True
            w.last_site[i] = s


@njit(inline="always")
def update_state(w, i, front):
    """The three-state machine (EXPLORING, SEEKING_FOOD, SEEKING_NEST)."""
    st = w.state[i]
    carrying = w.carrying[i]
    if st == EXPLORING:
        if w.tab_valid[i, FOOD] and not carrying:
            st = SEEKING_FOOD
        elif w.tab_valid[i, NEST] and carrying:
            st = SEEKING_NEST
    elif st == SEEKING_FOOD:
        if carrying:
            st = SEEKING_NEST if w.tab_valid[i, NEST] else EXPLORING
        elif norm(w.tab_vec[i, FOOD, 0], w.tab_vec[i, FOOD, 1]) < w.radius:
            w.tab_valid[i, FOOD] = False
            st = EXPLORING
    elif st == SEEKING_NEST:
        if not carrying:
            st = SEEKING_FOOD if w.tab_valid[i, FOOD] else EXPLORING
        elif norm(w.tab_vec[i, NEST, 0], w.tab_vec[i, NEST, 1]) < w.radius:
            w.tab_valid[i, NEST] = False
            st = EXPLORING
    if st != EXPLORING and front:
        w.tab_valid[i, FOOD if st == SEEKING_FOOD else NEST] = False
        st = EXPLORING
    w.state[i] = st


@njit(inline="always")
def draw_index(cdf, guide, u):
    """Inverse-CDF sampling on a table: the first index whose cumulative probability exceeds u.

    ``guide[j]`` is that index for u = j / len(guide) (see ``build.guide_table``), so the search starts
    next to the answer and takes about one step on average instead of a binary search's ~14."""
    k = guide[int(u * guide.shape[0])]
    last = cdf.shape[0] - 1
    while k < last and cdf[k] <= u:
        k += 1
    return k


@njit(inline="always")
def intended_move(w, i, rng):
    """The movement the robot wants, in its own frame: towards the sought site, or a random-walk step."""
    st = w.state[i]
    if st != EXPLORING:
        s = FOOD if st == SEEKING_FOOD else NEST
        x = w.tab_vec[i, s, 0]
        y = w.tab_vec[i, s, 1]
        length = norm(x, y)
        if length > w.speed:
            x *= w.speed / length
            y *= w.speed / length
        return x, y
    turn = 0
    if w.levy[i] <= 1:
        turn = draw_index(w.cauchy_cdf, w.cauchy_guide, uniform(rng))
    w.levy[i] -= 1
    if w.levy[i] <= 0:
        w.levy[i] = draw_index(w.levy_cdf, w.levy_guide, uniform(rng)) + 1
    if turn == 0:
        return w.speed, 0.0
    return w.speed * w.turn_cos[turn], w.speed * w.turn_sin[turn]


@njit(inline="always")
def odometry_update(w, i, dx, dy):
    """Dead reckoning: every table and pending entry moves by -dr, turns by -heading(dr), ages by one.
    Turning by -heading(dr) is multiplying by dr's conjugate unit vector, so no trigonometry is needed."""
    length = norm(dx, dy)
    c = dx / length
    s = -dy / length
    for k in range(2):
        x = w.tab_vec[i, k, 0] - dx
        y = w.tab_vec[i, k, 1] - dy
        w.tab_vec[i, k, 0] = c * x - s * y
        w.tab_vec[i, k, 1] = s * x + c * y
        w.tab_age[i, k] += 1
        for j in range(w.pend_count[i, k]):
            x = w.pend_vec[i, k, j, 0] - dx
            y = w.pend_vec[i, k, j, 1] - dy
            w.pend_vec[i, k, j, 0] = c * x - s * y
            w.pend_vec[i, k, j, 1] = s * x + c * y
            w.pend_age[i, k, j] += 1


@njit(inline="always")
def behaviour_step(w, i, rng):
    """Sensors, state machine, intended movement with wall reflection, table update (MODEL.md §3).
    Returns the reflected intended movement (robot frame)."""
    front, right, back, left = walls(w.pos[i, 0], w.pos[i, 1], w.speed * w.hdir[i, 0],
                                     w.speed * w.hdir[i, 1], w.radius, w.width, w.height)
    sense_sites(w, i)
    update_state(w, i, front)
    dx, dy = intended_move(w, i, rng)
    if (front and dx >= 0.0) or (back and dx <= 0.0):
        dx = -dx
    if (right and dy <= 0.0) or (left and dy >= 0.0):
        dy = -dy
    if dx != 0.0 or dy != 0.0:
        odometry_update(w, i, dx, dy)
    return dx, dy


@njit(inline="always")
def move(w, i, dx, dy, rng):
    """Execute the movement with odometry noise: the robot turns by N(bias, noise_sd) more than it
    thinks; its new heading is the direction it actually moved; positions are clamped to the arena."""
    if dx == 0.0 and dy == 0.0:
        return
    mx, my = to_world(w, i, dx, dy)
    mx, my = rotate(mx, my, normal(rng, w.bias[i], w.noise_sd))
    length = norm(mx, my)
    w.hdir[i, 0] = mx / length
    w.hdir[i, 1] = my / length
    r = w.radius
    w.pos[i, 0] = min(max(w.pos[i, 0] + mx, r), w.width - r)
    w.pos[i, 1] = min(max(w.pos[i, 1] + my, r), w.height - r)


@njit
def record_history(w):
    """Wealth of every robot every ``hist_every`` steps (row k holds step (k + 1) * hist_every)."""
    if w.hist_every > 0 and w.clock[0] % w.hist_every == 0:
        k = w.clock[0] // w.hist_every - 1
        if 0 <= k < w.hist.shape[0]:
            for i in range(w.pos.shape[0]):
                w.hist[k, i] = w.balance[i]


@njit
def _turn_tables(cos_out, sin_out):
    for k in range(cos_out.shape[0]):
        a = float(k) * DEG
        cos_out[k] = math.cos(a)
        sin_out[k] = math.sin(a)


def turn_tables():
    """cos and sin of every whole-degree turn, computed by compiled code (the same libm calls the
    kernel made before it looked them up), so a turn costs a table read instead of two calls."""
    c = np.empty(360)
    s = np.empty(360)
    _turn_tables(c, s)
    return c, s
