"""Gossip: how heads and pending transactions travel between robots (one hop a step between neighbours,
messages lost at random, a backbone with a latency, a partition), and a robot adopting a heavier head."""
from ...jit import njit

from ...state.view import unlock
from .forks import ancestor_at, heavier
from .mempool import chance, learn, nest_side, partitioned


@njit(forceinline=True, cache=True)
def heavier_than_view(w, b, i):
    """Is block b heavier than robot i's head (its cached weight and hash: the head may be dropped)?"""
    return w.blk_weight[b] > w.view_weight[i] or (w.blk_weight[b] == w.view_weight[i]
                                                   and w.blk_hash[b] < w.view_hash[i])


@njit(cache=True)
def set_head(w, i, b):
    """Robot i's head becomes block b (a view reorganisation when its old head is not on b's branch)."""
    h = w.view_head[i]
    if h < 0 or ancestor_at(w, b, w.blk_height[h]) != h:
        unlock(w.chn_view_reorgs)[0] += 1
    unlock(w.view_head)[i] = b
    unlock(w.view_height)[i] = w.blk_height[b]
    unlock(w.view_weight)[i] = w.blk_weight[b]
    unlock(w.view_hash)[i] = w.blk_hash[b]
    unlock(w.view_bal)[i] = w.blk_bal[w.blk_state[b], i]
    unlock(w.view_stale)[i] = True


@njit(cache=True)
def adopt(w, i, b):
    """Robot i takes block b as its head if b is heavier than its head; True when it did."""
    if b == w.view_head[i] or not heavier_than_view(w, b, i):
        return False
    set_head(w, i, b)
    return True


@njit(cache=True)
def deliver_block(w, b):
    """The backbone brings block b to every robot; during a partition only to the robots on its signer's
    side, and to the others once it ends (``gossip``)."""
    if partitioned(w, w.clock[0]):
        side = w.blk_signer[b] >= 0 and nest_side(w, w.blk_signer[b])
        for i in range(w.view_head.shape[0]):
            if nest_side(w, i) == side:
                adopt(w, i, b)
        return
    unlock(w.blk_by_backbone)[b] = True
    for i in range(w.view_head.shape[0]):
        adopt(w, i, b)


@njit(cache=True)
def gossip(w):
    """One gossip round at the start of a step: every robot hears each neighbour's head and pending
    transactions as they were when the round began (so news travels one hop per step), each message
    lost with probability ``chn_loss``; the backbone delivers what is ``chn_latency`` steps old; each
    robot's view lag is measured."""
    t = w.clock[0]
    n = w.view_head.shape[0]
    old, heads = unlock(w.view_head_before), w.view_head
    mold, known = unlock(w.mp_known_before), unlock(w.mp_known)
    words = w.mp_words_used[0]  # (known-bits beyond are all 0)
    for i in range(n):
        old[i] = heads[i]
        if w.nbr_count[i] > 0:  # (neighbours are mutual: only a robot with one is heard)
            for k in range(words):
                mold[i, k] = known[i, k]
    loss = w.chn_loss
    cut = partitioned(w, t)
    for i in range(n):
        best = -1
        for a in range(w.nbr_count[i]):
            j = w.nbr[i, a]
            if loss > 0.0 and chance(w.chn_seed, t, j, i) < loss:
                continue
            if cut and nest_side(w, i) != nest_side(w, j):
                continue  # the partition: nothing crosses the bisector
            c = old[j]
            if c >= 0 and c != heads[i] and (heavier(w, c, best) if best >= 0 else heavier_than_view(w, c, i)):
                best = c
            for k in range(words):
                known[i, k] |= mold[j, k]
        if best >= 0:
            set_head(w, i, best)
    if w.chn_backbone and (w.chn_latency > 0 or w.chn_part_start >= 0):
        for a in range(w.mp_count[0]):
            tx = w.mp_order[a]
            if not w.mp_by_backbone[tx] and w.mp_step[tx] + w.chn_latency <= t:
                side = nest_side(w, w.mp_origin[tx])
                if not cut:
                    unlock(w.mp_by_backbone)[tx] = True
                for i in range(n):
                    if not cut or nest_side(w, i) == side:
                        learn(w, i, tx)
        for b in range(w.blk_live.shape[0]):
            if w.blk_live[b] and not w.blk_by_backbone[b] and w.blk_step[b] + w.chn_latency <= t:
                deliver_block(w, b)
    top = w.blk_height[w.chn_canon[0]]
    lag = unlock(w.chn_lag_sum)
    for i in range(n):
        lag[i] += top - w.view_height[i]
