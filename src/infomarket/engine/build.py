"""Build a run's world from an experiment (docs/model.md §1), and grow it between steps.

Each domain builds and grows itself (``engine.params``, ``engine.swarm``, ``ledger.state``,
``state.log``); this module only puts them side by side in the flat ``World``.
"""
from __future__ import annotations

import numpy as np

from ..config.schema import Experiment
from ..ledger.state import grow_ledger, ledger_of
from ..state.log import build_log, grow_log
from .params import behaviour_kinds, behaviour_table, build_params  # noqa: F401  (behaviour_kinds re-exported)
from .swarm import build_swarm, grow_swarm
from .terrain import place_clear
from .world import World


def build_world(cfg: Experiment, rng: np.random.Generator, *, record_events: bool = False,
                history_every: int = 0) -> tuple[World, list[str]]:
    """A fresh world: robots in group order (ids follow the groups), uniform integer positions,
    uniform headings, bimodal odometry biases, empty tables, initial wealth; and each robot's behaviour."""
    kind, bparams, names = behaviour_table(cfg)
    params = build_params(cfg, bparams)
    swarm = build_swarm(cfg, rng, kind, params["grid_nx"] * params["grid_ny"])
    log = build_log(cfg.swarm.robots, record_events=record_events, history_every=history_every,
                    history_rows=cfg.steps // history_every if history_every else 0,
                    sites=len(params["sites_r"]))
    world = World(**params, **swarm, **ledger_of(cfg), **log)
    if cfg.terrain:
        place_clear(world, rng)
    return world, names


def make_room(world: World, tx_need: np.ndarray | None = None) -> World:
    """Grow whatever the next step might outgrow (the kernel's ``has_room`` said something would):
    neighbour and pending lists, the transaction pool, the event and payment logs.  ``tx_need``
    overrides each buyer's transaction need (default: open ones + 2 per neighbour)."""
    nbr = world.nbr_count
    changes = grow_swarm(world)
    need_t = world.tx_count + 2 * nbr if tx_need is None else tx_need
    changes.update(grow_ledger(world, need_t))
    if world.record:
        events = int(world.ev_count[0]) + world.pos.shape[0] + 2 * int(nbr.sum())
        changes.update(grow_log(world, events, int(world.pay_count[0]) + int(need_t.sum())))
    return world._replace(**changes)
