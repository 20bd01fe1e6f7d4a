"""The transaction pool's compiled housekeeping (``ledger.state``: each buyer's open transactions are a
block of the pool): move an entry, make a buyer's block big enough.  Both ledgers use it; only ledger
operations call it."""
from ..jit import njit

from ..state.view import unlock


@njit(forceinline=True, cache=True)
def move_transaction(w, src, dst):
    """Copy pool entry ``src`` (every field of a transaction) to ``dst``."""
    unlock(w.tx_seller)[dst] = w.tx_seller[src]
    unlock(w.tx_site)[dst] = w.tx_site[src]
    unlock(w.tx_dir)[dst] = w.tx_dir[src]
    unlock(w.tx_step)[dst] = w.tx_step[src]
    unlock(w.tx_stake)[dst] = w.tx_stake[src]


@njit(cache=True)
def reserve(w, buyer, need):
    """Make the buyer's block of the transaction pool hold at least ``need`` transactions, moving it to
    a bigger block at the top of the pool if needed; False when the pool is full (the host grows it)."""
    cap = w.tx_cap[buyer]
    if need <= cap:
        return True
    cap = max(2 * cap, need + 8)
    top = w.pool_top[0]
    if top + cap > w.tx_seller.shape[0]:
        return False
    a = w.tx_off[buyer]
    for x in range(w.tx_count[buyer]):
        move_transaction(w, a + x, top + x)
    unlock(w.tx_off)[buyer] = top
    unlock(w.tx_cap)[buyer] = cap
    unlock(w.pool_top)[0] = top + cap
    return True
