"""The one check-and-lock both ledgers make before a sale: can the seller's money cover the stake and
the gas, and how much stake does it lock.

The instant ledger runs it on the seller's balance when a purchase is made; the chain model runs it
twice, on the seller's own view when it signs (``ledger.poa.mempool``) and on the branch's balance when
a block includes the reveal (``ledger.poa.blocks``).  Only the funds array differs, so the rule and its
float rounding are the same everywhere.
"""
from ..jit import njit

#: A seller whose money falls short of the stake by less than this (float rounding of sums of stakes,
#: e.g. 1 - 24 x 0.04) can still lock it: the exact on-chain ledger would accept it.
STAKE_TOLERANCE = 1e-9


@njit(forceinline=True, cache=True)
def lock_stake_and_gas(funds, seller, stake, gas):
    """Take ``gas`` and then the stake from ``funds[seller]`` if they cover ``stake + gas`` (within
    ``STAKE_TOLERANCE``): (True, the stake locked, never more than what is left) or (False, 0.0) with
    nothing taken.  The caller moves the money the funds gave up (to the pot, to gas)."""
    if stake > 0.0 or gas > 0.0:
        if funds[seller] < stake + gas - STAKE_TOLERANCE:
            return False, 0.0
    if gas > 0.0:
        funds[seller] -= gas
    lock = 0.0
    if stake > 0.0:
        lock = min(stake, funds[seller])  # never below zero, even within the tolerance
        funds[seller] -= lock
    return True, lock
