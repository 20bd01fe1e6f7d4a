"""The terrain-aware step: obstacles, several sites of a kind, line of sight and collisions.

Setups on the paper's plane never run this code: ``engine.specialise`` rebinds the step loop's
``find_neighbours``, ``forage``, ``behaviour_step`` and ``move`` to the functions below only when the
experiment has ``cfg.terrain`` (a separate compiled kernel), so the paper's kernel is the one it always was.

Rules (docs/terrain.md says the same for users):

* **Sensing and reflection.**  The four proximity sensors fire when a move of ``v`` towards heading,
  heading - 90, heading + 180, heading + 90 would put the robot's disc outside the arena *or* touching
  an obstacle (distance from the probed centre to it at most ``r``); the reflection rule and the
  "FRONT while seeking invalidates the entry" rule are the model's, unchanged (MODEL.md §3).
* **Never inside.**  A move whose end point (after noise and the arena clamp) would make the disc
  overlap an obstacle (distance below ``r``) is not made: the robot stays where it is.
* **Collisions** (``robot.collisions``).  Robots move one at a time in id order (as always); a move
  whose end point would overlap another robot's disc (centres closer than ``2 r``) where that robot is
  now is not made either.  Nobody is ever pushed, so the rule is deterministic and no overlap can arise
  (initial positions are drawn clear, ``place_clear``).  The check is against every robot, O(n) per
  move.
* **Odometry of a blocked robot.**  Its heading still turns to the direction it tried to move in, and
  its dead reckoning counts the whole intended move: it cannot tell it was stopped, exactly as the
  arena clamp already works.
* **Several sites.**  Every site is sensed; a robot inside sites of one kind senses the first in file
  order.  The navigation table keeps one entry per kind (the last site of that kind sensed).  A robot
  inside a site of the kind it needs gets a spot there (a new one if its spot lies in another site);
  items are counted per site in ``site_items`` (pick-ups at food sites, deposits at nests, after the
  transitory period).
* **Sensing robots** (``robot.sense_robots``, added after the crowd's first answer, see
  docs/research.md).  The proximity sensors also fire when the probed disc would touch another
  robot's disc (centres at most ``2 r`` apart), so robots reflect off each other as off walls.
* **Line of sight** (``robot.line_of_sight``).  A neighbour pair is dropped when an obstacle cuts the
  segment between the two centres (touching counts).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..errors import ConfigError
from .draws import normal, uniform
from .geometry import norm, rotate
from .kernels import intended_move, odometry_update, outside, to_frame, to_world, update_state, within
from .neighbours import find_neighbours as _find_all
from .obstacles import nearest, sight_blocked
from .world import FOOD, NEST

#: Tries per robot to draw a clear initial position before the setup is refused.
PLACEMENT_TRIES = 10_000


def site_arrays(cfg) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every site as (centres [S, 2], radii [S], kinds [S]): food sites first, then nests, file order."""
    sites = [(s, FOOD) for s in cfg.sites("food")] + [(s, NEST) for s in cfg.sites("nest")]
    return (np.array([[s.x, s.y] for s, _ in sites], dtype=np.float64),
            np.array([s.radius for s, _ in sites], dtype=np.float64),
            np.array([k for _, k in sites], dtype=np.int64))


def place_clear(world, rng: np.random.Generator) -> None:
    """Redraw (uniform whole numbers, as the first draw) the initial position of every robot whose disc
    overlaps an obstacle or, with collisions, a robot placed before it; in id order, after all other
    initial draws, so nothing else about the initial state changes."""
    r = world.radius
    lo, hi_x, hi_y = math.ceil(r), math.floor(world.width - 1 - r), math.floor(world.height - 1 - r)
    pos = world.pos
    for i in range(pos.shape[0]):
        for _ in range(PLACEMENT_TRIES):
            x, y = pos[i]
            clear = nearest(world.obs_kind, world.obs_geom, x, y) >= r
            if clear and world.collisions and i:
                d2 = ((pos[:i] - pos[i]) ** 2).sum(axis=1)
                clear = bool((d2 >= 4 * r * r).all())
            if clear:
                break
            pos[i, 0] = rng.integers(lo, hi_x, endpoint=True)
            pos[i, 1] = rng.integers(lo, hi_y, endpoint=True)
        else:
            raise ConfigError(f"cannot place robot {i} clear of obstacles{' and other robots' if world.collisions else ''}"
                              f" after {PLACEMENT_TRIES} tries: the arena has too little free space")


