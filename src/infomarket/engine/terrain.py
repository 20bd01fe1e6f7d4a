"""Terrain: obstacles, several sites of a kind, line of sight and collisions: the rules, and the helpers
the step's ``terrain`` variant calls (``engine.step``).

Setups on the paper's plane never run this code: their kernel is compiled with ``terrain`` off, so the
branches that call these helpers are folded away and the paper's kernel is the one it always was.

Rules (docs/terrain.md says the same for users):

* **Sensing and reflection.**  The four proximity sensors fire when a move of ``v`` towards heading,
  heading - 90, heading + 180, heading + 90 would put the robot's disc outside the arena *or* touching
  an obstacle (distance from the probed centre to it at most ``r``); the reflection rule and the
  "FRONT while seeking invalidates the entry" rule are the model's, unchanged (docs/model.md §3).
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

from ..jit import njit

from ..errors import ConfigError
from ..space.obstacles import nearest, sight_blocked
from .geometry import outside, within

#: Tries per robot to draw a clear initial position before the setup is refused.
PLACEMENT_TRIES = 10_000


def place_clear(world, rng) -> None:
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
            others = " and other robots" if world.collisions else ""
            raise ConfigError(f"cannot place robot {i} clear of obstacles{others}"
                              f" after {PLACEMENT_TRIES} tries: the arena has too little free space")


@njit(cache=True)
def drop_hidden_pairs(w):
    """With line of sight, drop the neighbour pairs whose straight line an obstacle cuts (lists stay in
    increasing id order).  Lists that overflowed are left alone: the step does not begin (``has_room``)
    and runs this again after the host grows them."""
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


@njit(forceinline=True, cache=True)
def containing_site(w, x, y, kind):
    """The first site of ``kind`` (file order) that (x, y) lies strictly inside, else -1."""
    for s in range(w.sites_r.shape[0]):
        if w.sites_kind[s] == kind and within(x, y, w.sites_xy[s, 0], w.sites_xy[s, 1], w.sites_r[s]):
            return s
    return -1


@njit(forceinline=True, cache=True)
def obstructed(w, i, x, y):
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


@njit(forceinline=True, cache=True)
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
