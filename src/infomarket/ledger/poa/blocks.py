"""Making and applying blocks: a due signer makes a block on its head holding the pending transactions
it knows, in sending order; its transactions are applied once, on its parent's state, and the state is
kept (``ledger.poa.states``).  ``end_of_step`` is the chain's end of a step (``ledger.backends``)."""
import functools

import numpy as np
from ...jit import njit

from ...state.view import unlock
from ..gas import table_gas
from ..lock import lock_stake_and_gas
from .arena import can_make
from .forks import move_checkpoint, new_canonical, next_checkpoint
from .gossip import adopt, deliver_block
from .lists import append_node, materialise, materialise_all
from .mempool import DEPOSIT, mix
from .states import ledger_at, save_state, set_current


@njit(cache=True)
def in_turn(w, height):
    """The signer whose turn block ``height`` is."""
    s = w.chn_signers
    return s[height % s.shape[0]]


@njit(cache=True)
def due(w, signer, t):
    """Does ``signer`` make a block on its head at step t: P steps after the head's block when in turn,
    P + delay when out of turn."""
    h = w.view_head[signer]
    if h < 0:
        return False  # its branch was dropped: it cannot build on it
    wait = w.chn_period if in_turn(w, w.blk_height[h] + 1) == signer else w.chn_period + w.chn_delay
    return t - w.blk_step[h] >= wait


#: The lowest set bit of a 64-bit word by de Bruijn multiplication: _LOWEST_BIT[(x & -x) * _DE_BRUIJN >> 58].
_DE_BRUIJN = np.uint64(0x03F79D71B4CB0A89)
_LOWEST_BIT = np.zeros(64, np.int64)
for _b in range(64):
    _LOWEST_BIT[((1 << _b) * 0x03F79D71B4CB0A89 % 2**64) >> 58] = _b


#: Gaps of the Shell sort of a block's transactions (Ciura's sequence, extended by x2.25).
_GAPS = np.array([1, 4, 10, 23, 57, 132, 301, 701, 1577, 3548, 7983, 17961, 40412, 90927, 204585, 460316,
                  1035711], np.int64)


@njit(cache=True)
def sort_by_seq(w, txs, k):
    """Put the first k mempool slots of ``txs`` in sending order (``mp_seq``, all distinct), in place:
    an insertion sort (a block's transactions come mostly in slot order, which is mostly sending order),
    as a Shell sort's last pass when there are many."""
    seq = w.mp_seq
    g = 0
    while g + 1 < _GAPS.shape[0] and _GAPS[g + 1] * 3 < k:
        g += 1
    while g >= 0:
        gap = _GAPS[g]
        for a in range(gap, k):
            v = txs[a]
            key = seq[v]
            c = a - gap
            while c >= 0 and seq[txs[c]] > key:
                txs[c + gap] = txs[c]
                c -= gap
            txs[c + gap] = v
        g -= 1


@njit(cache=True)
def new_block(w, signer, t):
    """``signer`` makes a block on its head at step t, holding every pending transaction it knows that
    its branch does not include yet, in sending order.  Returns its slot (the ledger is not touched)."""
    parent = w.view_head[signer]
    live = unlock(w.blk_live)
    b = w.blk_free_from[0]  # every slot below it is taken: the lowest free slot is at or above it
    while live[b]:
        b += 1  # the host keeps a free slot for every block a step can make
    unlock(w.blk_free_from)[0] = b + 1
    if b >= w.blk_slots_touched[0]:
        unlock(w.blk_slots_touched)[0] = b + 1
    height = w.blk_height[parent] + 1
    live[b] = True
    unlock(w.blk_count)[0] += 1
    unlock(w.blk_parent)[b] = parent
    unlock(w.blk_height)[b] = height
    unlock(w.blk_weight)[b] = w.blk_weight[parent] + (2 if in_turn(w, height) == signer else 1)
    h = mix(np.uint64(w.blk_hash[parent]) ^ (np.uint64(height) * np.uint64(0x9E3779B97F4A7C15)))
    h = mix(h ^ (np.uint64(signer) + np.uint64(t) * np.uint64(0xD6E8FEB86659FD93)))
    unlock(w.blk_hash)[b] = np.int64(h >> np.uint64(2))
    unlock(w.blk_signer)[b] = signer
    unlock(w.blk_step)[b] = t
    unlock(w.blk_children)[b] = 0
    unlock(w.blk_by_backbone)[b] = False
    unlock(w.blk_children)[parent] += 1
    unlock(w.chn_blocks)[0] += 1
    if w.blk_children[parent] > 1:
        unlock(w.chn_forks)[0] += 1
    top = w.blk_tx_top[0]
    txs = unlock(w.blk_tx)[top:]
    inc = unlock(w.blk_included)
    k = 0
    for word in range(inc.shape[1]):  # known (so pending) and not on the parent's branch
        if word >= w.mp_words_used[0]:
            inc[b, word] = 0
            continue
        m = w.mp_known[signer, word] & ~inc[parent, word]
        inc[b, word] = inc[parent, word] | m
        while m != np.uint64(0):
            low = m & (~m + np.uint64(1))
            txs[k] = word * 64 + _LOWEST_BIT[(low * _DE_BRUIJN) >> np.uint64(58)]
            k += 1
            m ^= low
    sort_by_seq(w, txs, k)
    unlock(w.blk_txoff)[b] = top
    unlock(w.blk_ntx)[b] = k
    if k == 0:  # no transaction: its parent's state
        unlock(w.blk_state)[b] = w.blk_state[parent]
    else:  # a state row of its own (there are never more states than blocks): the lowest free one
        used = unlock(w.state_used)
        s = w.state_free_from[0]
        while used[s]:
            s += 1
        used[s] = True
        unlock(w.state_free_from)[0] = s + 1
        unlock(w.blk_state)[b] = s
    unlock(w.blk_tx_top)[0] = top + k
    return b


