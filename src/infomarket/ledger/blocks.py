"""The chain model: robots as blockchain nodes (docs/chain-model.md).  Its state, builder and growth, and
the compiled ledger operations on blocks.

State (``SPEC``, the ``chain`` domain; only ledger operations write it, like the ledger's own):

* **Blocks**, a store of the blocks that are not final yet: parent, height, weight (total difficulty:
  2 per in-turn block, 1 per out-of-turn one, as Clique), hash, signer, step, the transactions it
  includes (mempool slots, in the order they were sent: ``blk_tx[blk_txoff[b]:][:blk_ntx[b]]``), a bit
  per pending transaction on its branch (``blk_inc``), and the ledger's state after it: a row
  (``blk_st``) of every robot's balances (``blk_bal``, the snapshot a robot's view reads) and the rest of
  the ledger (``bs_*``; each buyer's open transactions as a node of the list store ``ls_*``: its last
  transaction, ``ls_prev`` the rest; the same reveal appended to the same list is the same node on every
  branch, so a node is a list's content and a settled list's weights are cached by it, ``ls_wt``).  A
  block that includes no transaction (most of them: two in three at the paper's size, all of them in a
  large sparse swarm) has its parent's row: nothing is copied or applied, and the rows in use stay few
  and warm, whatever the number of live blocks.  A row is kept while a live block uses it (``st_used``),
  even once the block that made it is dropped.  The **checkpoint** (``chn_ckpt``) is the newest
  final block (every robot's head descends from it, or it lies ``chn_final`` blocks below the canonical
  head): nothing before it can change, so it is the root of the store.
* **Mempool** (``ledger.mempool``): transactions not yet in a final block, with a bit per robot
  (``mp_known``) saying who knows each.
* **Views**: each robot's head block (``view_head``, -1 once its branch is dropped), the head's height,
  weight and hash and its own balance there (``view_*``), and its spendable money (``view_avail``).
* **Ledgers**: the engine's ledger arrays (``ledger.state``) hold the state at the **canonical head**
  (``chn_canon``: the heaviest block, ties to the lower hash), which the run reports; ``ck_*`` hold the
  state at the checkpoint.  The state at any other block is a copy away (``load_state``, then
  ``materialise`` for the lists a block touches): a block's transactions are applied once, on its parent's
  state, and a reorganisation undoes and redoes payments by switching states.
* **Measures** (the log): blocks made, forks, reorganisations and the transactions they dropped, failed
  transactions, deposit-to-payment delays, every robot's summed view lag.

Memory: the blocks since the checkpoint (each with O(pending / 64) bits, and an O(n) state row if it
includes transactions), the list nodes they use and their cached weights, the mempool with its known-bits
(O(n x transactions in flight)), two ledgers (the checkpoint's without its lists: its block keeps them).
Every array is sized by what is live (the host packs the arenas); nothing grows with the run's history.
First capacities scale with the swarm (``POOL_PER_ROBOT``, ``MEMPOOL_PER_ROBOT``, ``ENTRIES_PER_ROBOT``),
zeroed, so a run seldom stops for the host to grow an array and untouched room takes no memory.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from ..state.spec import Spec, fields
from ..state.view import unlock
from .kernels import reserve
from .mempool import (DEPOSIT, REVEAL, STAKE_TOLERANCE, chance, drop_own, knows, learn, mix, nest_side, on_branch,
                      partitioned, refresh_view)
from .gas import table_gas
from .state import TX_POOL

#: The checkpoint's copy of each ledger field (``ck_<field>``) but the buyers' lists of open transactions
#: (the checkpoint's block state keeps those, ``bs_ver``; ``ck_tx_off``, ``ck_tx_cap`` and ``ck_pool_top``
#: only bound what the transaction pool may need, ``chain_needs``).
CHECKPOINTED = ("balance", "pot", "burned", "tx_off", "tx_cap", "tx_count", "pool_top", "money",
                "rep_settled", "rep_reduced", "rep_earned", "rep_stake_lost", "rep_deposits", "gas_paid")
#: The ledger fields each block keeps (``bs_<field>``; the balances are ``blk_bal``; each buyer's open
#: transactions are a version of its list, ``bs_ver``), so the state after any live block is a copy away:
#: nothing is replayed.
BLOCK_STATE = ("pot", "burned", "tx_count", "money", "rep_settled", "rep_reduced", "rep_earned",
               "rep_stake_lost", "rep_deposits", "gas_paid")
_LEDGER_KINDS = {"balance": ("float64", "n"), "pot": ("float64", "n"), "burned": ("float64", "1"),
                 "tx_off": ("int64", "n"), "tx_cap": ("int64", "n"), "tx_count": ("int64", "n"),
                 "tx_seller": ("int64", "P"), "tx_site": ("int64", "P"), "tx_dir": ("float64", "P"),
                 "tx_step": ("int64", "P"), "tx_stake": ("float64", "P"), "pool_top": ("int64", "1"),
                 "money": ("float64", "1"), "rep_settled": ("int64", "n"), "rep_reduced": ("int64", "n"),
                 "rep_earned": ("float64", "n"), "rep_stake_lost": ("float64", "n"),
                 "rep_deposits": ("int64", "n"), "gas_paid": ("float64", "n")}

#: Shapes: ``Bc`` block slots, ``Bt`` entries of the blocks' transaction lists, ``T`` mempool slots (a multiple of 64), ``T/64`` words of known-bits,
#: ``C`` open transactions a block's state can hold, ``S`` signers, ``G`` points of the deposit-gas table.
SPEC = Spec("chain", [
    *fields("host", [
        ("chn_period", "int", "", "block period P, steps: an in-turn signer makes a block P steps after its head's"),
        ("chn_delay", "int", "", "extra steps an out-of-turn signer waits (P + delay after its head's block)"),
        ("chn_signers", "int64", "S", "the signer set (robot ids); block h is in turn for signers[h % S]"),
        ("chn_backbone", "bool", "", "a backbone also carries every transaction and block to every robot"),
        ("chn_latency", "int", "", "the backbone's latency, steps"),
        ("chn_loss", "float", "", "probability that a message between two neighbours is lost"),
        ("chn_gas_price", "float", "", "money per unit of gas"),
        ("chn_gas_reveal", "float", "", "gas of one reveal (docs/gas.md)"),
        ("chn_gas_n", "float64", "G", "deposit-gas table: reveals settled"),
        ("chn_gas_deposit", "float64", "G", "deposit-gas table: gas"),
        ("chn_seed", "int", "", "seed of the chain's own draws (message loss)"),
        ("chn_final", "int", "", "finality depth F: a block F blocks below the canonical head is final"),
        ("chn_part_start", "int", "", "first step of the partition (-1: none)"),
        ("chn_part_end", "int", "", "step the partition ends (not partitioned any more)"),
        ("chn_cache", "bool", "", "the payment scheme reads neither the market nor rng: a list's weights are "
                                  "kept and reused when another branch settles the same list"),
    ]),
    *fields("ledger", [
        ("view_head", "int64", "n", "each robot's head block (a slot of the block store; -1: its branch "
                                    "was dropped, the robot keeps the head's height, weight and its balance)"),
        ("view_height", "int64", "n", "height of each robot's head"),
        ("view_weight", "int64", "n", "weight of each robot's head"),
        ("view_hash", "int64", "n", "hash of each robot's head"),
        ("view_bal", "float64", "n", "each robot's own balance at its head"),
        ("view_old", "int64", "n", "heads at the start of the gossip phase (what neighbours hear)"),
        ("view_avail", "float64", "n", "money each robot's view lets it spend: balance at its head less "
                                        "its own pending reveals' stakes and gas (up to date unless view_stale)"),
        ("view_stale", "bool", "n", "its head moved since view_avail was computed (mempool.refresh_view, "
                                    "done when the robot next sells or its head is dropped)"),
        ("chn_nblk", "int64", "1", "live blocks"),
        ("chn_slots", "int64", "1", "1 + the highest block slot ever used (slots from it on are untouched)"),
        ("chn_free", "int64", "1", "every block slot below it is taken (where new_block looks for the lowest "
                                   "free one)"),
        ("gas_paid", "float64", "n", "gas each robot has paid on the canonical chain"),
        ("blk_live", "bool", "Bc", "slot holds a block (the checkpoint or one after it)"),
        ("blk_parent", "int64", "Bc", "parent slot (-1 for the checkpoint)"),
        ("blk_height", "int64", "Bc", "height (genesis 0)"),
        ("blk_weight", "int64", "Bc", "total difficulty: +2 in turn, +1 out of turn"),
        ("blk_hash", "int64", "Bc", "hash (ties between equally heavy heads go to the lower)"),
        ("blk_signer", "int64", "Bc", "robot that made it (-1 genesis)"),
        ("blk_step", "int64", "Bc", "step it was made"),
        ("blk_kids", "int64", "Bc", "blocks made on it"),
        ("blk_bb", "bool", "Bc", "delivered by the backbone"),
        ("blk_mark", "int8", "Bc", "scratch of move_checkpoint: 1 descends from the new checkpoint, 2 not"),
        ("blk_ntx", "int64", "Bc", "transactions it includes"),
        ("blk_txoff", "int64", "Bc", "where its transactions start in blk_tx"),
        ("blk_tx", "int64", "Bt", "block b's transactions (mempool slots, in the order they were sent) are "
                                  "blk_tx[blk_txoff[b] : blk_txoff[b] + blk_ntx[b]]"),
        ("chn_txtop", "int64", "1", "first unused entry of blk_tx (the host packs the live blocks' entries)"),
        ("blk_st", "int64", "Bc", "the ledger state after the block (a row of blk_bal and bs_*): a new one "
                                  "for a block with transactions, its parent's for a block without"),
        ("st_used", "bool", "Bc", "the state row is some live block's (blk_st)"),
        ("chn_stfree", "int64", "1", "every state row below it is used (where new_block looks for a free one)"),
        ("blk_bal", "float64", "Bc,n", "every robot's balance in each state (row blk_st[b]: after block b; "
                                       "balances_after)"),
        ("blk_inc", "uint64", "Bc,T/64", "bit tx: pending transaction tx is included on its branch after the "
                                         "checkpoint"),
        *[(f"bs_{f}", _LEDGER_KINDS[f][0], "Bc" if _LEDGER_KINDS[f][1] == "1" else "Bc,n",
           f"{f} after the block (its ledger state, with blk_bal)") for f in BLOCK_STATE],
        ("bs_ver", "int64", "Bc,n", "each buyer's open transactions after the block: the list node "
                                    "bs_ver[b, i] and its predecessors (ls_prev), the last one first "
                                    "(-1: none)"),
        *[(f"ls_{f[3:]}", _LEDGER_KINDS[f][0], "L", f"{f} of a node of the buyers' lists of open transactions "
                                                    f"(one open transaction)") for f in TX_POOL],
        ("ls_prev", "int64", "L", "the node before it in its list (-1: it is the first)"),
        ("ls_len", "int64", "L", "length of the list that ends with it"),
        ("ls_seq", "int64", "L", "sending order (mp_seq) of the reveal it records"),
        ("ls_buyer", "int64", "L", "the buyer whose list it is in"),
        ("ls_kid", "int64", "L", "first node made after it (-1: none); the others are its ls_sib chain"),
        ("ls_sib", "int64", "L", "next node with the same predecessor (-1: none)"),
        ("ls_wt", "int64", "L", "where the payment scheme's weights of the list ending here start in "
                                "chn_wt (-1: not weighed yet)"),
        ("chn_lroot", "int64", "n", "each buyer's first node of a list (-1: none); the others, its ls_sib chain"),
        ("chn_lstop", "int64", "1", "first unused node (the host packs the nodes live blocks use)"),
        ("chn_wt", "float64", "W", "weights of settled lists, ls_len[v] of them from ls_wt[v] (the settlement "
                                   "cache)"),
        ("chn_wttop", "int64", "1", "first unused entry of chn_wt"),
        ("chn_bver", "int64", "n", "each buyer's list (a node) in the state the ledger arrays hold, or in the "
                                   "block being applied"),
        ("chn_ver", "int64", "n", "the list (a node) of each buyer whose transactions the ledger arrays' "
                                  "pool holds (materialise)"),
        ("chn_unheld", "bool", "1", "some buyer's list in chn_bver may not be the one the pool holds "
                                    "(chn_ver): set when a state is loaded or a list grows"),
        ("chn_ckpt", "int64", "1", "the checkpoint's slot"),
        ("chn_canon", "int64", "1", "the canonical head's slot"),
        ("chn_cur", "int64", "1", "a live block whose state the ledger arrays hold"),
        ("chn_mute", "int64", "1", "1 mutes the event and payment logs and the measures (blocks are applied "
                                   "once each and never replayed: stays 0)"),
        ("chn_seq", "int64", "1", "transactions sent so far (their order)"),
        ("chn_nopen", "int64", "1", "reveals the deposit being applied settles"),
        ("chn_behind", "int64", "1", "the robot whose head kept next_checkpoint from moving the checkpoint "
                                     "last time (checked first next time)"),
        ("mp_live", "bool", "T", "slot holds a pending transaction"),
        ("mp_cursor", "int64", "1", "where the next free slot is looked for"),
        ("mp_order", "int64", "T", "the pending transactions' slots in sending order (the first mp_count)"),
        ("mp_words", "int64", "1", "words of known-bits in use: every pending slot is below 64 x mp_words"),
        ("mp_onext", "int64", "T", "a pending reveal's sender's next own pending reveal (-1: none)"),
        ("mp_oprev", "int64", "T", "... and previous one (-1: none)"),
        ("own_first", "int64", "n", "each robot's oldest own pending reveal (-1: none)"),
        ("own_last", "int64", "n", "each robot's newest own pending reveal (-1: none)"),
        ("mp_count", "int64", "1", "pending transactions"),
        ("mp_for_buyer", "int64", "n", "pending reveals per buyer"),
        ("mp_own", "int64", "n", "pending reveals per seller (0: its view is its balance at its head)"),
        ("mp_kind", "int64", "T", "REVEAL / DEPOSIT"),
        ("mp_origin", "int64", "T", "robot that sent it (the seller of a reveal, the depositor)"),
        ("mp_buyer", "int64", "T", "buyer (the depositor for a deposit)"),
        ("mp_seller", "int64", "T", "seller (-1)"),
        ("mp_site", "int64", "T", "site (-1)"),
        ("mp_dir", "float64", "T", "direction of the bought vector, degrees"),
        ("mp_stake", "float64", "T", "stake the seller's view locked"),
        ("mp_gas", "float64", "T", "gas cost the sender's view set aside"),
        ("mp_step", "int64", "T", "step it was sent"),
        ("mp_seq", "int64", "T", "its place in sending order"),
        ("mp_bb", "bool", "T", "delivered by the backbone"),
        ("mp_known", "uint64", "n,T/64", "bit tx of row i: robot i knows transaction tx"),
        ("mp_old", "uint64", "n,T/64", "known-bits at the start of the gossip phase"),
        ("mp_mask", "uint64", "T/64", "scratch of move_checkpoint (all 0 between calls)"),
        *[(f"ck_{f}", _LEDGER_KINDS[f][0], _LEDGER_KINDS[f][1], f"{f} at the checkpoint")
          for f in CHECKPOINTED],
    ]),
    *fields("log", [
        ("chn_blocks", "int64", "1", "blocks made"),
        ("chn_forks", "int64", "1", "blocks made on a parent that already had a child"),
        ("chn_reorgs", "int64", "1", "times the canonical head moved to another branch"),
        ("chn_reorg_tx", "int64", "1", "transactions those moves took out of the canonical chain"),
        ("chn_view_reorgs", "int64", "1", "times a robot's head moved to a block not descending from it"),
        ("chn_failed", "int64", "1", "included transactions that failed (the branch could not pay)"),
        ("chn_delay_sum", "int64", "1", "summed steps from deposit to the block that paid it"),
        ("chn_delay_count", "int64", "1", "deposits paid"),
        ("chn_lag_sum", "int64", "n", "each robot's summed lag (canonical height - its head's), per step"),
    ]),
])

#: First capacities: block slots (at least 16, at most 1024, as many as ``BLOCK_STATE_BYTES`` of block
#: states hold: each is O(robots); the arrays are allocated zeroed, so a slot takes memory only once a
#: block has been made in it) and mempool slots.  Generous first sizes spare a run most of the host's
#: growth calls, which cost as much as many steps (at 10 000 robots, each copies every live block's
#: state); they change no number.
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
#: First size of the settlement cache (``chn_wt``).
WEIGHT_ENTRIES = 1 << 17
#: First size of the ledger's transaction pool in a chain world: ``POOL_ENTRIES`` and ``POOL_PER_ROBOT`` a
#: robot (the instant ledger's is ``ledger.state.TX_CAPACITY`` a robot).  ``chain_needs`` bounds what any
#: branch's lists may need: a paper-size run reaches 30 000-70 000 entries, 10 000 robots 850 000.
POOL_ENTRIES = 1 << 16
POOL_PER_ROBOT = 128
#: Mempool slots a robot at first (at least ``MEMPOOL_CAPACITY``): ``chain_needs`` keeps a slot for every
#: purchase a step could make, about 2 x the robots of a large swarm.
MEMPOOL_PER_ROBOT = 3


def first_block_slots(n: int) -> int:
    """Block slots a fresh chain of n robots starts with (``BLOCK_CAPACITY``, ``BLOCK_STATE_BYTES``)."""
    per_block = 8 * n * (len(BLOCK_STATE) + 2)  # blk_bal, bs_*, bs_ver
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
        "chn_part_end": -1 if partition is None else int(partition[1]), "chn_cache": bool(cache_weights), "view_height": z(n, np.int64), "view_weight": z(n, np.int64),
        "view_hash": np.full(n, np.int64(int(seed) % (2**62)), np.int64), "view_bal": ledger["balance"].copy(),
        "view_head": z(n, np.int64), "view_old": z(n, np.int64), "view_avail": ledger["balance"].copy(),
        "view_stale": z(n, np.bool_), "chn_nblk": np.ones(1, np.int64), "chn_free": np.ones(1, np.int64), "chn_slots": np.ones(1, np.int64),
        "gas_paid": z(n),
        "blk_live": z(bc, np.bool_), "blk_parent": np.full(bc, -1, np.int64), "blk_height": z(bc, np.int64),
        "blk_weight": z(bc, np.int64), "blk_hash": z(bc, np.int64), "blk_signer": np.full(bc, -1, np.int64),
        "blk_step": z(bc, np.int64), "blk_kids": z(bc, np.int64), "blk_bb": z(bc, np.bool_),
        "blk_mark": z(bc, np.int8), "blk_st": z(bc, np.int64), "st_used": z(bc, np.bool_),
        "chn_stfree": np.ones(1, np.int64),
        "blk_ntx": z(bc, np.int64), "blk_txoff": z(bc, np.int64), "blk_tx": z(TX_ENTRIES + ENTRIES_PER_ROBOT * n, np.int64), "blk_bal": z((bc, n)), "blk_inc": z((bc, _words(t)), np.uint64),
        "chn_ckpt": z(1, np.int64), "chn_canon": z(1, np.int64), "chn_cur": z(1, np.int64),
        "chn_mute": z(1, np.int64), "chn_seq": z(1, np.int64),
        "chn_nopen": z(1, np.int64), "chn_behind": z(1, np.int64), "chn_txtop": z(1, np.int64),
        "mp_live": z(t, np.bool_), "mp_cursor": z(1, np.int64), "mp_order": z(t, np.int64),
        "mp_words": z(1, np.int64), "mp_onext": np.full(t, -1, np.int64), "mp_oprev": np.full(t, -1, np.int64),
        "own_first": np.full(n, -1, np.int64), "own_last": np.full(n, -1, np.int64), "mp_count": z(1, np.int64),
        "mp_for_buyer": z(n, np.int64), "mp_own": z(n, np.int64), "mp_kind": z(t, np.int64),
        "mp_origin": z(t, np.int64),
        "mp_buyer": z(t, np.int64), "mp_seller": z(t, np.int64), "mp_site": z(t, np.int64), "mp_dir": z(t),
        "mp_stake": z(t), "mp_gas": z(t), "mp_step": z(t, np.int64), "mp_seq": z(t, np.int64),
        "mp_bb": z(t, np.bool_),
        "mp_known": z((n, _words(t)), np.uint64), "mp_old": z((n, _words(t)), np.uint64),
        "mp_mask": z(_words(t), np.uint64),
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
    chain["bs_ver"] = np.full((bc, n), -1, np.int64)
    for f in TX_POOL:
        chain[f"ls_{f[3:]}"] = z(LIST_ENTRIES + ENTRIES_PER_ROBOT * n, ledger[f].dtype)
    for f in ("ls_prev", "ls_len", "ls_seq", "ls_buyer", "ls_kid", "ls_sib", "ls_wt"):
        chain[f] = np.full(LIST_ENTRIES + ENTRIES_PER_ROBOT * n, -1, np.int64)
    chain["chn_lroot"] = np.full(n, -1, np.int64)
    chain["chn_lstop"] = z(1, np.int64)
    chain["chn_wt"] = z(WEIGHT_ENTRIES)
    chain["chn_wttop"] = z(1, np.int64)
    chain["chn_ver"] = np.full(n, -1, np.int64)
    chain["chn_unheld"] = z(1, np.bool_)
    chain["chn_bver"] = np.full(n, -1, np.int64)
    # genesis: slot 0, height 0, every robot's head, the checkpoint and the canonical head
    chain["blk_live"][0] = True
    chain["st_used"][0] = True  # genesis's state is row 0
    chain["blk_hash"][0] = np.int64(int(seed) % (2**62))
    chain["blk_bal"][0] = ledger["balance"]
    for f in BLOCK_STATE:  # genesis's state: the fresh ledger (no open transaction)
        v = chain["gas_paid"] if f == "gas_paid" else ledger[f]
        chain[f"bs_{f}"][0] = v[0] if v.shape == (1,) else v
    SPEC.check(chain)
    return chain


def used_states(world) -> np.ndarray:
    """The state rows live blocks use (of ``blk_bal`` and ``bs_*``)."""
    return np.flatnonzero(world.st_used)


def balances_after(world, b: int) -> np.ndarray:
    """Every robot's balance after live block b (a view of its state's row)."""
    return world.blk_bal[world.blk_st[b]]


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
    entries and what the next step adds (``entries - chn_txtop``) do not fit twice."""
    live = np.flatnonzero(world.blk_live)
    off, ntx = world.blk_txoff, world.blk_ntx
    used = int(ntx[live].sum())
    size = max(world.blk_tx.shape[0], 4 * (used + entries - int(world.chn_txtop[0])))
    new = np.zeros(size, np.int64)
    new_off = changes.get("blk_txoff", off).copy()
    sizes = ntx[live]
    starts = (np.cumsum(sizes) - sizes).astype(np.int64)
    new[:used] = world.blk_tx[np.repeat(off[live] - starts, sizes) + np.arange(used, dtype=np.int64)]
    new_off[live] = starts
    return {"blk_tx": new, "blk_txoff": new_off, "chn_txtop": np.array([used], np.int64)}


