"""The simulation engine.

State as arrays, split by domain (``params``, ``swarm``; with ``ledger.state`` and ``state.log`` side by
side in ``world``), built by ``build``; one step written once (``step``, with ``terrain`` and ``paths``
helpers), looped by ``loop_template`` specialised to the configured rules by ``specialise``; the host
that drives it is ``simulation``.
"""
from .simulation import Result, Simulation, simulate

__all__ = ["Result", "Simulation", "simulate"]
