"""The chain model's transactions in flight and each robot's view (docs/chain-model.md).

With ``[chain] consensus = "poa"`` the ledger does not apply a purchase or a deposit at once: it becomes a
pending transaction in a bounded pool (the *mempool*), known at first only to the robot that sent it, and
it moves money only when a block includes it (``ledger.poa.blocks``).  This module holds what acts on a
robot's own view and nothing else: the view check of a reveal (``reveal``, the chain's way to open a
transaction), the sending of a deposit, and a robot's spendable balance at its head.

Random draws (message loss) come from a counter-based hash of the run's chain seed, the step and the two
robots (``chance``): the engine's random streams are never touched, so turning the chain on does not move
a single draw of the swarm's.
"""
import numpy as np
from ...jit import njit

from ...state.view import unlock
from ..lock import lock_stake_and_gas

# Transaction kinds in the mempool.
REVEAL = 0   #: revealInformation: a purchase (the seller sends it; stake and gas come from the seller)
DEPOSIT = 1  #: buyItem + settle: a deposit (the depositing robot's; its reward pays the deposit's gas)

_GOLDEN = np.uint64(0x9E3779B97F4A7C15)


@njit(forceinline=True, cache=True)
def mix(x):
    """splitmix64's finaliser: a bijective scramble of a 64-bit word (``x`` uint64)."""
    x = (x ^ (x >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    x = (x ^ (x >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return x ^ (x >> np.uint64(31))


@njit(cache=True)
def chance(seed, a, b, c):
    """A uniform draw in [0, 1) that depends only on (seed, a, b, c), all non-negative integers."""
    x = mix(np.uint64(seed) + _GOLDEN)
    x = mix(x ^ (np.uint64(a) * _GOLDEN))
    x = mix(x ^ (np.uint64(b) + np.uint64(0x632BE59BD9B4E019)))
    x = mix(x ^ (np.uint64(c) * np.uint64(0xD6E8FEB86659FD93)))
    return float(x >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@njit(forceinline=True, cache=True)
def knows(w, i, tx):
    """Does robot i know pending transaction ``tx`` (its bit in ``mp_known``)?"""
    return (w.mp_known[i, tx >> 6] >> np.uint64(tx & 63)) & np.uint64(1) != np.uint64(0)


@njit(forceinline=True, cache=True)
def learn(w, i, tx):
    """Mark transaction ``tx`` as known to node ``i`` (one bit in its mempool bitset)."""
    unlock(w.mp_known)[i, tx >> 6] |= np.uint64(1) << np.uint64(tx & 63)


@njit(forceinline=True, cache=True)
def on_branch(w, b, tx):
    """Is pending transaction ``tx`` included on block b's branch after the checkpoint (``blk_included``)?
    Nothing is for b = -1 (a dropped head)."""
    return b >= 0 and (w.blk_included[b, tx >> 6] >> np.uint64(tx & 63)) & np.uint64(1) != np.uint64(0)


@njit(cache=True)
def refresh_view(w, i):
    """Robot i's spendable money at its head: its balance there, less the gas and stakes of its own
    reveals that its head's branch does not include yet (in sending order; all of them when its branch
    was dropped, ``view_head`` -1).  Done when the robot sells or its head is dropped, if its head moved
    since (``view_stale``): nothing it reads changes in between except by those."""
    unlock(w.view_stale)[i] = False
    a = w.view_bal[i]
    own = w.mp_own[i]
    if own == 0:  # nothing of its own pending: no branch to look at
        unlock(w.view_avail)[i] = a
        return
    h = w.view_head[i]
    tx = w.own_first[i]
    while tx >= 0:  # its own pending reveals, in sending order
        if not on_branch(w, h, tx):
            a -= w.mp_gas[tx]
            a -= w.mp_stake[tx]
        tx = w.mp_own_next[tx]
    unlock(w.view_avail)[i] = a


@njit(forceinline=True, cache=True)
def partitioned(w, t):
    """Is the chain's network partitioned at step t (``[chain] partition``)?"""
    return w.chn_part_start <= t < w.chn_part_end


@njit(cache=True)
def nest_side(w, i):
    """Is robot i on the nest's side of the perpendicular bisector of the first food site and the first
    nest (on it counts as the nest's side)?"""
    f = -1
    m = -1
    for s in range(w.sites_kind.shape[0]):
        if w.sites_kind[s] == 0 and f < 0:
            f = s
        elif w.sites_kind[s] == 1 and m < 0:
            m = s
    fx, fy = w.sites_xy[f, 0], w.sites_xy[f, 1]
    nx, ny = w.sites_xy[m, 0], w.sites_xy[m, 1]
    return ((w.pos[i, 0] - 0.5 * (fx + nx)) * (nx - fx) + (w.pos[i, 1] - 0.5 * (fy + ny)) * (ny - fy)) >= 0.0


@njit(cache=True)
def new_tx(w, kind, origin, buyer, seller, site, direction, stake, gas):
    """Put a transaction in the mempool, known to its sender (and to everyone at once through a backbone
    of zero latency).  The host keeps a free slot for every transaction a step can make."""
    live = unlock(w.mp_live)
    cap = live.shape[0]
    x = w.mp_cursor[0]  # the lowest free slot (the cursor goes back to 0 when slots are freed)
    for _ in range(cap):
        if not live[x]:
            break
        x = (x + 1) % cap
    live[x] = True
    unlock(w.mp_cursor)[0] = (x + 1) % cap
    if x >> 6 >= w.mp_words_used[0]:
        unlock(w.mp_words_used)[0] = (x >> 6) + 1
    unlock(w.mp_kind)[x] = kind
    unlock(w.mp_origin)[x] = origin
    unlock(w.mp_buyer)[x] = buyer
    unlock(w.mp_seller)[x] = seller
    unlock(w.mp_site)[x] = site
    unlock(w.mp_dir)[x] = direction
    unlock(w.mp_stake)[x] = stake
    unlock(w.mp_gas)[x] = gas
    unlock(w.mp_step)[x] = w.clock[0]
    unlock(w.mp_seq)[x] = w.mp_sent[0]
    unlock(w.mp_sent)[0] += 1
    unlock(w.mp_order)[w.mp_count[0]] = x
    unlock(w.mp_count)[0] += 1
    if w.chn_backbone and w.chn_latency == 0 and not partitioned(w, w.clock[0]):
        for i in range(w.view_head.shape[0]):
            learn(w, i, x)
        unlock(w.mp_by_backbone)[x] = True
    elif w.chn_backbone and w.chn_latency == 0:  # partitioned: its side at once, the rest when it ends
        side = nest_side(w, origin)
        for i in range(w.view_head.shape[0]):
            if nest_side(w, i) == side:
                learn(w, i, x)
        unlock(w.mp_by_backbone)[x] = False
    else:
        learn(w, origin, x)
        unlock(w.mp_by_backbone)[x] = False
    if kind == REVEAL:
        unlock(w.mp_for_buyer)[buyer] += 1
        unlock(w.mp_own)[origin] += 1
        last = w.own_last[origin]
        unlock(w.mp_own_prev)[x] = last
        unlock(w.mp_own_next)[x] = -1
        if last >= 0:
            unlock(w.mp_own_next)[last] = x
        else:
            unlock(w.own_first)[origin] = x
        unlock(w.own_last)[origin] = x
    return x


@njit(cache=True)
def drop_own(w, tx):
    """Take reveal ``tx`` out of its sender's list of own pending reveals."""
    i = w.mp_origin[tx]
    p, q = w.mp_own_prev[tx], w.mp_own_next[tx]
    if p >= 0:
        unlock(w.mp_own_next)[p] = q
    else:
        unlock(w.own_first)[i] = q
    if q >= 0:
        unlock(w.mp_own_prev)[q] = p
    else:
        unlock(w.own_last)[i] = p


@njit(cache=True)
def reveal(w, buyer, seller, site, direction):
    """A purchase in a chain world (``ledger.kernels.open_transaction``).  The seller signs the light
    contract only if its own view can pay: ``lock_stake_and_gas`` on its spendable money at its head
    (the instant ledger's check, on the view).  The buyer gets the vector at once (off-chain light
    contract); the reveal goes to the mempool.  True when the seller's view accepts it."""
    gas = w.chn_gas_price * w.chn_gas_reveal
    if w.view_stale[seller]:
        refresh_view(w, seller)
    ok, lock = lock_stake_and_gas(unlock(w.view_avail), seller, w.stake, gas)
    if not ok:
        return False
    new_tx(w, REVEAL, seller, buyer, seller, site, direction, lock, gas)
    return True


@njit(cache=True)
def send_deposit(w, i):
    """Robot i deposited an item: a deposit transaction (buyItem, then settle) goes to the mempool; the
    reward and the payments move when a block includes it."""
    new_tx(w, DEPOSIT, i, i, -1, -1, 0.0, 0.0, 0.0)
