"""Allocate a World for an experiment and draw its initial state (MODEL.md §1)."""
from __future__ import annotations

import math

import numpy as np

from ..config.schema import Experiment
from ..registry import behaviours
from .world import World

TX_CAPACITY = 64
EVENT_CAPACITY = 4096


def cauchy_cdf(rho: float) -> np.ndarray:
    """CDF of the wrapped Cauchy turning angle (eq. 2) on whole degrees 0..359."""
    phi = np.arange(360) * math.pi / 180.0
    f = (1 - rho**2) / (2 * math.pi * (1 + rho**2 - 2 * rho * np.cos(phi)))
    cdf = np.cumsum(f / f.sum())
    cdf[-1] = 1.0
    return cdf


def levy_cdf(alpha: float, steps: int) -> np.ndarray:
    """CDF of Lévy step lengths (eq. 3), P(k) ∝ k^-(alpha+1) for k = 1..steps+1 (index k-1)."""
    k = np.arange(1, steps + 2, dtype=np.float64)
    p = k ** -(alpha + 1.0)
    cdf = np.cumsum(p / p.sum())
    cdf[-1] = 1.0
    return cdf


def guide_table(cdf: np.ndarray) -> np.ndarray:
    """For u in [j/M, (j+1)/M): the answer of inverse-CDF sampling is at least ``guide[j]`` (M = len(cdf)),
    the first index whose cumulative probability exceeds j/M."""
    m = len(cdf)
    return np.searchsorted(cdf, np.arange(m) / m, side="right").astype(np.int64)


def behaviour_kinds(cfg: Experiment) -> tuple[str, ...]:
    """Distinct behaviours in order of first appearance: a robot's ``kind`` indexes this tuple."""
    names: list[str] = []
    for g in cfg.swarm.groups:
        if g.count and g.behaviour not in names:
            names.append(g.behaviour)
    return tuple(names)


