"""Build a run's world from an experiment (docs/model.md §1), and grow it between steps.

Each domain builds and grows itself (``engine.params``, ``engine.swarm``, ``ledger.state``,
``state.log``); this module only puts them side by side in the flat ``World``.
"""
from __future__ import annotations

import numpy as np

from ..config.schema import Experiment
from ..ledger import gas
from ..ledger.poa import arena
from ..ledger.state import grow_ledger, ledger_of
from ..registry import get_payment
from ..state.log import build_log, grow_log
from .params import behaviour_kinds, behaviour_table, build_params  # noqa: F401  (behaviour_kinds re-exported)
from .swarm import build_swarm, grow_swarm
from .terrain import place_clear
from .world import ChainWorld, World, kernel_view


#: Parameter arrays no run writes (the random walk's sampling tables), shared by the worlds built from one
#: ``build_params`` instead of copied: the Lévy tables are 16 bytes per step of the run, for each world.
SHARED_TABLES = frozenset({"levy_cdf", "levy_guide", "cauchy_cdf", "cauchy_guide", "turn_cos", "turn_sin"})


def build_world(cfg: Experiment, rng: np.random.Generator, *, record_events: bool = False,
                history_every: int = 0, kinds: tuple[str, ...] | None = None,
                params: dict | None = None) -> tuple[World, list[str]]:
    """A fresh world: robots in group order (ids follow the groups), uniform integer positions,
    uniform headings, bimodal odometry biases, empty tables, initial wealth; and each robot's behaviour
    (its ``kind`` an index into ``kinds``, the kernel's behaviours; by default the experiment's own).
    ``params``: ``build_params`` of ``cfg`` (with the same ``kinds``) made earlier (its arrays are copied,
    but for the ``SHARED_TABLES``),
    for many runs of one configuration; they draw nothing from ``rng``."""
    kind, bparams, names = behaviour_table(cfg, kinds)
    if params is None:
        params = build_params(cfg, bparams)
    else:
        params = {k: v.copy() if isinstance(v, np.ndarray) and k not in SHARED_TABLES else v for k, v in params.items()}
    swarm = build_swarm(cfg, rng, kind, params["grid_nx"] * params["grid_ny"])
    log = build_log(cfg.swarm.robots, record_events=record_events, history_every=history_every,
                    history_rows=cfg.steps // history_every if history_every else 0,
                    sites=len(params["sites_r"]))
    ledger = ledger_of(cfg)
    if cfg.chain.enabled:
        ledger.update(arena.chain_pool(ledger))
        world = ChainWorld(**params, **swarm, **ledger, **log, **chain_of(cfg, ledger, rng))
    else:
        world = World(**params, **swarm, **ledger, **log)
    if cfg.terrain:
        place_clear(world, rng)
    return world, names


def chain_seed(rng: np.random.Generator) -> int:
    """The chain's own seed (message loss), derived from the run's seed sequence without drawing from
    ``rng``: the swarm's random streams are the same with the chain on or off."""
    seq = rng.bit_generator.seed_seq
    child = np.random.SeedSequence(seq.entropy, spawn_key=tuple(seq.spawn_key) + (0xC4A1,))
    return int(child.generate_state(1, np.uint64)[0] >> np.uint64(1))


def chain_of(cfg: Experiment, ledger: dict, rng: np.random.Generator) -> dict:
    """The chain model's state for a run of ``cfg`` (``ledger.poa``)."""
    c = cfg.chain
    reveal, deposit = gas.gas_schedule(cfg.payment.scheme, cfg.payment.stake)
    rule = get_payment(cfg.payment.scheme).weights  # weights of a list, nothing else: cached per list
    return arena.build_chain(ledger, period=c.period, delay=c.out_of_turn_delay,
                              signers=c.signers or list(range(cfg.swarm.robots)), backbone=c.backbone,
                              latency=c.latency, loss=c.loss, gas_price=c.gas_price, gas_reveal=reveal,
                              gas_table=list(zip(gas.GAS_DEPOSIT_N, deposit)), seed=chain_seed(rng),
                              finality=c.finality, partition=c.partition,
                              cache_weights=not (rule.wants_market or rule.wants_rng))


#: The swarm's pending-purchase lists: their last axis is the room per robot and neighbour slot.
PENDING = ("pend_vec", "pend_age", "pend_seller")


def room_of(world: World, room: dict | None) -> dict | None:
    """The room ``world`` has now (neighbour and pending widths, each buyer's transaction block, the event
    and payment logs), at least ``room``; None for a chain world, which ``with_room`` leaves as built."""
    if isinstance(world, ChainWorld):
        return None
    now = {"nbr": world.nbr.shape[1], "pend": world.pend_seller.shape[2], "tx": world.tx_cap.copy(),
           "events": world.ev_step.shape[0], "payments": world.pay_step.shape[0]}
    if room is None:
        return now
    return {"nbr": max(now["nbr"], room["nbr"]), "pend": max(now["pend"], room["pend"]),
            "tx": np.maximum(now["tx"], room["tx"]) if len(room["tx"]) == len(now["tx"]) else now["tx"],
            "events": max(now["events"], room["events"]), "payments": max(now["payments"], room["payments"])}


def with_room(world: World, room: dict | None) -> World:
    """A freshly built ``world`` with at least the capacities ``room`` records (``room_of`` of earlier runs
    of the same kernel), so the run need not stop to grow them; its values are those of the built world
    (every list empty).  Capacities never change what a run does, only when the host grows them."""
    if room is None or isinstance(world, ChainWorld):
        return world
    n = world.pos.shape[0]
    changes = {}
    if room["nbr"] > world.nbr.shape[1]:
        changes["nbr"] = np.zeros((n, room["nbr"]), world.nbr.dtype)
    if room["pend"] > world.pend_seller.shape[2]:
        for f in PENDING:
            old = getattr(world, f)
            changes[f] = np.zeros(old.shape[:2] + (room["pend"],) + old.shape[3:], old.dtype)
    if len(room["tx"]) == n:  # blocks of at least the recorded size (grow_ledger: max(2 x size, need + 8))
        changes.update(grow_ledger(world, np.maximum(room["tx"] - 8, 0)))
    if world.record:
        changes.update(grow_log(world, room["events"], room["payments"]))
    return world._replace(**changes) if changes else world


def make_room(world: World, tx_need: np.ndarray | None = None) -> World:
    """Grow whatever the next step might outgrow (the kernel's ``has_room`` said something would):
    neighbour and pending lists, the transaction pool, the event and payment logs.  ``tx_need``
    overrides each buyer's transaction need (default: open ones + 2 per neighbour)."""
    nbr = world.nbr_count
    changes = grow_swarm(world)
    if isinstance(world, ChainWorld):  # blocks open transactions: the chain's own bound (ledger.poa.arena)
        needs = arena.chain_needs(kernel_view(world))
        changes.update(arena.grow_chain(world, needs))
        if world.record:
            changes.update(grow_log(world, int(needs[3]), int(needs[4])))
        return world._replace(**changes)
    need_t = world.tx_count + 2 * nbr if tx_need is None else tx_need
    changes.update(grow_ledger(world, need_t))
    if world.record:
        events = int(world.ev_count[0]) + world.pos.shape[0] + 2 * int(nbr.sum())
        changes.update(grow_log(world, events, int(world.pay_count[0]) + int(need_t.sum())))
    return world._replace(**changes)