def _packed_lists(world, changes: dict, lists: int) -> dict:
    """The list nodes that live blocks and the ledger arrays use, packed in their order (``ls_prev``,
    ``bs_ver``, ``chn_ver``, ``chn_bver`` renumbered; ``ls_kid``, ``ls_sib``, ``chn_lroot`` rebuilt; the kept
    nodes' cached weights packed too), grown when they and what the next step adds (``lists - chn_lstop``)
    do not fit twice."""
    rows = used_states(world)
    top = int(world.chn_lstop[0])
    keep = np.zeros(top, np.bool_)
    _reachable(world.ls_prev, np.concatenate([world.bs_ver[rows].ravel(), world.chn_ver, world.chn_bver]), keep)
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
    for f in ("ls_prev", "ls_len", "ls_seq", "ls_buyer", "ls_kid", "ls_sib", "ls_wt"):
        out[f] = np.empty(size, np.int64)
        out[f][:total] = -1
    out["ls_prev"][:total] = new_of[world.ls_prev[old]]
    for f in ("ls_len", "ls_seq", "ls_buyer"):
        out[f][:total] = getattr(world, f)[old]
    wt_old = world.ls_wt[old]
    cached = wt_old >= 0
    lens = out["ls_len"][:total][cached]
    starts = (np.cumsum(lens) - lens).astype(np.int64)
    used = int(lens.sum())
    src = np.repeat(wt_old[cached] - starts, lens) + np.arange(used, dtype=np.int64)
    wsize = max(world.chn_wt.shape[0], 4 * used, 2 * lists)
    wt = np.empty(wsize)
    wt[:used] = world.chn_wt[src]
    out["ls_wt"][:total][cached] = starts
    roots = np.full(world.chn_lroot.shape[0], -1, np.int64)
    _relink(out["ls_prev"], out["ls_buyer"], out["ls_kid"], out["ls_sib"], roots, total)

    def renumber(v):
        return new_of[v]

    bs_ver = changes.get("bs_ver", world.bs_ver)  # (grown already when the block slots grew; renumbered in
    # place: the world this packs is replaced by the one make_room returns)
    bs_ver[rows] = renumber(world.bs_ver[rows])
    out.update(bs_ver=bs_ver, chn_ver=renumber(world.chn_ver), chn_bver=renumber(world.chn_bver),
               chn_lroot=roots, chn_lstop=np.array([total], np.int64), chn_wt=wt,
               chn_wttop=np.array([used], np.int64))
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
                  "mp_gas", "mp_step", "mp_seq", "mp_bb", "mp_order", "mp_onext", "mp_oprev"):
            changes[f] = _grown(getattr(world, f), 0, size)
        for f in ("mp_known", "mp_old", "blk_inc"):
            changes[f] = _grown(getattr(world, f), 1, _words(size))
        changes["mp_mask"] = _grown(world.mp_mask, 0, _words(size))
    bc = world.blk_live.shape[0]
    if blocks > bc:
        size = max(2 * bc, blocks)
        for f in ("blk_live", "blk_height", "blk_weight", "blk_hash", "blk_step", "blk_kids", "blk_bb", "blk_mark", "blk_ntx",
                  "blk_txoff", "blk_st", "st_used"):
            changes[f] = _grown(getattr(world, f), 0, size)
        for f in ("blk_parent", "blk_signer"):
            changes[f] = _grown(getattr(world, f), 0, size, -1)
        # a new slot's bits and a new state row are written whole when first used (new_block, save_state),
        # and nothing reads a free one: the new rows are left untouched (no memory until used), and only
        # the live blocks' bits and the used state rows are copied
        rows = used_states(world)
        changes["blk_bal"] = _grown_rows(world.blk_bal, rows, size)
        changes["blk_inc"] = _grown_rows(changes.get("blk_inc", world.blk_inc), np.flatnonzero(world.blk_live), size)
        for f in BLOCK_STATE:
            changes[f"bs_{f}"] = _grown_rows(getattr(world, f"bs_{f}"), rows, size)
        changes["bs_ver"] = _grown_rows(world.bs_ver, rows, size)
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
    live = w.chn_nblk[0]
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
    entries = w.chn_txtop[0] + (due + 2) * mp  # every block made holds at most the whole mempool
    lists = w.chn_lstop[0] + (due + 2) * reveals  # a block makes at most a node per pending reveal
    return mp, live + due + 1, pool, events, payments, lists, entries


