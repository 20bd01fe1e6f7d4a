"""``check_invariants(world)``: the rules of ``ledger.poa``'s docstring, checked on the host between steps.

A debugging aid, not part of a run: it reads every live block, state row and list, so it costs far more
than a step.  The chain tests call it after every step of their small runs; a broken rule raises
``InternalError`` naming the rule and where it broke.
"""
from __future__ import annotations

import numpy as np

from ...errors import InternalError
from .spec import BLOCK_STATE, CHECKPOINTED


def _require(ok, rule: str) -> None:
    if not ok:
        raise InternalError(f"chain invariant broken: {rule}")


def _list_of(world, node: int) -> list[int]:
    """The nodes of the list ending at ``node``, oldest first."""
    out = []
    while node >= 0:
        out.append(node)
        node = int(world.ls_prev[node])
    return out[::-1]


def _check_blocks(world) -> np.ndarray:
    live = np.flatnonzero(world.blk_live)
    ck = int(world.checkpoint[0])
    _require(world.blk_live[ck] and world.blk_parent[ck] == -1, "the checkpoint is live and has no parent")
    _require(int(world.blk_count[0]) == live.size, "blk_count counts the live blocks")
    _require(live.max() < int(world.blk_slots_touched[0]), "every live slot is below blk_slots_touched")
    _require(world.blk_live[:int(world.blk_free_from[0])].all(), "every slot below blk_free_from is live")
    for b in live:
        if b == ck:
            continue
        p = int(world.blk_parent[b])
        _require(p >= 0 and world.blk_live[p], f"block {b}'s parent {p} is live")
        _require(world.blk_height[b] == world.blk_height[p] + 1, f"block {b} is one higher than its parent")
        _require(world.blk_height[b] > world.blk_height[ck], f"block {b} descends from the checkpoint")
    return live


def _check_rows(world, live: np.ndarray) -> np.ndarray:
    ck = int(world.checkpoint[0])
    rows = world.blk_state[live]
    used = np.zeros_like(world.state_used)
    used[rows] = True
    _require(np.array_equal(used, world.state_used), "state_used marks exactly the live blocks' rows")
    _require(world.state_used[:int(world.state_free_from[0])].all(), "every row below state_free_from is used")
    own = [b for b in live if world.blk_ntx[b] > 0 and b != ck]
    _require(len({int(world.blk_state[b]) for b in own}) == len(own), "a block with transactions has a row of its own")
    for b in live:
        p = int(world.blk_parent[b])
        if b == ck:
            continue
        same = world.blk_state[b] == world.blk_state[p]
        _require(same == (world.blk_ntx[b] == 0),
                 f"block {b} shares its parent's row exactly when it includes no transaction")
    return np.unique(rows)


def _check_lists(world, rows: np.ndarray) -> None:
    for r in rows:
        for i, v in enumerate(world.bs_list[r]):
            v = int(v)
            count = int(world.bs_tx_count[r, i])
            if v < 0:
                _require(count == 0, f"row {r}: buyer {i} has no list and no open transaction")
                continue
            nodes = _list_of(world, v)
            _require([int(world.ls_len[x]) for x in nodes] == list(range(1, len(nodes) + 1)),
                     f"row {r}: buyer {i}'s list counts its nodes (ls_len)")
            _require(all(world.ls_buyer[x] == i for x in nodes), f"row {r}: buyer {i}'s list is buyer {i}'s")
            _require(count == len(nodes), f"row {r}: buyer {i}'s open transactions are its list's")


_LIVE_AND_ROW = [("balance", "blk_bal")] + [(f, f"bs_{f}") for f in BLOCK_STATE]


def _check_live_ledger(world) -> None:
    row = int(world.blk_state[int(world.state_block[0])])
    _require(row == int(world.blk_state[int(world.chn_canon[0])]),
             "the ledger arrays hold the canonical head's state")
    for f, g in _LIVE_AND_ROW:
        _require(np.array_equal(np.ravel(getattr(world, f)), np.ravel(getattr(world, g)[row])),
                 f"the ledger's {f} is the canonical row's {g}")
    _require(np.array_equal(world.state_list, world.bs_list[row]), "state_list is the canonical row's bs_list")
    _require(not world.pool_stale[0] and np.array_equal(world.pool_list, world.state_list),
             "the pool holds every buyer's list (pool_list == state_list)")
    for i, v in enumerate(world.state_list):
        a, k = int(world.tx_off[i]), int(world.tx_count[i])
        nodes = _list_of(world, int(v))
        _require(len(nodes) == k, f"buyer {i}'s pool block holds its list")
        for x, node in enumerate(nodes):
            _require(world.tx_seller[a + x] == world.ls_seller[node] and world.tx_dir[a + x] == world.ls_dir[node]
                     and world.tx_stake[a + x] == world.ls_stake[node] and world.tx_site[a + x] == world.ls_site[node]
                     and world.tx_step[a + x] == world.ls_step[node], f"buyer {i}'s pool entry {x} is its list's")


def _check_checkpoint(world) -> None:
    row = int(world.blk_state[int(world.checkpoint[0])])
    for f in CHECKPOINTED:
        if f in ("tx_off", "tx_cap", "pool_top"):  # bounds of the pool, not the ledger's content
            continue
        kept = world.blk_bal[row] if f == "balance" else getattr(world, f"bs_{f}")[row]
        _require(np.array_equal(np.ravel(getattr(world, f"ck_{f}")), np.ravel(kept)),
                 f"ck_{f} is the checkpoint's row")


def _check_views_and_mempool(world) -> None:
    for i, h in enumerate(world.view_head):
        h = int(h)
        if h < 0:
            continue
        _require(world.blk_live[h], f"robot {i}'s head is live")
        _require(world.view_height[i] == world.blk_height[h] and world.view_weight[i] == world.blk_weight[h]
                 and world.view_hash[i] == world.blk_hash[h], f"robot {i}'s cached head is its head's")
        _require(world.view_bal[i] == world.blk_bal[world.blk_state[h], i], f"robot {i}'s view balance is its head's")
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
    for b in np.flatnonzero(world.blk_live):
        bits = np.unpackbits(world.blk_included[b].view(np.uint8), bitorder="little").astype(np.bool_)
        _require(not (bits & ~pending).any(), f"block {b} includes pending transactions only")


def check_invariants(world) -> None:
    """Check every rule of ``ledger.poa``'s four forms of the ledger (and the blocks, views and mempool
    around them) on a chain world between steps; raise ``InternalError`` at the first one broken."""
    live = _check_blocks(world)
    rows = _check_rows(world, live)
    _check_lists(world, rows)
    _check_live_ledger(world)
    _check_checkpoint(world)
    _check_views_and_mempool(world)
