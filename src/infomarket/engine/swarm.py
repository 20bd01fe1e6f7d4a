"""The swarm's state: every robot's pose, odometry, navigation table, offers, pending purchases, spots,
timers, neighbours, outcome records and provenance; its builder (the initial draws of docs/model.md §1) and its growth.

Written by the engine's step; a buy rule writes only its own robot's ``new_*`` table and pending list,
through ``behaviours.api``.  Nothing is [n, n]: ``kn`` neighbour and ``kp`` pending slots per robot, grown
by the host between steps when the kernel asks for room (``grow_swarm``), and ``kt`` = ``TRUST_SLOTS`` outcome
records per robot (the sellers it has judged by its trips, ``api.trust_add``), a fixed number so that a
large swarm pays ``n * kt``, not ``n * n``.  ``origin`` is the provenance a buy rule may record of its own
entries (``api.origin_set``), which buyers read as the origin of that robot's offers (``api.origin_of``).
"""
from __future__ import annotations

import math

import numpy as np

from ..config.schema import Experiment
from ..state.spec import Spec, fields

#: Most points a waypoint path holds, the first one (the table entry itself) included.
PATH_POINTS = 4
#: First neighbour and pending capacities.
NEIGHBOUR_CAPACITY = 8
PENDING_CAPACITY = 4
#: Sellers a robot keeps an outcome record for (``api.trust_add`` forgets the least-judged one beyond it).
TRUST_SLOTS = 16

# Robot states.
EXPLORING = 0
SEEKING_FOOD = 1
SEEKING_NEST = 2
STATE_NAMES = ("exploring", "seeking_food", "seeking_nest")

SPEC = Spec("swarm", fields("engine", [
    ("pos", "float64", "n,2", "true positions"),
    ("hdir", "float64", "n,2", "unit vector of the true heading (no angle is kept; ``headings`` gives degrees)"),
    ("bias", "float64", "n", "odometry bias mu_i, degrees per step"),
    ("kind", "int64", "n", "behaviour index (``params.behaviour_kinds``)"),
    ("state", "int64", "n", "EXPLORING / SEEKING_FOOD / SEEKING_NEST"),
    ("carrying", "bool", "n", "carrying an item"),
    ("levy", "int64", "n", "random-walk steps left before the next turn"),
    ("tab_vec", "float64", "n,2,2", "navigation table (robot frame) at the start of the step: what sellers sell"),
    ("tab_age", "int64", "n,2", "age of each entry, steps"),
    ("tab_valid", "bool", "n,2", "entry known"),
    ("new_vec", "float64", "n,2,2", "the table being bought into during the communication phase"),
    ("new_age", "int64", "n,2", "its ages"),
    ("new_valid", "bool", "n,2", "its validity"),
    ("off_vec", "float64", "n,2,2", "this step's offers (seller frame)"),
    ("off_age", "int64", "n,2", "their ages"),
    ("off_valid", "bool", "n,2", "offered"),
    ("pend_vec", "float64", "n,2,kp,2", "pending (unconfirmed) purchases per site, robot frame, aged like entries"),
    ("pend_age", "int64", "n,2,kp", "their ages"),
    ("pend_seller", "int64", "n,2,kp", "their sellers"),
    ("pend_count", "int64", "n,2", "pending purchases per site"),
    ("spot", "float64", "n,2,2", "pick-up / drop spot per kind of site"),
    ("has_spot", "bool", "n,2", "spot drawn"),
    ("spot_site", "int64", "n,2", "the site (index into sites_*) each spot lies in"),
    ("last_site", "int64", "n", "kind of the last site sensed (-1 none)"),
    ("items", "int64", "n", "items deposited after the transitory period"),
    ("stop_timer", "int64", "n", "steps left standing still after a trade"),
    ("cool_timer", "int64", "n", "steps left before trading again"),
    ("nbr", "int64", "n,kn", "neighbours in increasing id order (a count above kn asks for room)"),
    ("nbr_count", "int64", "n", "neighbours"),
    ("cell_start", "int64", "cells+1", "the neighbour grid, rebuilt every step"),
    ("cell_items", "int64", "n", "robots sorted by grid cell"),
    ("blocked", "bool", "n,2", "bumped into something seeking that site since last there (path step)"),
    ("path_vec", "float64", "n,2,PATH_POINTS-1,2", "further waypoints after the entry (robot frame; the last "
                                                   "is the site), start-of-step copy"),
    ("path_count", "int64", "n,2", "further waypoints held (0: a plain vector)"),
    ("new_path_vec", "float64", "n,2,PATH_POINTS-1,2", "the path being bought into"),
    ("new_path_count", "int64", "n,2", "its waypoints"),
    ("trust_seller", "int64", "n,kt", "sellers the robot keeps an outcome record for (-1: free slot)"),
    ("trust_good", "float64", "n,kt", "their trips that reached the site (written by buy rules, ``api.trust_add``)"),
    ("trust_bad", "float64", "n,kt", "their trips that found nothing there"),
    ("trust_due", "float64", "n,kt", "of those, the ones since the robot's round trip was last settled (a "
                                     "payment rule may charge them, ``api.trust_record``)"),
    ("origin", "int64", "n,2,3", "per site: the robot its entry's information came from, the entry's age and the "
                                 "step when its buy rule recorded them (-1: none; ``api.origin_set``)"),
]))