@njit
def room_fits(w):
    """Does the next step fit in the chain's arrays (and, when recording, the logs)?"""
    mp, blocks, pool, events, payments, lists, entries = chain_needs(w)
    if mp > w.mp_live.shape[0] or blocks > w.blk_live.shape[0] or pool > w.tx_seller.shape[0]:
        return False
    if lists > w.ls_seller.shape[0] or entries > w.blk_tx.shape[0]:
        return False
    return not w.record or (events <= w.ev_step.shape[0] and payments <= w.pay_step.shape[0])


@njit
def can_make(w):
    """Is there room for one more block this step (a free slot, room for its transactions and its
    buyers' lists, log rows for its settlements)?  A signer that finds none makes its block in a later
    step, after the host has grown the arrays (``chain_needs`` plans for the signers due at the step's
    start and two more, so this is rare)."""
    if w.chn_nblk[0] >= w.blk_live.shape[0] or w.chn_txtop[0] + w.mp_count[0] > w.blk_tx.shape[0]:
        return False
    payments = 0  # any branch's open transactions: its checkpoint's and the pending reveals
    reveals = 0
    for i in range(w.tx_count.shape[0]):
        payments += max(w.tx_count[i], w.ck_tx_count[i]) + w.mp_for_buyer[i]
        reveals += w.mp_for_buyer[i]
    if w.chn_lstop[0] + reveals > w.ls_seller.shape[0]:
        return False
    if not w.record:
        return True
    return (w.ev_count[0] + w.mp_count[0] <= w.ev_step.shape[0]
            and w.pay_count[0] + payments <= w.pay_step.shape[0])


