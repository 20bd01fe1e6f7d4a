"""The simulated blockchain: balances, per-buyer open transactions, stakes, and reward sharing.

Two ledgers behind one set of operations (``ledger.backends``): ``instant`` (``ledger.instant``, the
paper's: every purchase and deposit applied at once) and ``poa`` (``ledger.poa``: robots as the nodes of
a proof-of-authority chain).  ``ledger.kernels`` holds the compiled operations both share (the buy
rules' ``open_transaction``, settlement's ``distribute``, the logs); ``ledger.lock`` the one stake-and-gas
check; ``ledger.replay`` runs the instant ledger over a list of events, for conformance tests and for
checking the EVM contract.
"""
from .replay import LedgerEvent, Replayed, replay_events

__all__ = ["LedgerEvent", "Replayed", "replay_events"]
