"""Replay a ledger event sequence through the engine's own compiled ledger code.

Used by the conformance tests (``payment_vectors.json``) and to check the EVM contract against the
simulation: both feed the same purchases and deposits and compare balances.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterable

import numpy as np

from ..config.schema import Experiment
from ..engine import specialise
from ..engine.build import build_world, make_room
from ..engine.flags import ErrorFlags
from ..errors import SimulationError
from ..engine.world import REPUTATION
from ..engine.worldref import kernel_view
from .kernels import expire_stakes, open_transaction, reserve


@dataclass(frozen=True)
class Replayed:
    """Balances and pots after a replay, and whether each purchase was accepted (in order)."""

    balances: np.ndarray
    pots: np.ndarray
    accepted: list[bool]
    #: the ledger's reputation record after the replay (``engine.world.REPUTATION``: field -> copy)
    record: dict = field(default_factory=dict)


@dataclass(frozen=True)
class LedgerEvent:
    """``kind`` is 'purchase' (buyer, seller, site, direction_deg) or 'deposit' (buyer); ``step`` is
    the simulation step it happened in (only the stake-expiry rule reads it)."""

    kind: str
    buyer: int
    seller: int = -1
    site: int = -1
    direction_deg: float = 0.0
    step: int = 0


def replay_events(events: Iterable, robots: int, *, scheme: str = "delayed", initial_wealth: float = 1.0,
                  reward: float = 1.0, information_share: float = 0.5, stake: float = 0.0,
                  params: dict | None = None, stake_expiry: int = 0) -> Replayed:
    """Apply purchases and deposits in order; return the final balances and pots and, per purchase,
    whether it was accepted.  Events are LedgerEvent-like objects or mappings with the same fields
    (a DataFrame's ``itertuples()`` works; 'refused' events are replayed as purchases).

    ``stake_expiry`` = T > 0 applies the stake-expiry rule (docs/chain.md): at the start of each step
    s (before its first event), every open transaction opened at a step t with t + T <= s expires:
    its stake goes back to its seller and it leaves the buyer's round trip."""
    cfg = Experiment.model_validate({
        "swarm": {"robots": robots, "groups": [{"behaviour": "naive", "count": robots}]},
        "payment": {"scheme": scheme, "initial_wealth": initial_wealth, "reward": reward,
                    "information_share": information_share, "stake": stake, "params": params or {},
                    "stake_expiry": int(stake_expiry)},
    })
    rng = np.random.default_rng(0)  # only a rule that asks for one uses it
    world, _ = build_world(cfg, rng)
    kernel = specialise.kernel_module(("naive",), scheme)
    view = kernel_view(world)
    accepted: list[bool] = []
    step = None
    for ev in events:
        get = ev.get if isinstance(ev, dict) else (lambda k, e=ev: getattr(e, k))
        kind = str(get("kind"))
        if stake_expiry:
            now = int(get("step"))
            if step is None or now > step:  # a new step begins: the engine's expiry, then the event
                step = now
                world.clock[0] = step
                for buyer in range(robots):
                    expire_stakes(view, buyer)
        if kind in ("purchase", "refused"):
            buyer = int(get("buyer"))
            while not reserve(view, buyer, int(world.tx_count[buyer]) + 1):
                world = make_room(world, tx_need=world.tx_count + 1)
                view = kernel_view(world)
            accepted.append(bool(open_transaction(view, buyer, int(get("seller")), int(get("site")),
                                                  float(get("direction_deg")))))
        elif kind == "deposit":
            kernel.settle(view, int(get("buyer")), rng)
        else:
            raise ValueError(f"unknown ledger event kind {kind!r}")
        flags = ErrorFlags(int(world.flags[0]))
        if flags:
            raise SimulationError(flags.describe())
    return Replayed(world.balance.copy(), world.pot.copy(), accepted,
                    {f: getattr(world, f).copy() for f in REPUTATION})
