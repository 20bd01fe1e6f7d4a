"""A read-only observer of the chain model's blocks (docs/chain-model.md, "Where the measures go").

``BlockLog(sim)`` steps a ``Simulation`` whose experiment has ``[chain] consensus = "poa"`` one step at
a time (``run``), or is told to look after each step the caller makes (``observe``), and keeps every
block the model made with a stable id (slots of the block store are reused), its parent's id, its
transactions and every robot's balance after it.  ``canonical()`` then gives the canonical chain, genesis
first: what ``infomarket chain demo`` replays on the EVM.  It never writes to the world.

What it reads, and the meaning it assumes (``ledger.poa.spec.SPEC`` and ``ledger.poa.mempool``; written once
here, so a change of a field is a change of this module only):

* ``blk_live[b]``: slot b holds a block (the checkpoint or one made after it).  A block in a slot is
  known by its ``blk_hash``, ``blk_step`` and ``blk_signer``: a slot whose hash or step changed since
  the last look holds a new block.  ``blk_height``, ``blk_signer``, ``blk_step``, ``blk_ntx``,
  ``blk_tx[blk_txoff[b]:][:ntx]`` (mempool slots, in the block's order) and ``blk_bal[blk_state[b]]`` (every
  robot's balance
  after the block) are written once, when the block is made, and read here at the end of that step.
* ``blk_parent[b]``: the parent's slot; the parent of a live block is live, except the checkpoint's
  (``checkpoint``), which is -1.  A block that was made and became the checkpoint in the same step (a
  zero-latency backbone) has lost its parent slot by the time we look: its parent is the block seen at
  the previous look at height h - 1; when there are several, the one whose hash the block's hash was
  made from (``_child_hash``, the formula of ``ledger.poa.blocks.new_block``).  A block that was made and dropped
  within one step is never seen (it cannot be on the canonical chain: a block has no child in the step
  it is made, and the canonical head at the end of a step is live).
* Blocks made in one step are ordered by their signer's place in ``chn_signers`` (signers make blocks
  in that order).
* Mempool slot x (``mp_*``): the transaction's kind (``mempool.REVEAL``/``DEPOSIT``), sender, buyer,
  seller, site, direction, stake and gas its sender's view set aside, step sent and sending order
  (``mp_seq``, unique over the run: the transaction's id).  A slot is freed only when its block becomes
  final and reused only by a transaction sent in a later step, so a block's transactions are read
  intact at the end of the step it was made; every transaction sent (``mp_sent`` of them) is seen live
  in the mempool or in a new block at the end of the step it was sent.
* ``chn_canon``: the canonical head's slot; ``view_head[i]``: robot i's head slot (-1: dropped).

Observing costs a few numpy operations per step over the block and mempool capacities, no Python per
robot; ``infomarket chain demo`` reports the time it takes.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import SimulationError
from .poa.mempool import DEPOSIT, REVEAL, mix

KINDS = {REVEAL: "reveal", DEPOSIT: "deposit"}
#: ``chain_views``' branch of a robot whose head was dropped (``view_head`` -1).
DROPPED = 255


def _block_txs(w, b):
    """Block b's transactions (mempool slots, in its order): ``blk_tx`` holds every block's, packed
    (docs/chain-model.md, "State arrays")."""
    a = int(w.blk_txoff[b])
    return w.blk_tx[a:a + int(w.blk_ntx[b])]


@dataclass(frozen=True)
class ChainTx:
    """One transaction as it was sent (``seq``: its place in sending order, unique over the run)."""

    seq: int
    kind: str
    origin: int
    buyer: int
    seller: int
    site: int
    direction: float
    stake: float
    gas: float
    step: int


@dataclass(frozen=True)
class Block:
    """One block the model made.  ``id``: the order the observer saw it in (genesis 0); ``parent``: the
    parent's id (-1 for genesis); ``balances``: every robot's balance after the block."""

    id: int
    parent: int
    height: int
    hash: int
    signer: int
    step: int
    txs: tuple[ChainTx, ...]
    balances: np.ndarray


def _child_hash(parent_hash: int, height: int, signer: int, step: int) -> int:
    """The hash ``ledger.poa.blocks.new_block`` gives a block of this height, signer and step on that parent."""
    h = mix(np.uint64(parent_hash) ^ (np.uint64(height) * np.uint64(0x9E3779B97F4A7C15)))
    h = mix(h ^ (np.uint64(signer) + np.uint64(step) * np.uint64(0xD6E8FEB86659FD93)))
    return int(np.int64(h >> np.uint64(2)))


class BlockLog:
    """Every block a chain run makes, with stable ids; ``canonical()`` at the end."""

    def __init__(self, sim):
        if not sim.config.chain.enabled:
            raise SimulationError("BlockLog needs a run with the chain model on ([chain] consensus = \"poa\")")
        self.sim = sim
        self.blocks: list[Block] = []
        self.txs: dict[int, ChainTx] = {}
        self._slot: dict[int, tuple[int, int, int]] = {}  # slot -> (id, hash, step) of its block
        self._hash = np.zeros(0, np.int64)  # the same as arrays by slot, to find new blocks at numpy speed
        self._step = np.full(0, -1, np.int64)
        self._seen_seq = 0
        self.canon_by_step: list[int] = []  # canonical head's id after each observed step
        self._last_step = -1
        self.observe()

    # -- looking ----------------------------------------------------------------------------------
    def observe(self) -> None:
        """Record what changed since the last look; call after every step (``run`` does)."""
        w = self.sim.world
        step = int(w.clock[0])
        if step == self._last_step:
            return
        if step > self._last_step + 1 and self._last_step >= 0:
            raise SimulationError(f"BlockLog: the simulation moved from step {self._last_step} to {step} "
                                  "unobserved; step it one step at a time (BlockLog.run) ")
        self._last_step = step
        self._record_txs(w)
        cap = w.blk_live.shape[0]
        if self._hash.shape[0] < cap:  # the block store grew (slots keep their numbers)
            self._hash = np.concatenate([self._hash, np.zeros(cap - self._hash.shape[0], np.int64)])
            self._step = np.concatenate([self._step, np.full(cap - self._step.shape[0], -1, np.int64)])
        new = np.flatnonzero(w.blk_live & ((w.blk_hash != self._hash) | (w.blk_step != self._step))).tolist()
        order = {int(s): k for k, s in enumerate(w.chn_signers)}
        new.sort(key=lambda b: (int(w.blk_step[b]), order.get(int(w.blk_signer[b]), -1)))
        previous = dict(self._slot)
        for b in new:
            self._add(w, b, previous)
        self.canon_by_step.append(self.id_of(int(w.chn_canon[0])))

    def _record_txs(self, w) -> None:
        top = int(w.mp_sent[0])
        if top == self._seen_seq:
            return
        slots = np.flatnonzero(w.mp_live & (w.mp_seq >= self._seen_seq))
        for x in slots:
            self._tx(w, int(x))
        # a transaction sent and made final this step is no longer live: it is in a block made this step
        for b in np.flatnonzero(w.blk_live & (w.blk_step == w.clock[0])):
            for x in _block_txs(w, b):
                if int(w.mp_seq[x]) >= self._seen_seq:
                    self._tx(w, int(x))
        missing = [seq for seq in range(self._seen_seq, top) if seq not in self.txs]
        if missing:
            raise SimulationError(f"BlockLog: transactions {sorted(missing)[:5]} were sent but never seen "
                                  "(the mempool's meaning changed? see ledger/blocklog.py)")
        self._seen_seq = top

    def _tx(self, w, x: int) -> ChainTx:
        seq = int(w.mp_seq[x])
        tx = self.txs.get(seq)
        if tx is None:
            tx = ChainTx(seq, KINDS[int(w.mp_kind[x])], int(w.mp_origin[x]), int(w.mp_buyer[x]),
                         int(w.mp_seller[x]), int(w.mp_site[x]), float(w.mp_dir[x]), float(w.mp_stake[x]),
                         float(w.mp_gas[x]), int(w.mp_step[x]))
            self.txs[seq] = tx
        return tx

    def _add(self, w, b: int, previous: dict) -> None:
        height, step, signer, h = (int(w.blk_height[b]), int(w.blk_step[b]), int(w.blk_signer[b]),
                                   int(w.blk_hash[b]))
        p = int(w.blk_parent[b])
        if not self.blocks:
            parent = -1  # genesis
        elif p >= 0:
            parent = self._slot[p][0]
        else:
            parent = self._lost_parent(previous, height, signer, step, h)
        txs = tuple(self._tx(w, int(x)) for x in _block_txs(w, b))
        block = Block(len(self.blocks), parent, height, h, signer, step, txs, w.blk_bal[w.blk_state[b]].copy())
        self.blocks.append(block)
        self._slot[b] = (block.id, h, step)
        self._hash[b], self._step[b] = h, step

    def _lost_parent(self, previous: dict, height: int, signer: int, step: int, h: int) -> int:
        """The parent of a block that became the checkpoint in the step it was made (its parent slot is
        gone): a block seen at the previous look at height - 1, the one whose hash made this one's."""
        candidates = [i for i, _, _ in previous.values() if self.blocks[i].height == height - 1]
        if len(candidates) > 1:
            candidates = [i for i in candidates if _child_hash(self.blocks[i].hash, height, signer, step) == h]
        if len(candidates) != 1:
            raise SimulationError(f"BlockLog: cannot tell the parent of the block made at step {step} by robot "
                                  f"{signer} ({len(candidates)} candidates; see ledger/blocklog.py)")
        return candidates[0]

    def id_of(self, slot: int) -> int:
        """The id of the block now in ``slot`` (-1 for -1)."""
        return -1 if slot < 0 else self._slot[slot][0]

    def run(self, steps: int | None = None, progress=None) -> None:
        """Step the simulation to ``steps`` (default: the experiment's), looking after every step."""
        end = self.sim.config.steps if steps is None else steps
        while self.sim.clock < end:
            self.sim.step(1)
            self.observe()
            if progress is not None:
                progress(self.sim.clock)

    # -- what it saw ------------------------------------------------------------------------------
    def canonical(self) -> list[Block]:
        """The canonical chain now: genesis first, the canonical head last."""
        chain = []
        b = self.id_of(int(self.sim.world.chn_canon[0]))
        while b >= 0:
            chain.append(self.blocks[b])
            b = self.blocks[b].parent
        return chain[::-1]

    def heads(self) -> list[int]:
        """Every robot's head block id (-1: its branch was dropped)."""
        return [self.id_of(int(s)) for s in self.sim.world.view_head]

    def forks(self) -> list[int]:
        """Ids of the blocks seen made on a parent that already had a child."""
        kids: dict[int, int] = {}
        out = []
        for blk in self.blocks[1:]:
            kids[blk.parent] = kids.get(blk.parent, 0) + 1
            if kids[blk.parent] > 1:
                out.append(blk.id)
        return out


