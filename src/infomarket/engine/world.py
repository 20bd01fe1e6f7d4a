"""The world: the four domains of a run's state side by side, as the compiled step sees them.

Each domain has its own spec (fields, shapes, dtypes, who writes them), builder and growth function:

================  ======================  ===================================================
domain            spec and builder        written by
================  ======================  ===================================================
parameters        ``engine.params``       nobody during a run (read-only in compiled code)
swarm             ``engine.swarm``        the engine's step; buy rules through ``behaviours.api``
ledger            ``ledger.state``        ledger operations only (``ledger.kernels``)
log               ``state.log``           the engine's loop and log writes, ledger operations
================  ======================  ===================================================

The compiled step receives one flat view of all of them (``World``, one pointer: ``state.view``), in
which the writer of each field decides its type: a rule that writes a parameter, a balance or a log
array does not compile.  ``python -c "from infomarket.engine.world import describe; print(describe())"``
prints every field.
"""
from __future__ import annotations

from collections import namedtuple
from typing import TYPE_CHECKING, Any, TypeAlias

import numpy as np

from ..ledger.poa import spec as chain_state
from ..ledger import state as ledger_state
from ..state import log as log_state
from ..state.view import make_view, register_layout
from . import params, swarm
from .params import FOOD, NEST, SITE_NAMES  # noqa: F401  (re-exported: one place to import the codes from)
from .swarm import EXPLORING, PATH_POINTS, SEEKING_FOOD, SEEKING_NEST, STATE_NAMES  # noqa: F401 - re-exported with the site codes
from ..ledger.state import REPUTATION, TX_POOL  # noqa: F401 - re-exported with the site codes
from ..state.log import EV_DEPOSIT, EV_PURCHASE, EV_REFUSED, EVENT_NAMES  # noqa: F401 - re-exported with the site codes

#: The domains of the flat world, in order.
DOMAINS = (params.SPEC, swarm.SPEC, ledger_state.SPEC, log_state.SPEC)
register_layout("world", DOMAINS)
#: A chain model's world (docs/chain-model.md): the same domains and the chain's (``ledger.poa``).
#: A separate layout, so the paper's world type (and every kernel compiled for it) has none of its fields.
CHAIN_DOMAINS = DOMAINS + (chain_state.SPEC,)
register_layout("chainworld", CHAIN_DOMAINS)
if TYPE_CHECKING:  # their fields are made from the domains' specs at import, which a type checker cannot read
    World: TypeAlias = Any
    ChainWorld: TypeAlias = Any
else:
    World = namedtuple("World", tuple(name for spec in DOMAINS for name in spec.names))
    ChainWorld = namedtuple("ChainWorld", tuple(name for spec in CHAIN_DOMAINS for name in spec.names))

#: Field names by writer (``state.spec``).
PARAMS = tuple(f.name for spec in CHAIN_DOMAINS for f in spec if f.writer == "host")
ROBOTS = swarm.SPEC.names
LEDGER = tuple(f.name for spec in (ledger_state.SPEC, chain_state.SPEC) for f in spec if f.writer == "ledger")
LOG = tuple(f.name for spec in (log_state.SPEC, chain_state.SPEC) for f in spec if f.writer == "log")


def kernel_view(world: World):
    """What to pass to the compiled kernels for this world (valid while ``world`` lives)."""
    return make_view("chainworld" if isinstance(world, ChainWorld) else "world", world)


def describe() -> str:
    """Every field of the world, domain by domain (markdown)."""
    return "\n\n".join(f"### {spec.domain}\n\n{spec.table()}" for spec in CHAIN_DOMAINS)


def headings(world: World) -> np.ndarray:
    """Each robot's true heading in degrees, [0, 360) (the state keeps only its unit vector)."""
    return np.degrees(np.arctan2(world.hdir[:, 1], world.hdir[:, 0])) % 360.0


def open_transactions(world, buyer: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Buyer's open transactions (sellers, sites, directions in degrees), oldest first (copies)."""
    a = int(world.tx_off[buyer])
    b = a + int(world.tx_count[buyer])
    return world.tx_seller[a:b].copy(), world.tx_site[a:b].copy(), world.tx_dir[a:b].copy()
