"""The chain model's ledger ("poa"): robots as the nodes of a proof-of-authority chain (docs/chain-model.md).

A purchase or a deposit does not move money at once: it becomes a pending transaction, robots gossip
transactions and blocks, due signers make blocks, and each block's transactions are applied once, on
its parent's state.  Its operations for the step loop are ``ledger.backends``'s; its modules, one job each:

``spec``      the state (``SPEC``, the ``chain`` domain), and ``runs_poa``: does a world run this ledger
``arena``     host side: first sizes, the builder of a fresh chain, growth between steps; the compiled bound
              of what a step may need (``chain_needs``)
``mempool``   pending transactions, who knows them, each robot's view and spendable money; a reveal (the
              chain's way to open a transaction) and a deposit
``states``    block states: saving the ledger arrays into a block's row and loading them back
``lists``     list nodes: each buyer's open transactions on a branch, and their cached weights
``forks``     fork choice (heavier, canonical head) and the checkpoint (finality)
``gossip``    heads and transactions travelling between robots
``blocks``    making a block and applying its transactions; the end of a step
``invariants``  ``check_invariants(world)``: every rule below, checked on the host

**The ledger after block b** lives in four forms.  Their rules, which every operation keeps between
steps (``invariants`` checks each; the chain tests run it after every step of their small runs):

1. **Live ledger arrays** (``ledger.state``'s fields, the ones the run reports) hold the state after
   block ``state_block``, whose state row is the canonical head's (``chn_canon``: the heaviest block,
   ties to the lower hash).  Each buyer's list in that state is ``state_list``; the pool
   (``tx_*``) holds it once materialised: between steps ``pool_list == state_list`` and ``pool_stale``
   is False, and buyer i's pool entries are its list's transactions, oldest first.
2. **State rows**: ``blk_state[b]`` is block b's row of ``blk_bal`` (every robot's balance) and ``bs_*``
   (the rest of the ledger; ``bs_list``: each buyer's list node).  A block that includes no transaction
   has its parent's row (nothing is copied); one that includes some has a row of its own.  A row is
   ``state_used`` exactly when some live block has it, and every row below ``state_free_from`` is used.
   A row never changes once saved.
3. **The checkpoint** (``checkpoint``): the newest final block, root of the live blocks (no parent);
   ``ck_*`` hold the ledger after it, equal to its row (its lists are its row's ``bs_list``).
4. **List nodes** (``ls_*``): a node is a list, its last transaction with ``ls_prev`` the rest;
   ``ls_len`` counts them and ``ls_buyer`` names the buyer.  A row's ``bs_list[r, i]`` is -1 when buyer i
   has no open transaction there, else a node of buyer i's of length ``bs_tx_count[r, i]``.  The same
   reveal appended to the same list is the same node on every branch (``ls_first_child`` and
   ``ls_next_sibling`` find it), so a settled list's weights are kept by its node (``ls_weights_at``).

Around them: block b is live iff it is the checkpoint or descends from it; ``blk_count`` counts the
live blocks, all below ``blk_slots_touched``, and every slot below ``blk_free_from`` is live.  Each
robot's head (``view_head``) is a live block or -1 (its branch was dropped), and its cached height,
weight, hash and own balance are its head's.  The mempool holds ``mp_count`` pending transactions,
``mp_order`` lists them in sending order, all below ``64 x mp_words_used``; a block's ``blk_included``
bits name pending transactions only.

Memory: the blocks since the checkpoint (each with O(pending / 64) bits, and an O(n) state row if it
includes transactions), the list nodes they use and their cached weights, the mempool with its
known-bits (O(n x transactions in flight)), two ledgers (the checkpoint's without its lists).  Nothing
grows with the run's history (``arena``).
"""
