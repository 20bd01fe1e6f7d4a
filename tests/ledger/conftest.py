"""The chain tests' small runs are checked after every step: ``Simulation.step`` on a chain world steps
one at a time and runs ``ledger.poa.invariants.check_invariants`` after each (a broken invariant fails
the test that broke it).  Long runs (``Simulation.run``, the digests) are left alone."""
from __future__ import annotations

import pytest

from infomarket.engine.simulation import Simulation
from infomarket.engine.world import ChainWorld
from infomarket.ledger.poa.invariants import check_invariants

_step = Simulation.step


def checked_step(sim, k: int = 1) -> None:
    """``sim.step(k)``, checking the chain's invariants after each of the k steps."""
    if not isinstance(sim.world, ChainWorld):
        return _step(sim, k)
    for _ in range(k):
        _step(sim, 1)
        check_invariants(sim.world)


@pytest.fixture(autouse=True)
def _chain_invariants_every_step(request, monkeypatch):
    if request.module.__name__.rsplit(".", 1)[-1].startswith("test_chain"):
        monkeypatch.setattr(Simulation, "step", checked_step)
