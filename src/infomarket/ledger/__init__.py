"""The simulated blockchain: balances, per-buyer open transactions, stakes, and reward sharing.

``ledger.kernels`` holds the compiled operations the engine calls; ``ledger.replay`` runs the same
operations over a list of events, for conformance tests and for checking the EVM contract.
"""
from .replay import LedgerEvent, Replayed, replay_events

__all__ = ["LedgerEvent", "Replayed", "replay_events"]
