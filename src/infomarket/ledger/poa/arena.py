"""The chain model's arrays on the host: the first sizes, the builder of a fresh chain, and growth between
steps; with the compiled bound of what the next step may need (``chain_needs``), which the kernel's
``has_room`` and the host's growth share.

Every array is sized by what is live (the host packs the arenas: block slots keep their numbers, the
blocks' transaction lists, the list nodes and their cached weights are packed to the front); nothing grows
with the run's history.  First capacities scale with the swarm (``POOL_PER_ROBOT``,
``MEMPOOL_PER_ROBOT``, ``ENTRIES_PER_ROBOT``), zeroed, so a run seldom stops for the host to grow an
array and untouched room takes no memory.
"""
from __future__ import annotations

import numpy as np
from ...jit import njit

from ..state import TX_POOL
from .spec import _LEDGER_KINDS, BLOCK_STATE, CHECKPOINTED, SPEC


#: First capacities: block slots (at least 16, at most 1024, as many as ``BLOCK_STATE_BYTES`` of block
#: states hold: each is O(robots); the arrays are allocated zeroed, so a slot takes memory only once a
#: block has been made in it) and mempool slots.  Generous first sizes spare a run most of the host's
#: growth calls, each of which copies every live block's state; they change no number.
BLOCK_CAPACITY = (16, 1024)
BLOCK_STATE_BYTES = 1 << 30
MEMPOOL_CAPACITY = 4096
#: First size of the blocks' transaction lists (``blk_tx``), and more per robot: ``chain_needs`` keeps room
#: for every signer due to include the whole mempool.
TX_ENTRIES = 1 << 18
#: First number of nodes of the buyers' lists (``ls_*``), and more per robot (room for every due signer to
#: append a node per pending reveal, ``chain_needs``).
LIST_ENTRIES = 1 << 17
#: The part of both that grows with the swarm: entries a robot.
ENTRIES_PER_ROBOT = 64
#: First size of the settlement cache (``weight_store``).
WEIGHT_ENTRIES = 1 << 17
#: First size of the ledger's transaction pool in a chain world: ``POOL_ENTRIES`` and ``POOL_PER_ROBOT`` a
#: robot (the instant ledger's is ``ledger.state.TX_CAPACITY`` a robot).  ``chain_needs`` bounds what any
#: branch's lists may need, which grows with the swarm and the transactions in flight.
POOL_ENTRIES = 1 << 16
POOL_PER_ROBOT = 128
#: Mempool slots a robot at first (at least ``MEMPOOL_CAPACITY``): ``chain_needs`` keeps a slot for every
#: purchase a step could make, about 2 x the robots of a large swarm.
MEMPOOL_PER_ROBOT = 3