def build_swarm(cfg: Experiment, rng: np.random.Generator, kind: np.ndarray, cells: int) -> dict:
    """A fresh swarm: uniform whole-number positions, uniform headings, bimodal odometry biases (drawn
    in that order from ``rng``), empty tables; ``kind`` from ``params.behaviour_table``."""
    n = cfg.swarm.robots
    r = cfg.robot.radius
    w_, h_ = cfg.arena.width, cfg.arena.height
    pos = np.empty((n, 2))
    pos[:, 0] = rng.integers(math.ceil(r), math.floor(w_ - 1 - r), size=n, endpoint=True)
    pos[:, 1] = rng.integers(math.ceil(r), math.floor(h_ - 1 - r), size=n, endpoint=True)
    heading = rng.uniform(0.0, 360.0, size=n)
    bias = rng.normal(cfg.robot.bias_mean, cfg.robot.bias_sd, size=n)
    bias *= np.where(rng.random(n) < 0.5, -1.0, 1.0)
    kn, kp = NEIGHBOUR_CAPACITY, PENDING_CAPACITY
    z = np.zeros
    swarm = {
        "pos": pos, "hdir": np.stack([np.cos(np.radians(heading)), np.sin(np.radians(heading))], axis=1),
        "bias": bias, "kind": kind, "state": z(n, np.int64), "carrying": z(n, np.bool_), "levy": np.ones(n, np.int64),
        "tab_vec": z((n, 2, 2)), "tab_age": z((n, 2), np.int64), "tab_valid": z((n, 2), np.bool_),
        "new_vec": z((n, 2, 2)), "new_age": z((n, 2), np.int64), "new_valid": z((n, 2), np.bool_),
        "off_vec": z((n, 2, 2)), "off_age": z((n, 2), np.int64), "off_valid": z((n, 2), np.bool_),
        "pend_vec": z((n, 2, kp, 2)), "pend_age": z((n, 2, kp), np.int64), "pend_seller": z((n, 2, kp), np.int64),
        "pend_count": z((n, 2), np.int64),
        "spot": z((n, 2, 2)), "has_spot": z((n, 2), np.bool_), "spot_site": z((n, 2), np.int64),
        "last_site": np.full(n, -1, np.int64), "items": z(n, np.int64), "stop_timer": z(n, np.int64),
        "cool_timer": z(n, np.int64), "nbr": z((n, kn), np.int64), "nbr_count": z(n, np.int64),
        "cell_start": z(cells + 1, np.int64), "cell_items": z(n, np.int64),
        "blocked": z((n, 2), np.bool_), "path_vec": z((n, 2, PATH_POINTS - 1, 2)), "path_count": z((n, 2), np.int64),
        "new_path_vec": z((n, 2, PATH_POINTS - 1, 2)), "new_path_count": z((n, 2), np.int64),
        "trust_seller": np.full((n, TRUST_SLOTS), -1, np.int64), "trust_good": z((n, TRUST_SLOTS)),
        "trust_bad": z((n, TRUST_SLOTS)), "trust_due": z((n, TRUST_SLOTS)), "origin": np.full((n, 2, 3), -1, np.int64),
    }
    SPEC.check(swarm)
    return swarm


def _grown(old: np.ndarray, axis: int, size: int) -> np.ndarray:
    shape = list(old.shape)
    shape[axis] = size
    new = np.zeros(shape, old.dtype)
    new[tuple(slice(0, k) for k in old.shape)] = old
    return new


def grow_swarm(swarm) -> dict:
    """Replacement arrays (field -> array) so the next step fits: neighbour lists to the largest count and
    pending lists to the largest count plus one purchase per neighbour, with headroom, at least doubling
    (amortised).  ``swarm``: any object with the swarm's fields.  Empty when nothing is short."""
    nbr = swarm.nbr_count
    changes = {}
    kn = swarm.nbr.shape[1]
    need_n = int(nbr.max(initial=0))
    if need_n > kn:
        changes["nbr"] = np.zeros((nbr.shape[0], max(2 * kn, need_n + 4)), np.int64)
    kp = swarm.pend_seller.shape[2]
    need_p = int((swarm.pend_count + nbr[:, None]).max(initial=0))
    if need_p > kp:
        size = max(2 * kp, need_p + 4)
        for f in ("pend_vec", "pend_age", "pend_seller"):
            changes[f] = _grown(getattr(swarm, f), 2, size)
    return changes