# ---- compiled: blocks ---------------------------------------------------------------------------------

@njit(inline="always")
def heavier(w, a, b):
    """Is block a heavier than block b: more total difficulty, or as much and a lower hash."""
    wa = w.blk_weight[a]
    wb = w.blk_weight[b]
    return wa > wb or (wa == wb and w.blk_hash[a] < w.blk_hash[b])


@njit(inline="always")
def ancestor_at(w, b, height):
    """The block on b's branch at ``height`` (b itself when b is not higher)."""
    while w.blk_height[b] > height:
        b = w.blk_parent[b]
    return b


@njit
def in_turn(w, height):
    """The signer whose turn block ``height`` is."""
    s = w.chn_signers
    return s[height % s.shape[0]]


@njit
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


@njit
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


@njit
def new_block(w, signer, t):
    """``signer`` makes a block on its head at step t, holding every pending transaction it knows that
    its branch does not include yet, in sending order.  Returns its slot (the ledger is not touched)."""
    parent = w.view_head[signer]
    live = unlock(w.blk_live)
    b = w.chn_free[0]  # every slot below it is taken: the lowest free slot is at or above it
    while live[b]:
        b += 1  # the host keeps a free slot for every block a step can make
    unlock(w.chn_free)[0] = b + 1
    if b >= w.chn_slots[0]:
        unlock(w.chn_slots)[0] = b + 1
    height = w.blk_height[parent] + 1
    live[b] = True
    unlock(w.chn_nblk)[0] += 1
    unlock(w.blk_parent)[b] = parent
    unlock(w.blk_height)[b] = height
    unlock(w.blk_weight)[b] = w.blk_weight[parent] + (2 if in_turn(w, height) == signer else 1)
    h = mix(np.uint64(w.blk_hash[parent]) ^ (np.uint64(height) * np.uint64(0x9E3779B97F4A7C15)))
    h = mix(h ^ (np.uint64(signer) + np.uint64(t) * np.uint64(0xD6E8FEB86659FD93)))
    unlock(w.blk_hash)[b] = np.int64(h >> np.uint64(2))
    unlock(w.blk_signer)[b] = signer
    unlock(w.blk_step)[b] = t
    unlock(w.blk_kids)[b] = 0
    unlock(w.blk_bb)[b] = False
    unlock(w.blk_kids)[parent] += 1
    unlock(w.chn_blocks)[0] += 1
    if w.blk_kids[parent] > 1:
        unlock(w.chn_forks)[0] += 1
    top = w.chn_txtop[0]
    txs = unlock(w.blk_tx)[top:]
    inc = unlock(w.blk_inc)
    k = 0
    for word in range(inc.shape[1]):  # known (so pending) and not on the parent's branch
        if word >= w.mp_words[0]:
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
        unlock(w.blk_st)[b] = w.blk_st[parent]
    else:  # a state row of its own (there are never more states than blocks): the lowest free one
        used = unlock(w.st_used)
        s = w.chn_stfree[0]
        while used[s]:
            s += 1
        used[s] = True
        unlock(w.chn_stfree)[0] = s + 1
        unlock(w.blk_st)[b] = s
    unlock(w.chn_txtop)[0] = top + k
    return b


