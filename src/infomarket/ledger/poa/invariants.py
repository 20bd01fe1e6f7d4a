"""``check_invariants(world)``: the rules of ``ledger.poa``'s docstring, checked on the host between steps.

A debugging aid, not part of a run: it reads every live block, state row and list.  The chain tests call
it after every step of their small runs, so each rule is checked on whole arrays at once (a list is
walked once however many rows share it); a broken rule raises ``InternalError`` naming the rule and the
first place where it broke.
"""
from __future__ import annotations

import numpy as np

from ...errors import InternalError
from .spec import BLOCK_STATE, CHECKPOINTED


def _require(ok, rule: str) -> None:
    if not ok:
        raise InternalError(f"chain invariant broken: {rule}")


def _each(ok: np.ndarray, rule: str, *where: np.ndarray) -> None:
    """``ok`` holds everywhere; else raise ``rule`` formatted with the first failing element of each of
    ``where`` (arrays of ``ok``'s shape)."""
    if not np.all(ok):
        k = int(np.argmin(ok))
        _require(False, rule.format(*(int(w[k]) for w in where)))


def _list_of(world, node: int) -> list[int]:
    """The nodes of the list ending at ``node``, oldest first."""
    out = []
    while node >= 0:
        out.append(node)
        _require(len(out) <= world.ls_prev.shape[0], f"the list ending at node {out[0]} has no first node")
        node = int(world.ls_prev[node])
    return out[::-1]


def _on_lists(world, heads: np.ndarray) -> np.ndarray:
    """Every node on the lists ending at ``heads`` (each once), walked back together."""
    seen = np.zeros(world.ls_prev.shape[0], np.bool_)
    frontier = np.unique(heads[heads >= 0])
    while frontier.size:
        seen[frontier] = True
        back = world.ls_prev[frontier]
        back = back[back >= 0]
        frontier = np.unique(back[~seen[back]])
    return np.flatnonzero(seen)


def _check_blocks(world) -> np.ndarray:
    live = np.flatnonzero(world.blk_live)
    ck = int(world.checkpoint[0])
    _require(world.blk_live[ck] and world.blk_parent[ck] == -1, "the checkpoint is live and has no parent")
    _require(int(world.blk_count[0]) == live.size, "blk_count counts the live blocks")
    _require(live.max() < int(world.blk_slots_touched[0]), "every live slot is below blk_slots_touched")
    _require(world.blk_live[:int(world.blk_free_from[0])].all(), "every slot below blk_free_from is live")
    b = live[live != ck]
    p = world.blk_parent[b]
    _each((p >= 0) & world.blk_live[np.maximum(p, 0)], "block {}'s parent {} is live", b, p)
    _each(world.blk_height[b] == world.blk_height[p] + 1, "block {} is one higher than its parent", b)
    _each(world.blk_height[b] > world.blk_height[ck], "block {} descends from the checkpoint", b)
    return live


def _check_rows(world, live: np.ndarray) -> np.ndarray:
    ck = int(world.checkpoint[0])
    rows = world.blk_state[live]
    used = np.zeros_like(world.state_used)
    used[rows] = True
    _require(np.array_equal(used, world.state_used), "state_used marks exactly the live blocks' rows")
    _require(world.state_used[:int(world.state_free_from[0])].all(), "every row below state_free_from is used")
    own = live[(world.blk_ntx[live] > 0) & (live != ck)]
    _require(np.unique(world.blk_state[own]).size == own.size, "a block with transactions has a row of its own")
    b = live[live != ck]
    same = world.blk_state[b] == world.blk_state[world.blk_parent[b]]
    _each(same == (world.blk_ntx[b] == 0), "block {} shares its parent's row exactly when it includes no transaction",
          b)
    return np.unique(rows)


def _check_lists(world, rows: np.ndarray) -> None:
    heads, counts = world.bs_list[rows], world.bs_tx_count[rows]
    row, buyer = np.broadcast_arrays(rows[:, None], np.arange(heads.shape[1])[None, :])
    none = heads < 0
    _each(counts[none] == 0, "row {}: buyer {} has no list and no open transaction", row[none], buyer[none])
    heads, counts, row, buyer = heads[~none], counts[~none], row[~none], buyer[~none]
    # each node one longer than the node before it (1 for the first) and the same buyer's: then every list
    # counts its nodes 1, 2, ... and is its last node's buyer's
    nodes = _on_lists(world, heads)
    back = world.ls_prev[nodes]
    before = np.maximum(back, 0)
    counted = np.where(back < 0, world.ls_len[nodes] == 1, world.ls_len[nodes] == world.ls_len[before] + 1)
    owned = (back < 0) | (world.ls_buyer[nodes] == world.ls_buyer[before])
    for ok, rule in ((counted, "counts its nodes (ls_len)"), (owned, "is buyer {i}'s")):
        if not ok.all():
            bad = set(nodes[~ok].tolist())
            k = next(k for k, v in enumerate(heads) if bad.intersection(_list_of(world, int(v))))
            _require(False, f"row {row[k]}: buyer {buyer[k]}'s list " + rule.format(i=buyer[k]))
    _each(world.ls_buyer[heads] == buyer, "row {}: buyer {}'s list is buyer {}'s", row, buyer, buyer)
    _each(world.ls_len[heads] == counts, "row {}: buyer {}'s open transactions are its list's", row, buyer)


