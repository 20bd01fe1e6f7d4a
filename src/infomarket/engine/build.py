"""Allocate a World for an experiment and draw its initial state (MODEL.md §1)."""
from __future__ import annotations

import math

import numpy as np

from ..config.schema import Experiment
from ..registry import behaviours
from .kernels import turn_tables
from . import obstacles
from .neighbours import grid_shape
from .terrain import place_clear, site_arrays
from .world import LOG, PATH_POINTS, TX_POOL, World

#: First capacities; the host grows each when the kernel asks for room (``make_room``).
NEIGHBOUR_CAPACITY = 8
PENDING_CAPACITY = 4
TX_CAPACITY = 16
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
    turn_cos, turn_sin = turn_tables()
    rc = float(cfg.robot.communication_range)
    cell, nx, ny = grid_shape(float(w_), float(h_), rc, n)
    hist_rows = cfg.steps // history_every if history_every else 0
    ecap = EVENT_CAPACITY if record_events else 0
    kn, kp, kt = NEIGHBOUR_CAPACITY, PENDING_CAPACITY, TX_CAPACITY
    z = np.zeros
    f, h = cfg.sites("food")[0], cfg.sites("nest")[0]
    sites_xy, sites_r, sites_kind = site_arrays(cfg)
    obs_kind, obs_geom = obstacles.encode(cfg.obstacles)
    world = World(
        width=float(w_), height=float(h_), radius=float(r), speed=float(cfg.robot.speed),
        comm_range=rc, noise_sd=float(cfg.robot.noise_sd),
        site_pos=np.array([[f.x, f.y], [h.x, h.y]], dtype=np.float64),
        site_r=np.array([f.radius, h.radius], dtype=np.float64),
        reward=float(cfg.payment.reward), info_share=float(cfg.payment.information_share),
        stake=float(cfg.payment.stake), stake_expiry=int(cfg.payment.stake_expiry), fuel_cost=float(cfg.robot.fuel_cost),
        transitory=int(cfg.transitory), stop_time=int(cfg.robot.stop_time), cooldown=int(cfg.robot.cooldown),
        cauchy_cdf=cauchy, cauchy_guide=guide_table(cauchy), levy_cdf=levy, levy_guide=guide_table(levy),
        turn_cos=turn_cos, turn_sin=turn_sin,
        bparams=bparams, pparams=pparams, record=bool(record_events), hist_every=int(history_every),
        grid_cell=cell, grid_nx=nx, grid_ny=ny,
        sites_xy=sites_xy, sites_r=sites_r, sites_kind=sites_kind, obs_kind=obs_kind, obs_geom=obs_geom,
        line_of_sight=bool(cfg.robot.line_of_sight), collisions=bool(cfg.robot.collisions),
        sense_robots=bool(cfg.robot.sense_robots),
        clock=z(1, np.int64), pos=pos,
        hdir=np.stack([np.cos(np.radians(heading)), np.sin(np.radians(heading))], axis=1), bias=bias, kind=kind,
        state=z(n, np.int64), carrying=z(n, np.bool_), levy=np.ones(n, np.int64),
        tab_vec=z((n, 2, 2)), tab_age=z((n, 2), np.int64), tab_valid=z((n, 2), np.bool_),
        new_vec=z((n, 2, 2)), new_age=z((n, 2), np.int64), new_valid=z((n, 2), np.bool_),
        off_vec=z((n, 2, 2)), off_age=z((n, 2), np.int64), off_valid=z((n, 2), np.bool_),
        pend_vec=z((n, 2, kp, 2)), pend_age=z((n, 2, kp), np.int64), pend_seller=z((n, 2, kp), np.int64),
        pend_count=z((n, 2), np.int64),
        spot=z((n, 2, 2)), has_spot=z((n, 2), np.bool_), last_site=np.full(n, -1, np.int64),
        items=z(n, np.int64), stop_timer=z(n, np.int64), cool_timer=z(n, np.int64),
        nbr=z((n, kn), np.int64), nbr_count=z(n, np.int64),
        cell_start=z(nx * ny + 1, np.int64), cell_items=z(n, np.int64), spot_site=z((n, 2), np.int64),
        blocked=z((n, 2), np.bool_), path_vec=z((n, 2, PATH_POINTS - 1, 2)), path_count=z((n, 2), np.int64),
        new_path_vec=z((n, 2, PATH_POINTS - 1, 2)), new_path_count=z((n, 2), np.int64),
        balance=np.full(n, float(cfg.payment.initial_wealth)), pot=z(n), burned=z(1),
        tx_off=np.arange(n, dtype=np.int64) * kt, tx_cap=np.full(n, kt, np.int64), tx_count=z(n, np.int64),
        tx_seller=z(n * kt, np.int64), tx_site=z(n * kt, np.int64), tx_dir=z(n * kt),
        tx_step=z(n * kt, np.int64), tx_stake=z(n * kt), pool_top=np.array([n * kt], np.int64),
        money=np.array([n * float(cfg.payment.initial_wealth)]), rep_settled=z(n, np.int64),
        rep_reduced=z(n, np.int64), rep_earned=z(n), rep_stake_lost=z(n), rep_deposits=z(n, np.int64),
        ev_step=z(ecap, np.int64), ev_kind=z(ecap, np.int64), ev_buyer=z(ecap, np.int64),
        ev_seller=z(ecap, np.int64), ev_site=z(ecap, np.int64), ev_dir=z(ecap), ev_x=z(ecap), ev_y=z(ecap),
        ev_age=z(ecap, np.int64), ev_stake=z(ecap), ev_sx=z(ecap), ev_sy=z(ecap), ev_count=z(1, np.int64),
        pay_step=z(ecap, np.int64), pay_buyer=z(ecap, np.int64), pay_seller=z(ecap, np.int64),
        pay_site=z(ecap, np.int64), pay_weight=z(ecap), pay_amount=z(ecap), pay_count=z(1, np.int64),
        hist=z((hist_rows, n)), flags=z(1, np.int64), site_items=z(len(sites_r), np.int64),
    )
    if cfg.terrain:
        place_clear(world, rng)
    return world, names