def build_world(cfg: Experiment, rng: np.random.Generator, *, record_events: bool = False,
                history_every: int = 0) -> tuple[World, list[str]]:
    """A fresh world: robots in group order (ids follow the groups), uniform integer positions,
    uniform headings, bimodal odometry biases, empty tables, initial wealth."""
    n = cfg.swarm.robots
    kinds = behaviour_kinds(cfg)
    specs = behaviours()
    n_par = max([len(specs[b].params) for b in kinds] + [1])
    kind = np.empty(n, np.int64)
    bparams = np.zeros((n, n_par))
    names: list[str] = []
    start = 0
    for g in cfg.swarm.groups:
        if g.count == 0:
            continue
        kind[start:start + g.count] = kinds.index(g.behaviour)
        values = list(cfg.behaviour_params(g).values())
        bparams[start:start + g.count, :len(values)] = values
        names += [g.behaviour] * g.count
        start += g.count
    pparams = np.array(list(cfg.payment_params().values()) or [0.0], dtype=np.float64)

    r = cfg.robot.radius
    w_, h_ = cfg.arena.width, cfg.arena.height
    pos = np.empty((n, 2))
    pos[:, 0] = rng.integers(math.ceil(r), math.floor(w_ - 1 - r), size=n, endpoint=True)
    pos[:, 1] = rng.integers(math.ceil(r), math.floor(h_ - 1 - r), size=n, endpoint=True)
    heading = rng.uniform(0.0, 360.0, size=n)
    bias = rng.normal(cfg.robot.bias_mean, cfg.robot.bias_sd, size=n)
    bias *= np.where(rng.random(n) < 0.5, -1.0, 1.0)

    cauchy = cauchy_cdf(cfg.random_walk.rho)
    levy = levy_cdf(cfg.random_walk.alpha, cfg.steps)
    hist_rows = cfg.steps // history_every if history_every else 0
    ecap = EVENT_CAPACITY if record_events else 0
    z = np.zeros
    world = World(
        width=float(w_), height=float(h_), radius=float(r), speed=float(cfg.robot.speed),
        comm_range=float(cfg.robot.communication_range), noise_sd=float(cfg.robot.noise_sd),
        site_pos=np.array([[cfg.food.x, cfg.food.y], [cfg.nest.x, cfg.nest.y]], dtype=np.float64),
        site_r=np.array([cfg.food.radius, cfg.nest.radius], dtype=np.float64),
        reward=float(cfg.payment.reward), info_share=float(cfg.payment.information_share),
        stake=float(cfg.payment.stake), fuel_cost=float(cfg.robot.fuel_cost),
        transitory=int(cfg.transitory), stop_time=int(cfg.robot.stop_time), cooldown=int(cfg.robot.cooldown),
        cauchy_cdf=cauchy, cauchy_guide=guide_table(cauchy), levy_cdf=levy, levy_guide=guide_table(levy),
        bparams=bparams, pparams=pparams, record=bool(record_events), hist_every=int(history_every),
        clock=z(1, np.int64), pos=pos, heading=heading,
        hdir=np.stack([np.cos(np.radians(heading)), np.sin(np.radians(heading))], axis=1), bias=bias, kind=kind,
        state=z(n, np.int64), carrying=z(n, np.bool_), levy=np.ones(n, np.int64),
        tab_vec=z((n, 2, 2)), tab_age=z((n, 2), np.int64), tab_valid=z((n, 2), np.bool_),
        new_vec=z((n, 2, 2)), new_age=z((n, 2), np.int64), new_valid=z((n, 2), np.bool_),
        off_vec=z((n, 2, 2)), off_age=z((n, 2), np.int64), off_valid=z((n, 2), np.bool_),
        pend_vec=z((n, 2, n, 2)), pend_age=z((n, 2, n), np.int64), pend_seller=z((n, 2, n), np.int64),
        pend_count=z((n, 2), np.int64),
        spot=z((n, 2, 2)), has_spot=z((n, 2), np.bool_), last_site=np.full(n, -1, np.int64),
        items=z(n, np.int64), balance=np.full(n, float(cfg.payment.initial_wealth)), pot=z(n),
        burned=z(1),
        tx_seller=z((n, TX_CAPACITY), np.int64), tx_site=z((n, TX_CAPACITY), np.int64),
        tx_dir=z((n, TX_CAPACITY)), tx_count=z(n, np.int64),
        nbr=z((n, n), np.int64), nbr_count=z(n, np.int64),
        stop_timer=z(n, np.int64), cool_timer=z(n, np.int64),
        ev_step=z(ecap, np.int64), ev_kind=z(ecap, np.int64), ev_buyer=z(ecap, np.int64),
        ev_seller=z(ecap, np.int64), ev_site=z(ecap, np.int64), ev_dir=z(ecap), ev_x=z(ecap), ev_y=z(ecap),
        ev_age=z(ecap, np.int64), ev_stake=z(ecap), ev_sx=z(ecap), ev_sy=z(ecap), ev_count=z(1, np.int64),
        hist=z((hist_rows, n)), flags=z(1, np.int64),
    )
    return world, names


def grow(world: World) -> World:
    """Double the per-buyer transaction capacity and the event log where a step might not fit."""
    n = world.pos.shape[0]
    changes = {}
    cap = world.tx_seller.shape[1]
    if int(world.tx_count.max(initial=0)) + 2 * n > cap:
        new = max(2 * cap, int(world.tx_count.max()) + 4 * n)
        for f in ("tx_seller", "tx_site", "tx_dir"):
            old = getattr(world, f)
            arr = np.zeros((n, new), old.dtype)
            arr[:, :cap] = old
            changes[f] = arr
    ecap = world.ev_step.shape[0]
    if world.record and int(world.ev_count[0]) + 2 * n * n + n > ecap:
        new = max(2 * ecap, int(world.ev_count[0]) + 4 * n * n + 2 * n)
        for f in [f for f in world._fields if f.startswith("ev_") and f != "ev_count"]:
            old = getattr(world, f)
            arr = np.zeros(new, old.dtype)
            arr[:ecap] = old
            changes[f] = arr
    return world._replace(**changes)
