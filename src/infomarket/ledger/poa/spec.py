"""The chain model's state (``SPEC``, the ``chain`` domain of a chain world; docs/chain-model.md), and
how compiled code tells a world that runs this ledger (``runs_poa``).

Only ledger operations write it, like the ledger's own fields; what each form of "the ledger after block
b" holds, and how they agree, is stated once in ``ledger.poa`` (the package's docstring) and checked by
``ledger.poa.invariants``.
"""
from __future__ import annotations

from ...state.spec import Spec, fields
from ..state import TX_POOL

#: The checkpoint's copy of each ledger field (``ck_<field>``) but the buyers' lists of open transactions
#: (the checkpoint's block state keeps those, ``bs_list``; ``ck_tx_off``, ``ck_tx_cap`` and ``ck_pool_top``
#: only bound what the transaction pool may need, ``chain_needs``).
CHECKPOINTED = ("balance", "pot", "burned", "tx_off", "tx_cap", "tx_count", "pool_top", "money",
                "rep_settled", "rep_reduced", "rep_earned", "rep_stake_lost", "rep_deposits", "gas_paid")
#: The ledger fields each block keeps (``bs_<field>``; the balances are ``blk_bal``; each buyer's open
#: transactions are a version of its list, ``bs_list``), so the state after any live block is a copy away:
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