class BranchNumbers:
    """Numbers for the branches robots are on that hold from one frame to the next (a viewer colours a
    branch by its number).  A branch is known by the hash of its first block off the canonical branch; it
    keeps its number while some robot is on it; a new branch takes the lowest number free (new branches of
    one frame in hash order).  Numbers run 1 .. ``DROPPED`` - 1 (the last is shared beyond that)."""

    def __init__(self) -> None:
        self._of: dict[int, int] = {}

    def __call__(self, keys) -> dict[int, int]:
        """Number of each branch key now present (keys no longer present free their numbers)."""
        keys = {int(k) for k in keys}
        self._of = {k: v for k, v in self._of.items() if k in keys}
        used = set(self._of.values())
        free = 1
        for k in sorted(keys - self._of.keys()):
            while free in used:
                free += 1
            self._of[k] = min(free, DROPPED - 1)
            used.add(free)
        return self._of


def chain_views(w, numbers: BranchNumbers | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each robot's head height, lag (canonical height minus its head's) and branch, from the world's
    arrays now: branch 0 when its head is on the canonical branch (however far behind), 1, 2, ... for each
    other branch (``numbers``: a ``BranchNumbers`` kept across calls keeps a branch's number while it
    lasts; without one, the branches are numbered afresh), ``DROPPED`` when its head's branch was
    dropped."""
    numbers = BranchNumbers() if numbers is None else numbers
    heads = w.view_head.astype(np.int64)
    canon = int(w.chn_canon[0])
    on_canon = np.zeros(w.blk_live.shape[0], bool)
    b = canon
    while b >= 0:
        on_canon[b] = True
        b = int(w.blk_parent[b])
    cur = heads.copy()
    leaf = np.full(heads.shape, -1, np.int64)  # the block where each robot's branch leaves the canonical one
    off = (cur >= 0) & ~on_canon[np.maximum(cur, 0)]
    while off.any():
        leaf[off] = cur[off]
        cur[off] = w.blk_parent[cur[off]]
        off &= cur >= 0
        off[off] = ~on_canon[cur[off]]
    branch = np.zeros(heads.shape, np.int64)
    keys, which = np.unique(w.blk_hash[leaf[leaf >= 0]], return_inverse=True)
    of = numbers(keys)
    branch[leaf >= 0] = np.array([of[int(k)] for k in keys], np.int64)[which]  # (a lookup per branch)
    branch[heads < 0] = DROPPED
    height = w.view_height.astype(np.float64)
    return height, w.blk_height[canon] - height, branch