@njit(cache=True)
def include_tx(w, b, tx):
    """Apply transaction ``tx`` of block b to the ledger arrays.  A reveal: the seller pays the gas and
    locks the stake if the branch's balance covers both (the view's check, on the branch), and the
    buyer's open list gets it; else it fails and moves nothing.  A deposit: True, the caller settles it
    (``distribute`` pays the reward and the sellers) and then calls ``finish_deposit``."""
    buyer = w.mp_buyer[tx]
    if w.mp_kind[tx] == DEPOSIT:
        materialise(w, buyer)  # the settlement weighs its list in the ledger arrays
        unlock(w.settling_count)[0] = w.tx_count[buyer]
        return True
    seller = w.mp_seller[tx]
    gas = w.mp_gas[tx]
    ok, lock = lock_stake_and_gas(unlock(w.balance), seller, w.stake, gas)
    if not ok:
        unlock(w.chn_failed)[0] += 1
        return False
    count = w.tx_count[buyer]
    money = unlock(w.money)
    if gas > 0.0:
        money[0] -= gas
        unlock(w.gas_paid)[seller] += gas
    if w.stake > 0.0:
        money[0] -= lock
        unlock(w.pot)[buyer] += lock
    unlock(w.pool_stale)[0] = True
    unlock(w.state_list)[buyer] = append_node(w, buyer, w.state_list[buyer], w.mp_seq[tx], seller, w.mp_site[tx],
                                            w.mp_dir[tx], w.mp_step[tx], lock)
    unlock(w.tx_count)[buyer] = count + 1  # (the pool gets the list when it is next weighed or read)
    return False


@njit(cache=True)
def deposit_gas(w, n):
    """Gas of a deposit that settles n reveals (the world's deposit-gas table)."""
    return table_gas(w.chn_gas_n, w.chn_gas_deposit, n)


@njit(cache=True)
def finish_deposit(w, b, tx):
    """After a deposit's settlement: the depositor pays the deposit's gas (never below a zero balance),
    and its delay from sending to this block is measured (first application only)."""
    buyer = w.mp_buyer[tx]
    unlock(w.state_list)[buyer] = -1  # the settlement emptied its list
    unlock(w.pool_list)[buyer] = -1
    if w.chn_gas_price > 0.0:
        cost = min(w.chn_gas_price * deposit_gas(w, float(w.settling_count[0])), w.balance[buyer])
        unlock(w.balance)[buyer] -= cost
        unlock(w.money)[0] -= cost
        unlock(w.gas_paid)[buyer] += cost
    unlock(w.chn_delay_sum)[0] += w.blk_step[b] - w.mp_step[tx]
    unlock(w.chn_delay_count)[0] += 1


@functools.cache
def end_of_step(settle):
    """The chain's end of a step (``make_blocks``) around ``settle(w, buyer, rng)``, the kernel's
    settlement (its payment rule's weights, then ``ledger.kernels.distribute``)."""

    @njit(cache=False)  # captures compiled functions: see compiled_cache
    def apply_block(w, b, rng):
        """Apply block b's transactions, in order, to the ledger arrays (which hold its parent's state)."""
        for k in range(w.blk_ntx[b]):
            tx = w.blk_tx[w.blk_txoff[b] + k]
            if include_tx(w, b, tx):
                settle(w, w.mp_buyer[tx], rng)
                finish_deposit(w, b, tx)

    @njit(cache=False)  # captures compiled functions: see compiled_cache
    def make_blocks(w, rng):
        """Every signer whose turn has come (in signer-set order) makes a block on its head and applies it
        (logged, measured); the heaviest block is the canonical head, whose state the ledger arrays hold
        when this returns; the checkpoint moves up as far as every head agrees."""
        t = w.clock[0]
        signers = w.chn_signers
        for k in range(signers.shape[0]):
            s = signers[k]
            if not due(w, s, t) or not can_make(w):
                continue
            parent = w.view_head[s]
            b = new_block(w, s, t)
            if w.blk_ntx[b] > 0:  # (a block with no transaction shares its parent's state: new_block)
                ledger_at(w, parent)
                apply_block(w, b, rng)
                set_current(w, b)
                save_state(w, b)
            adopt(w, s, b)
            if w.chn_backbone and w.chn_latency == 0:
                deliver_block(w, b)
            new_canonical(w, b)
        while True:
            c = next_checkpoint(w)
            if c < 0:
                break
            ledger_at(w, c)  # (the lists stay where they are: the checkpoint's block keeps its own)
            move_checkpoint(w, c)
        ledger_at(w, w.chn_canon[0])
        materialise_all(w)

    return make_blocks