#: Shapes: ``Bc`` block slots, ``Bt`` entries of the blocks' transaction lists, ``T`` mempool slots (a multiple of
#: 64), ``T/64`` words of known-bits,
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
        ("view_head_before", "int64", "n", "heads at the start of the gossip phase (what neighbours hear)"),
        ("view_avail", "float64", "n", "money each robot's view lets it spend: balance at its head less "
                                        "its own pending reveals' stakes and gas (up to date unless view_stale)"),
        ("view_stale", "bool", "n", "its head moved since view_avail was computed (mempool.refresh_view, "
                                    "done when the robot next sells or its head is dropped)"),
        ("blk_count", "int64", "1", "live blocks"),
        ("blk_slots_touched", "int64", "1", "1 + the highest block slot ever used (slots from it on are untouched)"),
        ("blk_free_from", "int64", "1", "every block slot below it is taken (where new_block looks for the lowest "
                                   "free one)"),
        ("gas_paid", "float64", "n", "gas each robot has paid on the canonical chain"),
        ("blk_live", "bool", "Bc", "slot holds a block (the checkpoint or one after it)"),
        ("blk_parent", "int64", "Bc", "parent slot (-1 for the checkpoint)"),
        ("blk_height", "int64", "Bc", "height (genesis 0)"),
        ("blk_weight", "int64", "Bc", "total difficulty: +2 in turn, +1 out of turn"),
        ("blk_hash", "int64", "Bc", "hash (ties between equally heavy heads go to the lower)"),
        ("blk_signer", "int64", "Bc", "robot that made it (-1 genesis)"),
        ("blk_step", "int64", "Bc", "step it was made"),
        ("blk_children", "int64", "Bc", "blocks made on it"),
        ("blk_by_backbone", "bool", "Bc", "delivered by the backbone"),
        ("blk_mark", "int8", "Bc", "scratch of move_checkpoint: 1 descends from the new checkpoint, 2 not"),
        ("blk_ntx", "int64", "Bc", "transactions it includes"),
        ("blk_txoff", "int64", "Bc", "where its transactions start in blk_tx"),
        ("blk_tx", "int64", "Bt", "block b's transactions (mempool slots, in the order they were sent) are "
                                  "blk_tx[blk_txoff[b] : blk_txoff[b] + blk_ntx[b]]"),
        ("blk_tx_top", "int64", "1", "first unused entry of blk_tx (the host packs the live blocks' entries)"),
        ("blk_state", "int64", "Bc", "the ledger state after the block (a row of blk_bal and bs_*): a new one "
                                  "for a block with transactions, its parent's for a block without"),
        ("state_used", "bool", "Bc", "the state row is some live block's (blk_state)"),
        ("state_free_from", "int64", "1", "every state row below it is used (where new_block looks for a free one)"),
        ("blk_bal", "float64", "Bc,n", "every robot's balance in each state (row blk_state[b]: after block b; "
                                       "balances_after)"),
        ("blk_included", "uint64", "Bc,T/64", "bit tx: pending transaction tx is included on its branch after the "
                                         "checkpoint"),
        *[(f"bs_{f}", _LEDGER_KINDS[f][0], "Bc" if _LEDGER_KINDS[f][1] == "1" else "Bc,n",
           f"{f} after the block (its ledger state, with blk_bal)") for f in BLOCK_STATE],
        ("bs_list", "int64", "Bc,n", "each buyer's open transactions after the block: the list node "
                                    "bs_list[b, i] and its predecessors (ls_prev), the last one first "
                                    "(-1: none)"),
        *[(f"ls_{f[3:]}", _LEDGER_KINDS[f][0], "L", f"{f} of a node of the buyers' lists of open transactions "
                                                    f"(one open transaction)") for f in TX_POOL],
        ("ls_prev", "int64", "L", "the node before it in its list (-1: it is the first)"),
        ("ls_len", "int64", "L", "length of the list that ends with it"),
        ("ls_seq", "int64", "L", "sending order (mp_seq) of the reveal it records"),
        ("ls_buyer", "int64", "L", "the buyer whose list it is in"),
        ("ls_first_child", "int64", "L",
         "first node made after it (-1: none); the others are its ls_next_sibling chain"),
        ("ls_next_sibling", "int64", "L", "next node with the same predecessor (-1: none)"),
        ("ls_weights_at", "int64", "L", "where the payment scheme's weights of the list ending here start in "
                                "weight_store (-1: not weighed yet)"),
        ("ls_roots", "int64", "n",
         "each buyer's first node of a list (-1: none); the others, its ls_next_sibling chain"),
        ("ls_top", "int64", "1", "first unused node (the host packs the nodes live blocks use)"),
        ("weight_store", "float64", "W",
         "weights of settled lists, ls_len[v] of them from ls_weights_at[v] (the settlement cache)"),
        ("weight_top", "int64", "1", "first unused entry of weight_store"),
        ("state_list", "int64", "n", "each buyer's list (a node) in the state the ledger arrays hold, or in the "
                                   "block being applied"),
        ("pool_list", "int64", "n", "the list (a node) of each buyer whose transactions the ledger arrays' "
                                  "pool holds (materialise)"),
        ("pool_stale", "bool", "1", "some buyer's list in state_list may not be the one the pool holds "
                                    "(pool_list): set when a state is loaded or a list grows"),
        ("checkpoint", "int64", "1", "the checkpoint's slot"),
        ("chn_canon", "int64", "1", "the canonical head's slot"),
        ("state_block", "int64", "1", "a live block whose state the ledger arrays hold"),
        ("mp_sent", "int64", "1", "transactions sent so far (their order)"),
        ("settling_count", "int64", "1", "reveals the deposit being applied settles"),
        ("checkpoint_blocker", "int64", "1", "the robot whose head kept next_checkpoint from moving the checkpoint "
                                     "last time (checked first next time)"),
        ("mp_live", "bool", "T", "slot holds a pending transaction"),
        ("mp_cursor", "int64", "1", "where the next free slot is looked for"),
        ("mp_order", "int64", "T", "the pending transactions' slots in sending order (the first mp_count)"),
        ("mp_words_used", "int64", "1", "words of known-bits in use: every pending slot is below 64 x mp_words_used"),
        ("mp_own_next", "int64", "T", "a pending reveal's sender's next own pending reveal (-1: none)"),
        ("mp_own_prev", "int64", "T", "... and previous one (-1: none)"),
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
        ("mp_by_backbone", "bool", "T", "delivered by the backbone"),
        ("mp_known", "uint64", "n,T/64", "bit tx of row i: robot i knows transaction tx"),
        ("mp_known_before", "uint64", "n,T/64", "known-bits at the start of the gossip phase"),
        ("mp_word_mask", "uint64", "T/64", "scratch of move_checkpoint (all 0 between calls)"),
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


def runs_poa(w) -> bool:
    """Does ``w`` run the chain model's ledger: does it hold every field of ``SPEC``?  ``w`` is a compiled
    view's numba type (its ``field_dict``) or, with ``NUMBA_DISABLE_JIT=1``, a world itself."""
    names = getattr(w, "field_dict", None)
    if names is None:
        names = getattr(w, "_fields", ())
    return _NAMES <= set(names)


_NAMES = frozenset(SPEC.names)