def first_block_slots(n: int) -> int:
    """Block slots a fresh chain of n robots starts with (``BLOCK_CAPACITY``, ``BLOCK_STATE_BYTES``)."""
    per_block = 8 * n * (len(BLOCK_STATE) + 2)  # blk_bal, bs_*, bs_list
    return int(min(BLOCK_CAPACITY[1], max(BLOCK_CAPACITY[0], BLOCK_STATE_BYTES // per_block)))


def chain_pool(ledger: dict) -> dict:
    """The ledger's transaction pool enlarged to ``POOL_ENTRIES`` for a chain world (zeroed: untouched
    entries take no memory), so a run grows it rarely; the same entries, so no number moves."""
    n = ledger["balance"].shape[0]
    size = max(ledger["tx_seller"].shape[0], POOL_ENTRIES + POOL_PER_ROBOT * n)
    return {f: _grown(ledger[f], 0, size) for f in TX_POOL}


def _words(t: int) -> int:
    return (t + 63) // 64


def build_chain(ledger: dict, *, period: int, delay: int, signers, backbone: bool, latency: int, loss: float,
                gas_price: float, gas_reveal: float, gas_table, seed: int, finality: int, partition=None,
                cache_weights: bool = False) -> dict:
    """The chain's state for a fresh ledger: the genesis block (every robot's head), an empty mempool,
    the checkpoint a copy of the ledger.  ``cache_weights``: the payment scheme's weights depend only on the
    list it weighs (it takes neither ``market`` nor ``rng``), so a settled list's weights may be reused."""
    n = ledger["balance"].shape[0]
    bc, t = first_block_slots(n), 64 * _words(max(MEMPOOL_CAPACITY, MEMPOOL_PER_ROBOT * n))
    z = np.zeros
    ns, gs = zip(*gas_table)
    chain = {
        "chn_period": int(period), "chn_delay": int(delay), "chn_signers": np.asarray(signers, np.int64),
        "chn_backbone": bool(backbone), "chn_latency": int(latency), "chn_loss": float(loss),
        "chn_gas_price": float(gas_price), "chn_gas_reveal": float(gas_reveal),
        "chn_gas_n": np.array(ns, np.float64), "chn_gas_deposit": np.array(gs, np.float64), "chn_seed": int(seed),
        "chn_final": int(finality),
        "chn_part_start": -1 if partition is None else int(partition[0]),
        "chn_part_end": -1 if partition is None else int(partition[1]), "chn_cache": bool(cache_weights),
        "view_height": z(n, np.int64), "view_weight": z(n, np.int64),
        "view_hash": np.full(n, np.int64(int(seed) % (2**62)), np.int64), "view_bal": ledger["balance"].copy(),
        "view_head": z(n, np.int64), "view_head_before": z(n, np.int64), "view_avail": ledger["balance"].copy(),
        "view_stale": z(n, np.bool_), "blk_count": np.ones(1, np.int64), "blk_free_from": np.ones(1, np.int64),
        "blk_slots_touched": np.ones(1, np.int64),
        "gas_paid": z(n),
        "blk_live": z(bc, np.bool_), "blk_parent": np.full(bc, -1, np.int64), "blk_height": z(bc, np.int64),
        "blk_weight": z(bc, np.int64), "blk_hash": z(bc, np.int64), "blk_signer": np.full(bc, -1, np.int64),
        "blk_step": z(bc, np.int64), "blk_children": z(bc, np.int64), "blk_by_backbone": z(bc, np.bool_),
        "blk_mark": z(bc, np.int8), "blk_state": z(bc, np.int64), "state_used": z(bc, np.bool_),
        "state_free_from": np.ones(1, np.int64),
        "blk_ntx": z(bc, np.int64), "blk_txoff": z(bc, np.int64),
        "blk_tx": z(TX_ENTRIES + ENTRIES_PER_ROBOT * n, np.int64), "blk_bal": z((bc, n)),
        "blk_included": z((bc, _words(t)), np.uint64),
        "checkpoint": z(1, np.int64), "chn_canon": z(1, np.int64), "state_block": z(1, np.int64),
        "mp_sent": z(1, np.int64),
        "settling_count": z(1, np.int64), "checkpoint_blocker": z(1, np.int64), "blk_tx_top": z(1, np.int64),
        "mp_live": z(t, np.bool_), "mp_cursor": z(1, np.int64), "mp_order": z(t, np.int64),
        "mp_words_used": z(1, np.int64), "mp_own_next": np.full(t, -1, np.int64),
        "mp_own_prev": np.full(t, -1, np.int64),
        "own_first": np.full(n, -1, np.int64), "own_last": np.full(n, -1, np.int64), "mp_count": z(1, np.int64),
        "mp_for_buyer": z(n, np.int64), "mp_own": z(n, np.int64), "mp_kind": z(t, np.int64),
        "mp_origin": z(t, np.int64),
        "mp_buyer": z(t, np.int64), "mp_seller": z(t, np.int64), "mp_site": z(t, np.int64), "mp_dir": z(t),
        "mp_stake": z(t), "mp_gas": z(t), "mp_step": z(t, np.int64), "mp_seq": z(t, np.int64),
        "mp_by_backbone": z(t, np.bool_),
        "mp_known": z((n, _words(t)), np.uint64), "mp_known_before": z((n, _words(t)), np.uint64),
        "mp_word_mask": z(_words(t), np.uint64),
        "chn_blocks": z(1, np.int64), "chn_forks": z(1, np.int64), "chn_reorgs": z(1, np.int64),
        "chn_reorg_tx": z(1, np.int64), "chn_view_reorgs": z(1, np.int64), "chn_failed": z(1, np.int64),
        "chn_delay_sum": z(1, np.int64),
        "chn_delay_count": z(1, np.int64), "chn_lag_sum": z(n, np.int64),
    }
    for f in CHECKPOINTED:
        chain[f"ck_{f}"] = (chain["gas_paid"] if f == "gas_paid" else ledger[f]).copy()
    for f in BLOCK_STATE:
        kind, dims = _LEDGER_KINDS[f]
        chain[f"bs_{f}"] = z(bc if dims == "1" else (bc, n), np.dtype(kind))
    chain["bs_list"] = np.full((bc, n), -1, np.int64)
    for f in TX_POOL:
        chain[f"ls_{f[3:]}"] = z(LIST_ENTRIES + ENTRIES_PER_ROBOT * n, ledger[f].dtype)
    for f in ("ls_prev", "ls_len", "ls_seq", "ls_buyer", "ls_first_child", "ls_next_sibling", "ls_weights_at"):
        chain[f] = np.full(LIST_ENTRIES + ENTRIES_PER_ROBOT * n, -1, np.int64)
    chain["ls_roots"] = np.full(n, -1, np.int64)
    chain["ls_top"] = z(1, np.int64)
    chain["weight_store"] = z(WEIGHT_ENTRIES)
    chain["weight_top"] = z(1, np.int64)
    chain["pool_list"] = np.full(n, -1, np.int64)
    chain["pool_stale"] = z(1, np.bool_)
    chain["state_list"] = np.full(n, -1, np.int64)
    # genesis: slot 0, height 0, every robot's head, the checkpoint and the canonical head
    chain["blk_live"][0] = True
    chain["state_used"][0] = True  # genesis's state is row 0
    chain["blk_hash"][0] = np.int64(int(seed) % (2**62))
    chain["blk_bal"][0] = ledger["balance"]
    for f in BLOCK_STATE:  # genesis's state: the fresh ledger (no open transaction)
        v = chain["gas_paid"] if f == "gas_paid" else ledger[f]
        chain[f"bs_{f}"][0] = v[0] if v.shape == (1,) else v
    SPEC.check(chain)
    return chain


def used_states(world) -> np.ndarray:
    """The state rows live blocks use (of ``blk_bal`` and ``bs_*``)."""
    return np.flatnonzero(world.state_used)


def balances_after(world, b: int) -> np.ndarray:
    """Every robot's balance after live block b (a view of its state's row)."""
    return world.blk_bal[world.blk_state[b]]


def _grown(old: np.ndarray, axis: int, size: int, fill=0) -> np.ndarray:
    """``old`` grown to ``size`` along ``axis``, the new part ``fill`` (None: left as allocated)."""
    shape = list(old.shape)
    shape[axis] = size
    new = np.empty(shape, old.dtype) if fill is None else np.full(shape, fill, old.dtype)
    new[tuple(slice(0, k) for k in old.shape)] = old
    return new


def _grown_rows(old: np.ndarray, rows: np.ndarray, size: int) -> np.ndarray:
    """``old`` grown to ``size`` rows, holding only ``rows`` of it (the rest left as allocated)."""
    new = np.empty((size, *old.shape[1:]), old.dtype)
    new[rows] = old[rows]
    return new


def _packed_entries(world, changes: dict, entries: int) -> dict:
    """``blk_tx`` with the live blocks' entries packed to its front (in slot order), grown when the packed
    entries and what the next step adds (``entries - blk_tx_top``) do not fit twice."""
    live = np.flatnonzero(world.blk_live)
    off, ntx = world.blk_txoff, world.blk_ntx
    used = int(ntx[live].sum())
    size = max(world.blk_tx.shape[0], 4 * (used + entries - int(world.blk_tx_top[0])))
    new = np.zeros(size, np.int64)
    new_off = changes.get("blk_txoff", off).copy()
    sizes = ntx[live]
    starts = (np.cumsum(sizes) - sizes).astype(np.int64)
    new[:used] = world.blk_tx[np.repeat(off[live] - starts, sizes) + np.arange(used, dtype=np.int64)]
    new_off[live] = starts
    return {"blk_tx": new, "blk_txoff": new_off, "blk_tx_top": np.array([used], np.int64)}


def _packed_lists(world, changes: dict, lists: int) -> dict:
    """The list nodes that live blocks and the ledger arrays use, packed in their order (``ls_prev``,
    ``bs_list``, ``pool_list``, ``state_list`` renumbered; ``ls_first_child``, ``ls_next_sibling``, ``ls_roots``
    rebuilt; the kept
    nodes' cached weights packed too), grown when they and what the next step adds (``lists - ls_top``)
    do not fit twice."""
    rows = used_states(world)
    top = int(world.ls_top[0])
    keep = np.zeros(top, np.bool_)
    _reachable(world.ls_prev, np.concatenate([world.bs_list[rows].ravel(), world.pool_list, world.state_list]), keep)
    old = np.flatnonzero(keep)
    total = old.shape[0]
    new_of = np.full(top + 1, -1, np.int64)  # index top + 1 - 1 = -1 -> -1
    new_of[old] = np.arange(total, dtype=np.int64)
    size = max(world.ls_seller.shape[0], 4 * (total + lists - top))
    out = {}  # (nodes from total on are written whole when they are made: their memory is left untouched)
    for f in TX_POOL:
        o = getattr(world, f"ls_{f[3:]}")
        new = np.empty(size, o.dtype)
        new[:total] = o[old]
        out[f"ls_{f[3:]}"] = new
    for f in ("ls_prev", "ls_len", "ls_seq", "ls_buyer", "ls_first_child", "ls_next_sibling", "ls_weights_at"):
        out[f] = np.empty(size, np.int64)
        out[f][:total] = -1
    out["ls_prev"][:total] = new_of[world.ls_prev[old]]
    for f in ("ls_len", "ls_seq", "ls_buyer"):
        out[f][:total] = getattr(world, f)[old]
    wt_old = world.ls_weights_at[old]
    cached = wt_old >= 0
    lens = out["ls_len"][:total][cached]
    starts = (np.cumsum(lens) - lens).astype(np.int64)
    used = int(lens.sum())
    src = np.repeat(wt_old[cached] - starts, lens) + np.arange(used, dtype=np.int64)
    wsize = max(world.weight_store.shape[0], 4 * used, 2 * lists)
    wt = np.empty(wsize)
    wt[:used] = world.weight_store[src]
    out["ls_weights_at"][:total][cached] = starts
    roots = np.full(world.ls_roots.shape[0], -1, np.int64)
    _relink(out["ls_prev"], out["ls_buyer"], out["ls_first_child"], out["ls_next_sibling"], roots, total)

    def renumber(v):
        return new_of[v]

    bs_list = changes.get("bs_list", world.bs_list)  # (grown already when the block slots grew; renumbered in
    # place: the world this packs is replaced by the one make_room returns)
    bs_list[rows] = renumber(world.bs_list[rows])
    out.update(bs_list=bs_list, pool_list=renumber(world.pool_list), state_list=renumber(world.state_list),
               ls_roots=roots, ls_top=np.array([total], np.int64), weight_store=wt,
               weight_top=np.array([used], np.int64))
    return out


@njit(cache=True)
def _reachable(prev, ends, keep):
    """keep[x] for every node on a list ending at one of ``ends`` (-1: the empty list)."""
    for e in ends:
        x = e
        while x >= 0 and not keep[x]:
            keep[x] = True
            x = prev[x]


@njit(cache=True)
def _relink(prev, buyer, kid, sib, roots, total):
    """Rebuild the first-successor and sibling links of the first ``total`` nodes (``roots``: each buyer's
    first nodes).  Newer nodes come first in a chain, as when they were made."""
    for x in range(total):
        p = prev[x]
        if p >= 0:
            sib[x] = kid[p]
            kid[p] = x
        else:
            sib[x] = roots[buyer[x]]
            roots[buyer[x]] = x


def grow_chain(world, needs) -> dict:
    """Replacement arrays (field -> array) so the next step fits (``needs``: ``chain_needs`` of the world's
    view), at least doubling what grows; slots keep their numbers (nothing is moved).  Empty when nothing
    is short."""
    mp, blocks, pool, lists, entries = int(needs[0]), int(needs[1]), int(needs[2]), int(needs[5]), int(needs[6])
    changes: dict = {}
    t = world.mp_live.shape[0]
    if mp > t:
        size = 64 * _words(max(2 * t, mp))
        for f in ("mp_live", "mp_kind", "mp_origin", "mp_buyer", "mp_seller", "mp_site", "mp_dir", "mp_stake",
                  "mp_gas", "mp_step", "mp_seq", "mp_by_backbone", "mp_order", "mp_own_next", "mp_own_prev"):
            changes[f] = _grown(getattr(world, f), 0, size)
        for f in ("mp_known", "mp_known_before", "blk_included"):
            changes[f] = _grown(getattr(world, f), 1, _words(size))
        changes["mp_word_mask"] = _grown(world.mp_word_mask, 0, _words(size))
    bc = world.blk_live.shape[0]
    if blocks > bc:
        size = max(2 * bc, blocks)
        for f in ("blk_live", "blk_height", "blk_weight", "blk_hash", "blk_step", "blk_children", "blk_by_backbone",
                  "blk_mark", "blk_ntx", "blk_txoff", "blk_state", "state_used"):
            changes[f] = _grown(getattr(world, f), 0, size)
        for f in ("blk_parent", "blk_signer"):
            changes[f] = _grown(getattr(world, f), 0, size, -1)
        # a new slot's bits and a new state row are written whole when first used (new_block, save_state),
        # and nothing reads a free one: the new rows are left untouched (no memory until used), and only
        # the live blocks' bits and the used state rows are copied
        rows = used_states(world)
        changes["blk_bal"] = _grown_rows(world.blk_bal, rows, size)
        changes["blk_included"] = _grown_rows(changes.get("blk_included", world.blk_included),
                                              np.flatnonzero(world.blk_live), size)
        for f in BLOCK_STATE:
            changes[f"bs_{f}"] = _grown_rows(getattr(world, f"bs_{f}"), rows, size)
        changes["bs_list"] = _grown_rows(world.bs_list, rows, size)
    if lists > world.ls_seller.shape[0]:
        changes.update(_packed_lists(world, changes, lists))
    if entries > world.blk_tx.shape[0]:
        changes.update(_packed_entries(world, changes, entries))
    p = world.tx_seller.shape[0]
    if pool > p:
        size = max(2 * p, pool)
        for f in TX_POOL:
            changes[f] = _grown(getattr(world, f), 0, size)
    return changes


@njit(cache=True)
def chain_needs(w):
    """What the next step may need at most, for the kernel's ``has_room`` and the host's growth alike:
    (mempool slots, block slots, transaction-pool entries, event rows, payment rows).  One transaction
    per purchase and deposit; a block for every signer due now (one more may wait a step:
    ``can_make``); for the ledger arrays, every buyer's block of the pool moved as often as its pending
    reveals can make it grow; a list node per pending reveal per block; the logs of one block's
    settlements on top of the step's."""
    n = w.nbr_count.shape[0]
    links = 0
    for i in range(n):
        links += w.nbr_count[i]
    t = w.clock[0] + 1
    due = 0
    for k in range(w.chn_signers.shape[0]):
        h = w.view_head[w.chn_signers[k]]
        if h >= 0 and t - w.blk_step[h] >= w.chn_period:
            due += 1
    live = w.blk_count[0]
    pool = max(w.pool_top[0], w.ck_pool_top[0])
    open_ = 0
    reveals = 2 * links  # pending reveals by the end of the step
    for i in range(n):  # any live block's list of buyer i is its list at the checkpoint and pending reveals
        grow = max(w.tx_count[i], w.ck_tx_count[i]) + w.mp_for_buyer[i] + 2 * w.nbr_count[i]
        pool += 4 * (grow + 8) + 2 * max(w.tx_cap[i], w.ck_tx_cap[i])
        open_ += grow
        reveals += w.mp_for_buyer[i]
    mp = w.mp_count[0] + n + 2 * links
    events = w.ev_count[0] + n + 2 * links + mp
    payments = w.pay_count[0] + 2 * open_
    entries = w.blk_tx_top[0] + (due + 2) * mp  # every block made holds at most the whole mempool
    lists = w.ls_top[0] + (due + 2) * reveals  # a block makes at most a node per pending reveal
    return mp, live + due + 1, pool, events, payments, lists, entries


@njit(cache=True)
def room_fits(w):
    """Does the next step fit in the chain's arrays (and, when recording, the logs)?"""
    mp, blocks, pool, events, payments, lists, entries = chain_needs(w)
    if mp > w.mp_live.shape[0] or blocks > w.blk_live.shape[0] or pool > w.tx_seller.shape[0]:
        return False
    if lists > w.ls_seller.shape[0] or entries > w.blk_tx.shape[0]:
        return False
    return not w.record or (events <= w.ev_step.shape[0] and payments <= w.pay_step.shape[0])


@njit(cache=True)
def can_make(w):
    """Is there room for one more block this step (a free slot, room for its transactions and its
    buyers' lists, log rows for its settlements)?  A signer that finds none makes its block in a later
    step, after the host has grown the arrays (``chain_needs`` plans for the signers due at the step's
    start and two more, so this is rare)."""
    if w.blk_count[0] >= w.blk_live.shape[0] or w.blk_tx_top[0] + w.mp_count[0] > w.blk_tx.shape[0]:
        return False
    payments = 0  # any branch's open transactions: its checkpoint's and the pending reveals
    reveals = 0
    for i in range(w.tx_count.shape[0]):
        payments += max(w.tx_count[i], w.ck_tx_count[i]) + w.mp_for_buyer[i]
        reveals += w.mp_for_buyer[i]
    if w.ls_top[0] + reveals > w.ls_seller.shape[0]:
        return False
    if not w.record:
        return True
    return (w.ev_count[0] + w.mp_count[0] <= w.ev_step.shape[0]
            and w.pay_count[0] + payments <= w.pay_step.shape[0])