_LIVE_AND_ROW = [("balance", "blk_bal")] + [(f, f"bs_{f}") for f in BLOCK_STATE]
_POOL_AND_LIST = [(f"tx_{f}", f"ls_{f}") for f in ("seller", "dir", "stake", "site", "step")]


def _check_live_ledger(world) -> None:
    """After ``_check_lists``: the canonical row's lists are well formed."""
    row = int(world.blk_state[int(world.state_block[0])])
    _require(row == int(world.blk_state[int(world.chn_canon[0])]),
             "the ledger arrays hold the canonical head's state")
    for f, g in _LIVE_AND_ROW:
        _require(np.array_equal(np.ravel(getattr(world, f)), np.ravel(getattr(world, g)[row])),
                 f"the ledger's {f} is the canonical row's {g}")
    _require(np.array_equal(world.state_list, world.bs_list[row]), "state_list is the canonical row's bs_list")
    _require(not world.pool_stale[0] and np.array_equal(world.pool_list, world.state_list),
             "the pool holds every buyer's list (pool_list == state_list)")
    node = world.state_list.astype(np.int64)
    buyers = np.arange(node.size)
    length = np.where(node >= 0, world.ls_len[np.maximum(node, 0)], 0)
    _each(length == world.tx_count, "buyer {}'s pool block holds its list", buyers)
    while (node >= 0).any():  # entry x of buyer i's pool block is its list's node x
        on = node >= 0
        x, i = node[on], buyers[on]
        entry = world.ls_len[x] - 1
        slot = world.tx_off[i] + entry
        same = np.logical_and.reduce([getattr(world, t)[slot] == getattr(world, s)[x] for t, s in _POOL_AND_LIST])
        _each(same, "buyer {}'s pool entry {} is its list's", i, entry)
        node[on] = world.ls_prev[x]


def _check_checkpoint(world) -> None:
    row = int(world.blk_state[int(world.checkpoint[0])])
    for f in CHECKPOINTED:
        if f in ("tx_off", "tx_cap", "pool_top"):  # bounds of the pool, not the ledger's content
            continue
        kept = world.blk_bal[row] if f == "balance" else getattr(world, f"bs_{f}")[row]
        _require(np.array_equal(np.ravel(getattr(world, f"ck_{f}")), np.ravel(kept)),
                 f"ck_{f} is the checkpoint's row")


def _check_views_and_mempool(world) -> None:
    robots = np.flatnonzero(world.view_head >= 0)
    h = world.view_head[robots]
    _each(world.blk_live[h], "robot {}'s head is live", robots)
    _each((world.view_height[robots] == world.blk_height[h]) & (world.view_weight[robots] == world.blk_weight[h])
          & (world.view_hash[robots] == world.blk_hash[h]), "robot {}'s cached head is its head's", robots)
    _each(world.view_bal[robots] == world.blk_bal[world.blk_state[h], robots], "robot {}'s view balance is its head's",
          robots)
    live = np.flatnonzero(world.mp_live)
    k = int(world.mp_count[0])
    _require(live.size == k, "mp_count counts the pending transactions")
    order = world.mp_order[:k]
    _require(np.array_equal(np.sort(order), live), "mp_order lists the pending transactions")
    _require(np.all(np.diff(world.mp_seq[order]) > 0), "mp_order is in sending order")
    _require(live.size == 0 or live.max() < 64 * int(world.mp_words_used[0]), "pending slots are below mp_words_used")
    _require(not world.mp_word_mask.any(), "mp_word_mask is clear between calls")
    pending = np.zeros(64 * world.blk_included.shape[1], np.bool_)
    pending[live] = True
    blocks = np.flatnonzero(world.blk_live)
    bits = np.unpackbits(np.ascontiguousarray(world.blk_included[blocks]).view(np.uint8), axis=1,
                         bitorder="little").astype(np.bool_)
    _each(~(bits & ~pending).any(axis=1), "block {} includes pending transactions only", blocks)


def check_invariants(world) -> None:
    """Check every rule of ``ledger.poa``'s four forms of the ledger (and the blocks, views and mempool
    around them) on a chain world between steps; raise ``InternalError`` at the first one broken."""
    live = _check_blocks(world)
    rows = _check_rows(world, live)
    _check_lists(world, rows)
    _check_live_ledger(world)
    _check_checkpoint(world)
    _check_views_and_mempool(world)