@njit
def include_tx(w, b, tx):
    """Apply transaction ``tx`` of block b to the ledger arrays.  A reveal: the seller pays the gas and
    locks the stake if the branch's balance covers both (the view's check, on the branch), and the
    buyer's open list gets it; else it fails and moves nothing.  A deposit: True, the caller settles it
    (``distribute`` pays the reward and the sellers) and then calls ``finish_deposit``."""
    buyer = w.mp_buyer[tx]
    if w.mp_kind[tx] == DEPOSIT:
        materialise(w, buyer)  # the settlement weighs its list in the ledger arrays
        unlock(w.chn_nopen)[0] = w.tx_count[buyer]
        return True
    seller = w.mp_seller[tx]
    balance, money = unlock(w.balance), unlock(w.money)
    gas = w.mp_gas[tx]
    if w.stake > 0.0 or gas > 0.0:
        if balance[seller] < w.stake + gas - STAKE_TOLERANCE:
            if w.chn_mute[0] == 0:
                unlock(w.chn_failed)[0] += 1
            return False
    count = w.tx_count[buyer]
    if gas > 0.0:
        balance[seller] -= gas
        money[0] -= gas
        unlock(w.gas_paid)[seller] += gas
    lock = 0.0
    if w.stake > 0.0:
        lock = min(w.stake, balance[seller])
        balance[seller] -= lock
        money[0] -= lock
        unlock(w.pot)[buyer] += lock
    unlock(w.chn_unheld)[0] = True
    unlock(w.chn_bver)[buyer] = append_node(w, buyer, w.chn_bver[buyer], w.mp_seq[tx], seller, w.mp_site[tx],
                                            w.mp_dir[tx], w.mp_step[tx], lock)
    unlock(w.tx_count)[buyer] = count + 1  # (the pool gets the list when it is next weighed or read)
    return False