@njit
def find_neighbours(w):
    """Neighbours as on the plane, then, with line of sight, pairs whose straight line an obstacle cuts
    are dropped (lists stay in increasing id order).  Lists that overflowed are left alone: the step
    does not begin (``has_room``) and runs this again after the host grows them."""
    _find_all(w)
    if not w.line_of_sight or w.obs_kind.shape[0] == 0:
        return
    nbr = w.nbr
    nbr_count = w.nbr_count
    n = nbr_count.shape[0]
    for i in range(n):
        if nbr_count[i] > nbr.shape[1]:
            return
    pos = w.pos
    for i in range(n):
        c = 0
        for a in range(nbr_count[i]):
            j = nbr[i, a]
            lo = min(i, j)  # the same arithmetic for (i, j) and (j, i): the relation stays symmetric
            hi = max(i, j)
            if not sight_blocked(w.obs_kind, w.obs_geom, pos[lo, 0], pos[lo, 1], pos[hi, 0], pos[hi, 1]):
                nbr[i, c] = j
                c += 1
        nbr_count[i] = c


@njit(inline="always")
def containing_site(w, x, y, kind):
    """The first site of ``kind`` (file order) that (x, y) lies strictly inside, else -1."""
    for s in range(w.sites_r.shape[0]):
        if w.sites_kind[s] == kind and within(x, y, w.sites_xy[s, 0], w.sites_xy[s, 1], w.sites_r[s]):
            return s
    return -1


@njit(inline="always")
def forage(w, i, rng):
    """Pick-up and drop spots at whichever site of the needed kind the robot is in (MODEL.md §6, per
    site).  Returns True when robot i deposits an item this step."""
    x = w.pos[i, 0]
    y = w.pos[i, 1]
    kind = NEST if w.carrying[i] else FOOD
    s = containing_site(w, x, y, kind)
    if s >= 0 and not (w.has_spot[i, kind] and w.spot_site[i, kind] == s):
        a = uniform(rng) * 2.0 * math.pi
        rr = w.sites_r[s] * math.sqrt(uniform(rng))
        w.spot[i, kind, 0] = w.sites_xy[s, 0] + rr * math.cos(a)
        w.spot[i, kind, 1] = w.sites_xy[s, 1] + rr * math.sin(a)
        w.has_spot[i, kind] = True
        w.spot_site[i, kind] = s
    if not (w.has_spot[i, kind] and within(x, y, w.spot[i, kind, 0], w.spot[i, kind, 1], w.radius)):
        return False
    w.has_spot[i, kind] = False
    counted = w.clock[0] >= w.transitory
    if counted:
        w.site_items[w.spot_site[i, kind]] += 1
    if kind == FOOD:
        w.carrying[i] = True
        return False
    w.carrying[i] = False
    if counted:
        w.items[i] += 1
    return True


@njit(inline="always")
def sense_sites(w, i):
    """Like the plane's: for each kind, the first site containing the robot sets that kind's entry to
    its target point there (its spot if the spot lies in that site, else the centre)."""
    x = w.pos[i, 0]
    y = w.pos[i, 1]
    for k in range(2):
        s = containing_site(w, x, y, k)
        if s < 0:
            continue
        if w.has_spot[i, k] and w.spot_site[i, k] == s:
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


@njit(inline="always")
def probe(w, i, x, y):
    """A proximity sensor of robot i: would a disc centred at (x, y) leave the arena or touch an
    obstacle (or, with ``sense_robots``, another robot's disc: centres at most 2 r apart)?"""
    if outside(x, y, w.radius, w.width, w.height):
        return True
    if nearest(w.obs_kind, w.obs_geom, x, y) <= w.radius:
        return True
    if w.sense_robots:
        pos = w.pos
        d2 = 4.0 * w.radius * w.radius
        for j in range(pos.shape[0]):
            if j != i:
                ex = pos[j, 0] - x
                ey = pos[j, 1] - y
                if ex * ex + ey * ey <= d2:
                    return True
    return False


@njit(inline="always")
def sensors(w, i):
    """FRONT, RIGHT, BACK, LEFT (MODEL.md §3) with obstacles sensed like the arena's walls."""
    x = w.pos[i, 0]
    y = w.pos[i, 1]
    c = w.speed * w.hdir[i, 0]
    s = w.speed * w.hdir[i, 1]
    return (probe(w, i, x + c, y + s), probe(w, i, x + s, y - c), probe(w, i, x - c, y - s),
            probe(w, i, x - s, y + c))


@njit(inline="always")
def behaviour_step(w, i, rng):
    """The plane's behaviour step (kernels.behaviour_step) with obstacle-aware sensors and every site."""
    front, right, back, left = sensors(w, i)
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
def blocked(w, i, x, y):
    """Would robot i's disc at (x, y) overlap an obstacle or (with collisions) another robot?"""
    r = w.radius
    if nearest(w.obs_kind, w.obs_geom, x, y) < r:
        return True
    if w.collisions:
        pos = w.pos
        d2 = 4.0 * r * r
        for j in range(pos.shape[0]):
            if j != i:
                ex = pos[j, 0] - x
                ey = pos[j, 1] - y
                if ex * ex + ey * ey < d2:
                    return True
    return False


@njit(inline="always")
def move(w, i, dx, dy, rng):
    """The plane's noisy move (kernels.move), not made when its end point is blocked (see above)."""
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
    if not blocked(w, i, x, y):
        w.pos[i, 0] = x
        w.pos[i, 1] = y
