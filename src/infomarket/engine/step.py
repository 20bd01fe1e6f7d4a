"""The pieces of one time step, each written once (docs/model.md §2-3, §6), with its variants explicit.

The step loop (``engine/loop_template.py``, specialised per set of rules by ``engine.specialise``) calls
these in the order of docs/model.md §3.  Two compile-time options select the variants: ``variant(terrain,
paths)`` returns the pieces compiled with those options as constants, so numba prunes the branches they
turn off before it types them (a kernel neither compiles nor runs a variant it does not use):

``terrain``  obstacles, several sites of a kind, line of sight, collisions, robots sensing each other
             (``engine.terrain`` has the rules and their helpers).  Off on the paper's plane, where there
             is one site of each kind and site index == kind (FOOD, NEST).
``paths``    waypoint paths (``engine.paths``): a seeking robot follows the legs of a bought path, its
             waypoints are dead-reckoned, a bump marks the site.  Implies ``terrain``.

The ledger's operations (an instant ledger or the chain model) are the ledger's own
(``ledger.backends``), chosen by the kernel's ``LEDGER`` option.

Nothing here depends on the configured rules; the loop's generated dispatch calls the rules.
"""
import functools
import math
from typing import NamedTuple
from collections.abc import Callable

from ..jit import njit

from ..state.view import unlock
from .draws import normal, uniform
from .geometry import norm, outside, rotate, to_frame, to_world, within
from .neighbours import find_all_neighbours
from .params import FOOD, NEST
from .paths import (advance, at_site, begin_paths, bumped, drop_invalid, install_path, path_odometry)
from .swarm import EXPLORING, SEEKING_FOOD, SEEKING_NEST
from .terrain import blocked, containing_site, drop_hidden_pairs, obstructed


# ---- the behaviour step's shared pieces ----------------------------------------------------------------

@njit(forceinline=True, cache=True)
def walls(x, y, c, s, r, width, height):
    """Wall sensors FRONT, RIGHT, BACK, LEFT: would a move of (c, s) (the heading times the speed),
    turned by 0, -90, 180, +90 degrees, put the robot's disc outside the arena?
    (Scalar arguments: this runs for every robot every step.)"""
    return (outside(x + c, y + s, r, width, height), outside(x + s, y - c, r, width, height),
            outside(x - c, y - s, r, width, height), outside(x - s, y + c, r, width, height))


@njit(forceinline=True, cache=True)
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


@njit(forceinline=True, cache=True)
def draw_index(cdf, guide, u):
    """Inverse-CDF sampling on a table: the first index whose cumulative probability exceeds u.

    ``guide[j]`` is that index for u = j / len(guide) (see ``params.guide_table``), so the search starts
    next to the answer and takes about one step on average instead of a binary search's ~14."""
    k = guide[int(u * guide.shape[0])]
    last = cdf.shape[0] - 1
    while k < last and cdf[k] <= u:
        k += 1
    return k


@njit(forceinline=True, cache=True)
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


@njit(forceinline=True, cache=True)
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


class Step(NamedTuple):
    """The step pieces of one variant, compiled for it (``variant``)."""

    find_neighbours: Callable
    begin_communication: Callable
    install_table: Callable
    forage: Callable
    sense_sites: Callable
    behaviour_step: Callable
    move: Callable


def variant(terrain: bool, paths: bool) -> Step:
    """The step's pieces for these options, chosen before anything compiles.  ``terrain`` and ``paths``
    are constants of the closures below, so numba prunes the branches they turn off before it types
    them: a kernel neither compiles nor runs the code of a variant it does not use (passed as
    arguments instead, every kernel would type and lower all of it)."""
    return _variant(bool(terrain), bool(paths))