def _grown(old: np.ndarray, axis: int, size: int) -> np.ndarray:
    shape = list(old.shape)
    shape[axis] = size
    new = np.zeros(shape, old.dtype)
    new[tuple(slice(0, k) for k in old.shape)] = old
    return new


def make_room(world: World, tx_need: np.ndarray | None = None) -> World:
    """Grow whatever the next step might outgrow (the kernel's ``has_room`` said something would):
    neighbour and pending capacities to the largest need with headroom, the transaction pool (its live
    blocks compacted to the front), the event log; capacities at least double, so growth is amortised.
    ``tx_need`` overrides each buyer's transaction need (default: open ones + 2 per neighbour)."""
    n = world.pos.shape[0]
    nbr = world.nbr_count
    need_n = int(nbr.max(initial=0))
    changes = {}
    kn = world.nbr.shape[1]
    if need_n > kn:
        changes["nbr"] = np.zeros((n, max(2 * kn, need_n + 4)), np.int64)
    kp = world.pend_seller.shape[2]
    need_p = int((world.pend_count + nbr[:, None]).max(initial=0))
    if need_p > kp:
        size = max(2 * kp, need_p + 4)
        for f in ("pend_vec", "pend_age", "pend_seller"):
            changes[f] = _grown(getattr(world, f), 2, size)
    need_t = world.tx_count + 2 * nbr if tx_need is None else tx_need
    needy = need_t > world.tx_cap
    if needy.any():
        caps = world.tx_cap.copy()
        caps[needy] = np.maximum(2 * caps[needy], need_t[needy] + 8)
        starts = np.concatenate([[0], np.cumsum(caps)[:-1]]).astype(np.int64)
        size = 2 * int(caps.sum())
        src = _ranges(world.tx_off, world.tx_count)
        dst = _ranges(starts, world.tx_count)
        for f in TX_POOL:
            old = getattr(world, f)
            new = np.zeros(size, old.dtype)
            new[dst] = old[src]
            changes[f] = new
        changes.update(tx_off=starts, tx_cap=caps, pool_top=np.array([int(caps.sum())], np.int64))
    if world.record:
        ecap = world.ev_step.shape[0]
        need_e = int(world.ev_count[0]) + n + 2 * int(nbr.sum())
        if need_e > ecap:
            for f in [f for f in LOG if f.startswith("ev_") and f != "ev_count"]:
                changes[f] = _grown(getattr(world, f), 0, max(2 * ecap, need_e))
        pcap = world.pay_step.shape[0]
        need_pay = int(world.pay_count[0]) + int(need_t.sum())
        if need_pay > pcap:
            for f in [f for f in LOG if f.startswith("pay_") and f != "pay_count"]:
                changes[f] = _grown(getattr(world, f), 0, max(2 * pcap, need_pay))
    return world._replace(**changes)


def _ranges(starts: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """Concatenated index ranges starts[i] .. starts[i] + counts[i] - 1."""
    total = int(counts.sum())
    if total == 0:
        return np.zeros(0, np.int64)
    offsets = np.repeat(starts - np.concatenate([[0], np.cumsum(counts)[:-1]]), counts)
    return np.arange(total, dtype=np.int64) + offsets
