"""The ledger's own state: the market's terms, every robot's balance and pot, each buyer's open
transactions in a shared pool, and the reputation record; its builder and its growth.

The ledger needs no swarm: ``new_book`` makes a ledger and a log on their own, and the ledger
operations (``ledger.kernels``) run on it exactly as they run inside the engine's flat world (they read
only the fields below, the log and the clock).  Inside the engine every array here is read-only to
compiled code except in ledger operations (``state.view``).

Transactions: buyer i's open transactions (since its last deposit) are pool entries
``tx_off[i] .. tx_off[i] + tx_count[i] - 1``, in purchase order; a block that could overflow is moved to
the top of the pool (``kernels.reserve``), and the host compacts and grows the pool between steps
(``grow_ledger``).
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np

from ..state import log as _log
from ..state.spec import Spec, fields
from ..state.view import register_layout

#: First size of each buyer's block in the transaction pool.
TX_CAPACITY = 16

#: The fields of one transaction in the pool (moved together when a block moves or is compacted).
TX_POOL = ("tx_seller", "tx_site", "tx_dir", "tx_step", "tx_stake")
#: The reputation record of every robot (rules read it through ``behaviours.market``).
REPUTATION = ("money", "rep_settled", "rep_reduced", "rep_earned", "rep_stake_lost", "rep_deposits", "rep_good",
              "rep_bad")

SPEC = Spec("ledger", [
    *fields("host", [
        ("reward", "float", "", "reward issued to a robot for each item it deposits"),
        ("info_share", "float", "", "share of the reward paid to the sellers of the round trip"),
        ("stake", "float", "", "stake a seller locks per sale (0: no staking)"),
        ("stake_expiry", "int", "", "steps after which an unsettled stake returns to its seller (0: never)"),
        ("rep_decay", "float", "", "factor on a seller's decayed record at each of its settled sales (1: none)"),
        ("pparams", "float64", "Q", "the payment scheme's parameters, in its declared order"),
    ]),
    *fields("ledger", [
        ("balance", "float64", "n", "each robot's spendable money"),
        ("pot", "float64", "n", "stakes locked by each buyer's open purchases"),
        ("burned", "float64", "1", "fuel burned by moving robots"),
        ("tx_off", "int64", "n", "start of each buyer's block in the pool"),
        ("tx_cap", "int64", "n", "size of each buyer's block"),
        ("tx_count", "int64", "n", "each buyer's open transactions"),
        ("tx_seller", "int64", "P", "seller of each pooled transaction"),
        ("tx_site", "int64", "P", "0 food, 1 nest"),
        ("tx_dir", "float64", "P", "direction of the bought vector, degrees (what the scheme weighs)"),
        ("tx_step", "int64", "P", "step the transaction was opened"),
        ("tx_stake", "float64", "P", "stake locked by the transaction"),
        ("pool_top", "int64", "1", "first unused pool entry"),
        ("money", "float64", "1", "sum of all balances, kept by every operation (a wealth share in O(1))"),
        ("rep_settled", "int64", "n", "sales settled by a deposit"),
        ("rep_reduced", "int64", "n", "of those, outliers (weighed 0 or below half the best of their site)"),
        ("rep_earned", "float64", "n", "money earned by sales"),
        ("rep_stake_lost", "float64", "n", "stake locked in sales and not paid back"),
        ("rep_deposits", "int64", "n", "deposits made as buyer"),
        ("rep_good", "float64", "n", "decayed count of settled sales that were not outliers (rep_decay < 1)"),
        ("rep_bad", "float64", "n", "decayed count of settled sales that were outliers (rep_decay < 1)"),
    ]),
])


def build_ledger(robots: int, *, initial_wealth: float, reward: float, information_share: float,
                 stake: float, stake_expiry: int, pparams, reputation_decay: float = 1.0) -> dict:
    """A fresh ledger: every robot holds ``initial_wealth``, no transaction is open."""
    n, kt = robots, TX_CAPACITY
    z = np.zeros
    ledger = {
        "reward": float(reward), "info_share": float(information_share), "stake": float(stake),
        "stake_expiry": int(stake_expiry), "rep_decay": float(reputation_decay),
        "pparams": np.array(list(pparams) or [0.0], dtype=np.float64),
        "balance": np.full(n, float(initial_wealth)), "pot": z(n), "burned": z(1),
        "tx_off": np.arange(n, dtype=np.int64) * kt, "tx_cap": np.full(n, kt, np.int64), "tx_count": z(n, np.int64),
        "tx_seller": z(n * kt, np.int64), "tx_site": z(n * kt, np.int64), "tx_dir": z(n * kt),
        "tx_step": z(n * kt, np.int64), "tx_stake": z(n * kt), "pool_top": np.array([n * kt], np.int64),
        "money": np.array([n * float(initial_wealth)]), "rep_settled": z(n, np.int64),
        "rep_reduced": z(n, np.int64), "rep_earned": z(n), "rep_stake_lost": z(n), "rep_deposits": z(n, np.int64),
        "rep_good": z(n), "rep_bad": z(n),
    }
    SPEC.check(ledger)
    return ledger


def ledger_of(cfg) -> dict:
    """The ledger an experiment starts with."""
    p = cfg.payment
    return build_ledger(cfg.swarm.robots, initial_wealth=p.initial_wealth, reward=p.reward,
                        information_share=p.information_share, stake=p.stake, stake_expiry=p.stake_expiry,
                        pparams=cfg.payment_params().values(), reputation_decay=p.reputation_decay)


def grow_ledger(ledger, tx_need: np.ndarray) -> dict:
    """Replacement arrays (field -> array) so each buyer's block holds ``tx_need`` transactions: blocks
    that are too small at least double, every live block is compacted to the front of a pool twice the
    blocks' total size.  ``ledger``: any object with the ledger's fields.  Empty when nothing is short."""
    needy = tx_need > ledger.tx_cap
    if not needy.any():
        return {}
    caps = ledger.tx_cap.copy()
    caps[needy] = np.maximum(2 * caps[needy], tx_need[needy] + 8)
    starts = np.concatenate([[0], np.cumsum(caps)[:-1]]).astype(np.int64)
    size = 2 * int(caps.sum())
    src = _ranges(ledger.tx_off, ledger.tx_count)
    dst = _ranges(starts, ledger.tx_count)
    changes = {}
    for f in TX_POOL:
        old = getattr(ledger, f)
        new = np.zeros(size, old.dtype)
        new[dst] = old[src]
        changes[f] = new
    changes.update(tx_off=starts, tx_cap=caps, pool_top=np.array([int(caps.sum())], np.int64))
    return changes


def _ranges(starts: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """Concatenated index ranges starts[i] .. starts[i] + counts[i] - 1."""
    total = int(counts.sum())
    if total == 0:
        return np.zeros(0, np.int64)
    offsets = np.repeat(starts - np.concatenate([[0], np.cumsum(counts)[:-1]]), counts)
    return np.arange(total, dtype=np.int64) + offsets


#: A ledger with its log and clock, and nothing of a swarm: what the ledger operations need to run alone.
Book = namedtuple("Book", SPEC.names + _log.SPEC.names)
register_layout("book", (SPEC, _log.SPEC))


def new_book(robots: int, *, record_events: bool = False, **terms) -> Book:
    """A ledger on its own (``build_ledger``'s ``terms``) with a log (``record_events``: the event and
    payment logs too), for replaying purchases, deposits and stakes without a swarm."""
    log = _log.build_log(robots, record_events=record_events, history_every=0, history_rows=0, sites=0)
    return Book(**build_ledger(robots, **terms), **log)


def grow_book(book: Book, tx_need: np.ndarray, events_needed: int = 0, payments_needed: int = 0) -> Book:
    """``book`` with room for ``tx_need`` open transactions per buyer and the given log rows."""
    changes = grow_ledger(book, tx_need)
    if book.record:
        changes.update(_log.grow_log(book, events_needed, payments_needed))
    return book._replace(**changes) if changes else book