@njit
def append_node(w, buyer, prev, seq, seller, site, direction, step, stake):
    """The list node after ``prev`` (-1: a first one) of buyer's list recording reveal ``seq``: an
    existing one with the same content, else a new one (``chn_lstop``; the host keeps room).  A list is
    then one node whatever branch made it, and a settled list's cached weights serve every branch."""
    x = w.ls_kid[prev] if prev >= 0 else w.chn_lroot[buyer]
    first = x
    while x >= 0:
        if (w.ls_seq[x] == seq and w.ls_stake[x] == stake
                and math.copysign(1.0, w.ls_stake[x]) == math.copysign(1.0, stake)):
            return x
        x = w.ls_sib[x]
    top = w.chn_lstop[0]
    unlock(w.ls_seller)[top] = seller
    unlock(w.ls_site)[top] = site
    unlock(w.ls_dir)[top] = direction
    unlock(w.ls_step)[top] = step
    unlock(w.ls_stake)[top] = stake
    unlock(w.ls_prev)[top] = prev
    unlock(w.ls_len)[top] = (w.ls_len[prev] if prev >= 0 else 0) + 1
    unlock(w.ls_seq)[top] = seq
    unlock(w.ls_buyer)[top] = buyer
    unlock(w.ls_kid)[top] = -1
    unlock(w.ls_sib)[top] = first
    unlock(w.ls_wt)[top] = -1
    if prev >= 0:
        unlock(w.ls_kid)[prev] = top
    else:
        unlock(w.chn_lroot)[buyer] = top
    unlock(w.chn_lstop)[0] = top + 1
    return top


@njit
def cached_weights(w, v, k):
    """The k weights cached for list node v (``cache_weights``), as the same array type a fresh weighing
    gives (the settlement reads them; only ledger operations may unlock ledger arrays)."""
    return unlock(w.chn_wt)[w.ls_wt[v]:w.ls_wt[v] + k]


@njit
def cache_weights(w, v, weights):
    """Keep the weights of list v (its ls_len[v] transactions) for the next settlement of the same list, if
    the cache has room (the host packs it with the lists)."""
    top = w.chn_wttop[0]
    k = weights.shape[0]
    if top + k > w.chn_wt.shape[0]:
        return
    wt = unlock(w.chn_wt)
    for x in range(k):
        wt[top + x] = weights[x]
    unlock(w.ls_wt)[v] = top
    unlock(w.chn_wttop)[0] = top + k


@njit
def deposit_gas(w, n):
    """Gas of a deposit that settles n reveals (the world's deposit-gas table)."""
    return table_gas(w.chn_gas_n, w.chn_gas_deposit, n)


@njit
def finish_deposit(w, b, tx):
    """After a deposit's settlement: the depositor pays the deposit's gas (never below a zero balance),
    and its delay from sending to this block is measured (first application only)."""
    buyer = w.mp_buyer[tx]
    unlock(w.chn_bver)[buyer] = -1  # the settlement emptied its list
    unlock(w.chn_ver)[buyer] = -1
    if w.chn_gas_price > 0.0:
        cost = min(w.chn_gas_price * deposit_gas(w, float(w.chn_nopen[0])), w.balance[buyer])
        unlock(w.balance)[buyer] -= cost
        unlock(w.money)[0] -= cost
        unlock(w.gas_paid)[buyer] += cost
    if w.chn_mute[0] == 0:
        unlock(w.chn_delay_sum)[0] += w.blk_step[b] - w.mp_step[tx]
        unlock(w.chn_delay_count)[0] += 1


@njit
def save_checkpoint(w):
    """The ledger arrays' state becomes the checkpoint's (``ck_*``).  Its buyers' lists of open
    transactions are not copied: the checkpoint is a live block, whose state keeps them (``bs_ver``)."""
    _copy_ledger(w.balance, w.pot, w.burned, w.tx_off, w.tx_cap, w.tx_count, w.pool_top, w.money, w.rep_settled,
                 w.rep_reduced, w.rep_earned, w.rep_stake_lost, w.rep_deposits, w.gas_paid,
                 unlock(w.ck_balance), unlock(w.ck_pot), unlock(w.ck_burned), unlock(w.ck_tx_off),
                 unlock(w.ck_tx_cap), unlock(w.ck_tx_count), unlock(w.ck_pool_top), unlock(w.ck_money),
                 unlock(w.ck_rep_settled), unlock(w.ck_rep_reduced), unlock(w.ck_rep_earned),
                 unlock(w.ck_rep_stake_lost), unlock(w.ck_rep_deposits), unlock(w.ck_gas_paid))


