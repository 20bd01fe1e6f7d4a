"""Fork choice and the checkpoint: which block is heavier, the canonical head, and when a block becomes
final (the checkpoint moves up, its transactions leave the mempool, blocks off its branch are dropped)."""
import numpy as np
from ...jit import njit

from ...state.view import unlock
from .mempool import REVEAL, drop_own, on_branch, refresh_view
from .states import save_checkpoint, set_current


@njit(forceinline=True, cache=True)
def heavier(w, a, b):
    """Is block a heavier than block b: more total difficulty, or as much and a lower hash."""
    wa = w.blk_weight[a]
    wb = w.blk_weight[b]
    return wa > wb or (wa == wb and w.blk_hash[a] < w.blk_hash[b])


@njit(forceinline=True, cache=True)
def ancestor_at(w, b, height):
    """The block on b's branch at ``height`` (b itself when b is not higher)."""
    while w.blk_height[b] > height:
        b = w.blk_parent[b]
    return b


@njit(cache=True)
def new_canonical(w, b):
    """Block b was made: if it is heavier than the canonical head it becomes the canonical head; when the
    old head is not on b's branch that is a reorganisation, and the old branch's transactions that b's
    branch does not include are counted.  Returns the canonical head."""
    old = w.chn_canon[0]
    if not heavier(w, b, old):
        return old
    unlock(w.chn_canon)[0] = b
    if ancestor_at(w, b, w.blk_height[old]) != old:
        dropped = 0
        x = old
        ck = w.checkpoint[0]
        while x != ck:
            for k in range(w.blk_ntx[x]):
                if not on_branch(w, b, w.blk_tx[w.blk_txoff[x] + k]):
                    dropped += 1
            x = w.blk_parent[x]
        unlock(w.chn_reorgs)[0] += 1
        unlock(w.chn_reorg_tx)[0] += dropped
    return b


@njit(cache=True)
def next_checkpoint(w):
    """The block after the checkpoint on the canonical branch if it is final: every robot's head
    descends from it, or it lies ``chn_final`` blocks or more below the canonical head.  Else -1."""
    ck = w.checkpoint[0]
    canon = w.chn_canon[0]
    if canon == ck:
        return -1
    c = ancestor_at(w, canon, w.blk_height[ck] + 1)
    hc = w.blk_height[c]
    if w.blk_height[canon] - hc >= w.chn_final:
        return c  # final by depth, whoever has not heard of it
    n = w.view_head.shape[0]
    first = w.checkpoint_blocker[0]  # the robot that was behind last time is likely to be still
    for a in range(n):
        i = (first + a) % n
        h = w.view_head[i]
        if h < 0 or w.blk_height[h] < hc or ancestor_at(w, h, hc) != c:
            unlock(w.checkpoint_blocker)[0] = i
            return -1
    return c


@njit(cache=True)
def move_checkpoint(w, c):
    """Block c (whose state the ledger arrays hold) becomes the checkpoint: its state is saved, its
    transactions leave the mempool, and every block not descending from it is dropped; a robot whose
    head is dropped keeps its head's height, weight, hash and its own balance (``view_head`` -1) until
    it hears a heavier block."""
    save_checkpoint(w)
    set_current(w, c)
    live, known, mask = unlock(w.mp_live), unlock(w.mp_known), unlock(w.mp_word_mask)
    n = known.shape[0]
    pending = w.mp_count[0]
    words = np.empty(w.blk_ntx[c], np.int64)  # the words holding c's transactions' bits, and their mask
    nw = 0
    for k in range(w.blk_ntx[c]):
        tx = w.blk_tx[w.blk_txoff[c] + k]
        if mask[tx >> 6] == np.uint64(0):
            words[nw] = tx >> 6
            nw += 1
        mask[tx >> 6] |= np.uint64(1) << np.uint64(tx & 63)
        if not live[tx]:
            continue
        live[tx] = False
        unlock(w.mp_count)[0] -= 1
        if w.mp_kind[tx] == REVEAL:
            unlock(w.mp_for_buyer)[w.mp_buyer[tx]] -= 1
            unlock(w.mp_own)[w.mp_origin[tx]] -= 1
            drop_own(w, tx)
    for i in range(n):  # nobody knows them any more
        for a in range(nw):
            known[i, words[a]] &= ~mask[words[a]]
    order = unlock(w.mp_order)
    k = 0
    top = 0
    for a in range(pending):  # the pending ones, still in sending order
        if live[order[a]]:
            order[k] = order[a]
            top = max(top, order[k])
            k += 1
    unlock(w.mp_words_used)[0] = (top >> 6) + 1 if k > 0 else 0
    unlock(w.mp_cursor)[0] = 0  # new transactions take the lowest free slots
    hc = w.blk_height[c]
    blive, inc, mark, used = unlock(w.blk_live), unlock(w.blk_included), unlock(w.blk_mark), unlock(w.state_used)
    for b in range(w.blk_slots_touched[0]):  # marks: 1 descends from c, 2 does not, 0 not known yet; and every
        mark[b] = 0  # state row is free until a kept block is found using it (rows used are below blk_slots_touched)
        used[b] = False
    mark[c] = 1
    for b in range(w.blk_slots_touched[0]):
        if not blive[b] or mark[b] != 0:
            continue
        x = b  # up to the first block whose answer is known (c, or any block at c's height or below)
        while mark[x] == 0 and w.blk_height[x] > hc:
            x = w.blk_parent[x]
        keep = mark[x] == 1
        end = x
        x = b
        while x != end:  # every block on the way has the same answer: each block is walked once
            mark[x] = 1 if keep else 2
            x = w.blk_parent[x]
    for b in range(w.blk_slots_touched[0]):
        if not blive[b]:
            continue
        if mark[b] != 1:
            blive[b] = False
            unlock(w.blk_count)[0] -= 1
            unlock(w.blk_free_from)[0] = min(w.blk_free_from[0], b)
            continue
        for a in range(nw):  # final now: they leave every branch's pending set
            word = words[a]
            inc[b, word] &= ~mask[word]
        used[w.blk_state[b]] = True
    for a in range(nw):
        mask[words[a]] = 0
    s = 0
    while s < used.shape[0] and used[s]:
        s += 1
    unlock(w.state_free_from)[0] = s
    unlock(w.blk_parent)[c] = -1
    unlock(w.checkpoint)[0] = c
    for i in range(n):
        h = w.view_head[i]
        if h >= 0 and not blive[h]:
            if w.view_stale[i]:
                refresh_view(w, i)  # what its view allowed on the dropped head
            unlock(w.view_head)[i] = -1