@functools.cache
def _variant(terrain: bool, paths: bool) -> Step:
    # ---- neighbours and the communication phase
    @njit(cache=True)
    def find_neighbours(w):
        """Every pair strictly closer than the communication range (``engine.neighbours``); with terrain and
        line of sight, pairs whose straight line an obstacle cuts are dropped."""
        find_all_neighbours(w)
        if terrain:
            drop_hidden_pairs(w)

    @njit(forceinline=True, cache=True)
    def begin_communication(w, i):
        """Robot i is about to buy: its purchases go to a new table (and path), a copy of the one it sells.
        Only robot i reads or writes its new table, and nobody writes its table before it moves, so the
        copy is made just before its buy rule runs, and only for a robot whose buy rule runs."""
        for s in range(2):
            w.new_vec[i, s, 0] = w.tab_vec[i, s, 0]
            w.new_vec[i, s, 1] = w.tab_vec[i, s, 1]
            w.new_age[i, s] = w.tab_age[i, s]
            w.new_valid[i, s] = w.tab_valid[i, s]
        if paths:
            begin_paths(w, i)

    @njit(forceinline=True, cache=True)
    def install_table(w, i):
        """The robot moves: what it bought becomes its table (and path); called for a robot whose
        ``begin_communication`` ran this step (for any other, the new table is not this step's)."""
        for s in range(2):
            w.tab_vec[i, s, 0] = w.new_vec[i, s, 0]
            w.tab_vec[i, s, 1] = w.new_vec[i, s, 1]
            w.tab_age[i, s] = w.new_age[i, s]
            w.tab_valid[i, s] = w.new_valid[i, s]
        if paths:
            install_path(w, i)

    @njit(forceinline=True, cache=True)
    def site_of(w, x, y, kind):
        """The site of ``kind`` that (x, y) lies strictly inside (the first in file order), else -1."""
        if terrain:
            return containing_site(w, x, y, kind)
        if within(x, y, w.sites_xy[kind, 0], w.sites_xy[kind, 1], w.sites_r[kind]):
            return kind
        return -1

    @njit(forceinline=True, cache=True)
    def forage(w, i, rng):
        """Pick-up and drop spots (docs/model.md §6), at whichever site of the needed kind the robot is in.
        Returns True when robot i deposits an item this step (the caller then pays and shares the reward)."""
        x = w.pos[i, 0]
        y = w.pos[i, 1]
        kind = NEST if w.carrying[i] else FOOD
        if terrain:
            s = containing_site(w, x, y, kind)
            fresh = s >= 0 and not (w.has_spot[i, kind] and w.spot_site[i, kind] == s)
        else:
            s = kind
            fresh = not w.has_spot[i, kind] and within(x, y, w.sites_xy[s, 0], w.sites_xy[s, 1], w.sites_r[s])
        if fresh:  # a spot uniform in the site's disc
            a = uniform(rng) * 2.0 * math.pi
            r = w.sites_r[s] * math.sqrt(uniform(rng))
            w.spot[i, kind, 0] = w.sites_xy[s, 0] + r * math.cos(a)
            w.spot[i, kind, 1] = w.sites_xy[s, 1] + r * math.sin(a)
            w.has_spot[i, kind] = True
            w.spot_site[i, kind] = s
        if not (w.has_spot[i, kind] and within(x, y, w.spot[i, kind, 0], w.spot[i, kind, 1], w.radius)):
            return False
        w.has_spot[i, kind] = False
        counted = w.clock[0] >= w.transitory  # from step == transitory on, as the original counts
        if terrain and counted:
            unlock(w.site_items)[w.spot_site[i, kind]] += 1
        if kind == FOOD:
            w.carrying[i] = True
            return False
        w.carrying[i] = False
        if counted:
            w.items[i] += 1
        return True

    @njit(forceinline=True, cache=False)  # captures compiled functions: see compiled_cache
    def sense_sites(w, i):
        """A robot inside a site knows exactly where its target point there is (its spot if the spot lies in
        that site, else the centre); for each kind, the first site containing it sets that kind's entry."""
        x = w.pos[i, 0]
        y = w.pos[i, 1]
        for k in range(2):
            s = site_of(w, x, y, k)
            if s < 0:
                continue
            if w.has_spot[i, k] and (not terrain or w.spot_site[i, k] == s):
                tx = w.spot[i, k, 0]
                ty = w.spot[i, k, 1]
            else:
                tx = w.sites_xy[s, 0]
                ty = w.sites_xy[s, 1]
            vx, vy = to_frame(w, i, tx - x, ty - y)
            w.tab_vec[i, k, 0] = vx
            w.tab_vec[i, k, 1] = vy
            w.tab_age[i, k] = 0
            w.tab_valid[i, k] = True
            w.last_site[i] = k

    @njit(forceinline=True, cache=True)
    def sensors(w, i):
        """FRONT, RIGHT, BACK, LEFT (docs/model.md §3); with terrain, obstacles (and, with sense_robots,
        other robots) are sensed like the arena's walls."""
        x = w.pos[i, 0]
        y = w.pos[i, 1]
        c = w.speed * w.hdir[i, 0]
        s = w.speed * w.hdir[i, 1]
        if terrain:
            return (obstructed(w, i, x + c, y + s), obstructed(w, i, x + s, y - c), obstructed(w, i, x - c, y - s),
                    obstructed(w, i, x - s, y + c))
        return walls(x, y, c, s, w.radius, w.width, w.height)

    @njit(forceinline=True, cache=False)  # captures compiled functions: see compiled_cache
    def behaviour_step(w, i, rng):
        """Sensors, sites, state machine, intended movement with wall reflection, dead reckoning
        (docs/model.md §3); with paths, a site sensed clears that kind's path and mark, the legs are followed,
        a bump marks the site and waypoints are dead-reckoned.  Returns the reflected intended movement
        (robot frame)."""
        front, right, back, left = sensors(w, i)
        sense_sites(w, i)
        was_food = was_nest = False
        if paths:
            for k in range(2):
                if containing_site(w, w.pos[i, 0], w.pos[i, 1], k) >= 0:
                    at_site(w, i, k)
            advance(w, i)
            was_food = w.tab_valid[i, FOOD]
            was_nest = w.tab_valid[i, NEST]
        update_state(w, i, front)
        if paths:
            bumped(w, i, front, was_food, was_nest)
            drop_invalid(w, i)
        dx, dy = intended_move(w, i, rng)
        if (front and dx >= 0.0) or (back and dx <= 0.0):
            dx = -dx
        if (right and dy <= 0.0) or (left and dy >= 0.0):
            dy = -dy
        if dx != 0.0 or dy != 0.0:
            odometry_update(w, i, dx, dy)
            if paths:
                path_odometry(w, i, dx, dy)
        return dx, dy

    @njit(forceinline=True, cache=True)
    def move(w, i, dx, dy, rng):
        """Execute the movement with odometry noise: the robot turns by N(bias, noise_sd) more than it
        thinks; its new heading is the direction it actually moved; positions are clamped to the arena.
        With terrain, a move whose end point is blocked (``terrain.blocked``) is not made."""
        if dx == 0.0 and dy == 0.0:
            return
        mx, my = to_world(w, i, dx, dy)
        mx, my = rotate(mx, my, normal(rng, w.bias[i], w.noise_sd))
        length = norm(mx, my)
        w.hdir[i, 0] = mx / length
        w.hdir[i, 1] = my / length
        r = w.radius
        x = min(max(w.pos[i, 0] + mx, r), w.width - r)
        y = min(max(w.pos[i, 1] + my, r), w.height - r)
        if terrain and blocked(w, i, x, y):
            return
        w.pos[i, 0] = x
        w.pos[i, 1] = y

    return Step(find_neighbours, begin_communication, install_table, forage, sense_sites, behaviour_step, move)


# ---- the log -----------------------------------------------------------------------------------------

@njit(cache=True)
def record_history(w):
    """Wealth of every robot every ``hist_every`` steps (row k holds step (k + 1) * hist_every)."""
    if w.hist_every > 0 and w.clock[0] % w.hist_every == 0:
        k = w.clock[0] // w.hist_every - 1
        hist = unlock(w.hist)
        if 0 <= k < hist.shape[0]:
            for i in range(w.pos.shape[0]):
                hist[k, i] = w.balance[i]