@njit
def _copy_ledger(balance, pot, burned, tx_off, tx_cap, tx_count, pool_top, money, rep_settled, rep_reduced,
                 rep_earned, rep_stake_lost, rep_deposits, gas_paid, o_balance, o_pot, o_burned, o_tx_off, o_tx_cap,
                 o_tx_count, o_pool_top, o_money, o_rep_settled, o_rep_reduced, o_rep_earned, o_rep_stake_lost,
                 o_rep_deposits, o_gas_paid):
    o_balance[:] = balance
    o_pot[:] = pot
    o_burned[:] = burned
    o_tx_off[:] = tx_off
    o_tx_cap[:] = tx_cap
    o_tx_count[:] = tx_count
    o_pool_top[0] = pool_top[0]
    o_money[0] = money[0]
    o_rep_settled[:] = rep_settled
    o_rep_reduced[:] = rep_reduced
    o_rep_earned[:] = rep_earned
    o_rep_stake_lost[:] = rep_stake_lost
    o_rep_deposits[:] = rep_deposits
    o_gas_paid[:] = gas_paid


@njit
def same_state(w, a, b):
    """Do blocks a and b have the same state (the same row: one of them, or a block between, includes no
    transaction)?"""
    return w.blk_st[a] == w.blk_st[b]


@njit
def set_current(w, b):
    """The ledger arrays now hold the state after block b."""
    unlock(w.chn_cur)[0] = b


@njit
def save_state(w, b):
    """Block b's state (its row of ``blk_bal`` and ``bs_*``, ``blk_st``): the ledger arrays' (they hold the
    state after b), with each buyer's list as its node (``chn_bver``: nothing is copied)."""
    n = w.balance.shape[0]
    b = w.blk_st[b]
    bal, pot, count, ver = unlock(w.blk_bal), unlock(w.bs_pot), unlock(w.bs_tx_count), unlock(w.bs_ver)
    settled, reduced, earned = unlock(w.bs_rep_settled), unlock(w.bs_rep_reduced), unlock(w.bs_rep_earned)
    lost, deposits, gas = unlock(w.bs_rep_stake_lost), unlock(w.bs_rep_deposits), unlock(w.bs_gas_paid)
    for i in range(n):
        bal[b, i] = w.balance[i]
        pot[b, i] = w.pot[i]
        count[b, i] = w.tx_count[i]
        settled[b, i] = w.rep_settled[i]
        reduced[b, i] = w.rep_reduced[i]
        earned[b, i] = w.rep_earned[i]
        lost[b, i] = w.rep_stake_lost[i]
        deposits[b, i] = w.rep_deposits[i]
        gas[b, i] = w.gas_paid[i]
        ver[b, i] = w.chn_bver[i]
    unlock(w.bs_burned)[b] = w.burned[0]
    unlock(w.bs_money)[b] = w.money[0]


@njit
def load_state(w, b):
    """The ledger arrays get block b's state (``save_state``), except the buyers' lists of open
    transactions, which ``materialise`` copies when they are needed.  ``chn_cur`` is then b."""
    n = w.balance.shape[0]
    s = w.blk_st[b]
    balance, pot, count = unlock(w.balance), unlock(w.pot), unlock(w.tx_count)
    settled, reduced, earned = unlock(w.rep_settled), unlock(w.rep_reduced), unlock(w.rep_earned)
    lost, deposits, gas = unlock(w.rep_stake_lost), unlock(w.rep_deposits), unlock(w.gas_paid)
    bver = unlock(w.chn_bver)
    for i in range(n):
        balance[i] = w.blk_bal[s, i]
        pot[i] = w.bs_pot[s, i]
        count[i] = w.bs_tx_count[s, i]
        settled[i] = w.bs_rep_settled[s, i]
        reduced[i] = w.bs_rep_reduced[s, i]
        earned[i] = w.bs_rep_earned[s, i]
        lost[i] = w.bs_rep_stake_lost[s, i]
        deposits[i] = w.bs_rep_deposits[s, i]
        gas[i] = w.bs_gas_paid[s, i]
        bver[i] = w.bs_ver[s, i]
    unlock(w.chn_unheld)[0] = True
    unlock(w.burned)[0] = w.bs_burned[s]
    unlock(w.money)[0] = w.bs_money[s]
    unlock(w.chn_cur)[0] = b


@njit
def materialise(w, i):
    """Buyer i's open transactions in the ledger arrays' pool are its list in the current state
    (``chn_bver``): nothing to do if the pool holds that list; only the nodes after it if the pool holds a
    list it extends; else the whole list."""
    v = w.chn_bver[i]
    held = w.chn_ver[i]
    if held == v:
        return
    k = w.ls_len[v] if v >= 0 else 0
    h = w.ls_len[held] if held >= 0 else 0
    x = v  # is the held list a beginning of v's?  (a node is the list that ends with it)
    while x >= 0 and w.ls_len[x] > h:
        x = w.ls_prev[x]
    if x != held:
        h = 0
    unlock(w.tx_count)[i] = h  # what reserve moves if the block must move
    reserve(w, i, k)  # the host keeps room (chain_needs)
    a = w.tx_off[i]
    seller, site, dirs = unlock(w.tx_seller), unlock(w.tx_site), unlock(w.tx_dir)
    step, stake = unlock(w.tx_step), unlock(w.tx_stake)
    x = v
    while x >= 0 and w.ls_len[x] > h:  # the nodes after the held beginning, last first
        p = a + w.ls_len[x] - 1
        seller[p] = w.ls_seller[x]
        site[p] = w.ls_site[x]
        dirs[p] = w.ls_dir[x]
        step[p] = w.ls_step[x]
        stake[p] = w.ls_stake[x]
        x = w.ls_prev[x]
    unlock(w.tx_count)[i] = k
    unlock(w.chn_ver)[i] = v


@njit
def materialise_all(w):
    """Every buyer's list of the current state in the pool (nothing to do unless a list changed since the
    last call: ``chn_unheld``)."""
    if not w.chn_unheld[0]:
        return
    for i in range(w.balance.shape[0]):
        materialise(w, i)
    unlock(w.chn_unheld)[0] = False


