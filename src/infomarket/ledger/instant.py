"""The instant ledger (the paper's): a purchase locks the seller's stake at once, a deposit settles at
once.  Its operations for the step kernel (``ledger.backends``): open a transaction, deposit (the
kernel's settlement itself), and the room a step needs; it has no end of step.
"""
from ..jit import njit

from ..state import flags
from ..state.view import unlock
from .pool import reserve
from .lock import lock_stake_and_gas


@njit(forceinline=True, cache=True)
def open_transaction(w, buyer, seller, site, direction):
    """Lock the seller's stake (``lock_stake_and_gas``, no gas) and record the transaction in the
    buyer's block of the pool; False, with nothing recorded, when refused."""
    k = w.tx_count[buyer]
    if k >= w.tx_cap[buyer]:
        unlock(w.flags)[0] |= flags.TX_OVERFLOW
        return False
    ok, lock = lock_stake_and_gas(unlock(w.balance), seller, w.stake, 0.0)
    if not ok:
        return False
    if w.stake > 0.0:
        unlock(w.money)[0] -= lock
        unlock(w.pot)[buyer] += lock
    x = w.tx_off[buyer] + k
    unlock(w.tx_seller)[x] = seller
    unlock(w.tx_site)[x] = site
    unlock(w.tx_dir)[x] = direction
    unlock(w.tx_step)[x] = w.clock[0]
    unlock(w.tx_stake)[x] = lock
    unlock(w.tx_count)[buyer] = k + 1
    return True


@njit(cache=True)
def has_room(w):
    """Can the next step's transactions fit?  A buy rule may make one purchase per neighbour and site;
    the log gets at most one event per purchase plus a deposit, and the payments log one row per
    transaction a deposit settles.  Transaction blocks that could overflow are moved to bigger ones
    while the pool has space."""
    nbr_count = w.nbr_count
    n = nbr_count.shape[0]
    events = n
    payments = 0
    for i in range(n):
        c = nbr_count[i]
        need = w.tx_count[i] + 2 * c
        if need > w.tx_cap[i] and not reserve(w, i, need):
            return False
        events += 2 * c
        payments += need
    if w.record and (w.ev_count[0] + events > w.ev_step.shape[0]
                     or w.pay_count[0] + payments > w.pay_step.shape[0]):
        return False
    return True