@njit(inline="always")
def heavier_than_view(w, b, i):
    """Is block b heavier than robot i's head (its cached weight and hash: the head may be dropped)?"""
    return w.blk_weight[b] > w.view_weight[i] or (w.blk_weight[b] == w.view_weight[i]
                                                   and w.blk_hash[b] < w.view_hash[i])


@njit
def set_head(w, i, b):
    """Robot i's head becomes block b (a view reorganisation when its old head is not on b's branch)."""
    h = w.view_head[i]
    if h < 0 or ancestor_at(w, b, w.blk_height[h]) != h:
        unlock(w.chn_view_reorgs)[0] += 1
    unlock(w.view_head)[i] = b
    unlock(w.view_height)[i] = w.blk_height[b]
    unlock(w.view_weight)[i] = w.blk_weight[b]
    unlock(w.view_hash)[i] = w.blk_hash[b]
    unlock(w.view_bal)[i] = w.blk_bal[w.blk_st[b], i]
    unlock(w.view_stale)[i] = True


@njit
def adopt(w, i, b):
    """Robot i takes block b as its head if b is heavier than its head; True when it did."""
    if b == w.view_head[i] or not heavier_than_view(w, b, i):
        return False
    set_head(w, i, b)
    return True


@njit
def deliver_block(w, b):
    """The backbone brings block b to every robot; during a partition only to the robots on its signer's
    side, and to the others once it ends (``gossip``)."""
    if partitioned(w, w.clock[0]):
        side = w.blk_signer[b] >= 0 and nest_side(w, w.blk_signer[b])
        for i in range(w.view_head.shape[0]):
            if nest_side(w, i) == side:
                adopt(w, i, b)
        return
    unlock(w.blk_bb)[b] = True
    for i in range(w.view_head.shape[0]):
        adopt(w, i, b)


@njit
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
        ck = w.chn_ckpt[0]
        while x != ck:
            for k in range(w.blk_ntx[x]):
                if not on_branch(w, b, w.blk_tx[w.blk_txoff[x] + k]):
                    dropped += 1
            x = w.blk_parent[x]
        unlock(w.chn_reorgs)[0] += 1
        unlock(w.chn_reorg_tx)[0] += dropped
    return b


@njit
def next_checkpoint(w):
    """The block after the checkpoint on the canonical branch if it is final: every robot's head
    descends from it, or it lies ``chn_final`` blocks or more below the canonical head.  Else -1."""
    ck = w.chn_ckpt[0]
    canon = w.chn_canon[0]
    if canon == ck:
        return -1
    c = ancestor_at(w, canon, w.blk_height[ck] + 1)
    hc = w.blk_height[c]
    if w.blk_height[canon] - hc >= w.chn_final:
        return c  # final by depth, whoever has not heard of it
    n = w.view_head.shape[0]
    first = w.chn_behind[0]  # the robot that was behind last time is likely to be still
    for a in range(n):
        i = (first + a) % n
        h = w.view_head[i]
        if h < 0 or w.blk_height[h] < hc or ancestor_at(w, h, hc) != c:
            unlock(w.chn_behind)[0] = i
            return -1
    return c


@njit
def move_checkpoint(w, c):
    """Block c (whose state the ledger arrays hold) becomes the checkpoint: its state is saved, its
    transactions leave the mempool, and every block not descending from it is dropped; a robot whose
    head is dropped keeps its head's height, weight, hash and its own balance (``view_head`` -1) until
    it hears a heavier block."""
    save_checkpoint(w)
    set_current(w, c)
    live, known, mask = unlock(w.mp_live), unlock(w.mp_known), unlock(w.mp_mask)
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
    unlock(w.mp_words)[0] = (top >> 6) + 1 if k > 0 else 0
    unlock(w.mp_cursor)[0] = 0  # new transactions take the lowest free slots
    hc = w.blk_height[c]
    blive, inc, mark, used = unlock(w.blk_live), unlock(w.blk_inc), unlock(w.blk_mark), unlock(w.st_used)
    for b in range(w.chn_slots[0]):  # marks: 1 descends from c, 2 does not, 0 not known yet; and every
        mark[b] = 0  # state row is free until a kept block is found using it (rows used are below chn_slots)
        used[b] = False
    mark[c] = 1
    for b in range(w.chn_slots[0]):
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
    for b in range(w.chn_slots[0]):
        if not blive[b]:
            continue
        if mark[b] != 1:
            blive[b] = False
            unlock(w.chn_nblk)[0] -= 1
            unlock(w.chn_free)[0] = min(w.chn_free[0], b)
            continue
        for a in range(nw):  # final now: they leave every branch's pending set
            word = words[a]
            inc[b, word] &= ~mask[word]
        used[w.blk_st[b]] = True
    for a in range(nw):
        mask[words[a]] = 0
    s = 0
    while s < used.shape[0] and used[s]:
        s += 1
    unlock(w.chn_stfree)[0] = s
    unlock(w.blk_parent)[c] = -1
    unlock(w.chn_ckpt)[0] = c
    for i in range(n):
        h = w.view_head[i]
        if h >= 0 and not blive[h]:
            if w.view_stale[i]:
                refresh_view(w, i)  # what its view allowed on the dropped head
            unlock(w.view_head)[i] = -1


# ---- compiled: gossip ---------------------------------------------------------------------------------



@njit
def gossip(w):
    """One gossip round at the start of a step: every robot hears each neighbour's head and pending
    transactions as they were when the round began (so news travels one hop per step), each message
    lost with probability ``chn_loss``; the backbone delivers what is ``chn_latency`` steps old; each
    robot's view lag is measured."""
    t = w.clock[0]
    n = w.view_head.shape[0]
    old, heads = unlock(w.view_old), w.view_head
    mold, known = unlock(w.mp_old), unlock(w.mp_known)
    words = w.mp_words[0]  # (known-bits beyond are all 0)
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
            if not w.mp_bb[tx] and w.mp_step[tx] + w.chn_latency <= t:
                side = nest_side(w, w.mp_origin[tx])
                if not cut:
                    unlock(w.mp_bb)[tx] = True
                for i in range(n):
                    if not cut or nest_side(w, i) == side:
                        learn(w, i, tx)
        for b in range(w.blk_live.shape[0]):
            if w.blk_live[b] and not w.blk_bb[b] and w.blk_step[b] + w.chn_latency <= t:
                deliver_block(w, b)
    top = w.blk_height[w.chn_canon[0]]
    lag = unlock(w.chn_lag_sum)
    for i in range(n):
        lag[i] += top - w.view_height[i]
