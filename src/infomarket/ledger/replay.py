"""Replay a ledger event sequence through the ledger's own compiled operations, on a ledger alone.

No swarm is built and no engine code runs: a ``ledger.state.Book`` (the ledger, its log and a clock) is
all the operations need.  Used by the conformance tests (``payment_vectors.json``) and to check the EVM
contract against the simulation: both feed the same purchases and deposits and compare balances.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from collections.abc import Iterable

import numpy as np

from ..errors import ConfigError, SimulationError
from ..registry import get_payment
from ..state.flags import ErrorFlags
from ..state.view import make_view
from .kernels import distribute, open_transaction, settle_expired, trip_expired
from .pool import reserve
from .state import REPUTATION, grow_book, new_book


@dataclass(frozen=True)
class Replayed:
    """Balances and pots after a replay, and whether each purchase was accepted (in order)."""

    balances: np.ndarray
    pots: np.ndarray
    accepted: list[bool]
    #: the ledger's reputation record after the replay (``ledger.state.REPUTATION``: field -> copy)
    record: dict = field(default_factory=dict)


@dataclass(frozen=True)
class LedgerEvent:
    """``kind`` is 'purchase' (buyer, seller, site, direction_deg) or 'deposit' (buyer); ``step`` is
    the simulation step it happened in (only the stake-expiry rule reads it)."""

    kind: str
    buyer: int
    seller: int = -1
    site: int = -1
    direction_deg: float = 0.0
    step: int = 0


class Ledger:
    """A ledger on its own: purchases, deposits (weighed by a payment scheme) and stake expiry, with
    the same compiled operations the engine runs inside a simulation."""

    def __init__(self, robots: int, *, scheme: str = "delayed", initial_wealth: float = 1.0,
                 reward: float = 1.0, information_share: float = 0.5, stake: float = 0.0,
                 params: dict | None = None, stake_expiry: int = 0, record_events: bool = False,
                 reputation_decay: float = 1.0):
        spec = get_payment(scheme)
        values = {**spec.defaults, **(params or {})}
        unknown = sorted(set(values) - set(spec.params))
        if unknown:
            raise ConfigError(f"payment {scheme!r} has no parameter {', '.join(map(repr, unknown))}; "
                              f"it takes {', '.join(spec.params) or 'none'}")
        self.scheme = spec
        self.book = new_book(robots, record_events=record_events, initial_wealth=initial_wealth, reward=reward,
                             information_share=information_share, stake=stake, stake_expiry=int(stake_expiry),
                             pparams=[float(values.get(p, 0.0)) for p in spec.params],
                             reputation_decay=float(reputation_decay))
        self.view = make_view("book", self.book)
        self.rng = np.random.default_rng(0)  # only a scheme that asks for one uses it

    def _check(self) -> None:
        flags = ErrorFlags(int(self.book.flags[0]))
        if flags:
            raise SimulationError(flags.describe())

    def begin_step(self, step: int) -> None:
        """Step ``step`` begins: the clock moves there and, with stake expiry, every buyer's expired round
        trip is settled whole, by the scheme's weights, the buyer paying the share (buyers in id order)."""
        self.book.clock[0] = step
        if self.book.stake_expiry > 0:
            for buyer in range(self.book.balance.shape[0]):
                if trip_expired(self.view, buyer):
                    self._grow_log(buyer)
                    settle_expired(self.view, buyer, self._weights(buyer))
                    self._check()

    def purchase(self, buyer: int, seller: int, site: int, direction_deg: float) -> bool:
        """Open a transaction (locking the seller's stake); False when the seller cannot stake."""
        book = self.book
        while not reserve(self.view, buyer, int(book.tx_count[buyer]) + 1):
            self.book = book = grow_book(book, book.tx_count + 1, int(book.ev_count[0]) + 1, 0)
            self.view = make_view("book", book)
        ok = bool(open_transaction(self.view, buyer, seller, site, float(direction_deg)))
        self._check()
        return ok

    def _grow_log(self, buyer: int) -> None:
        """Room in the logs for one settlement of the buyer's open transactions."""
        book = self.book
        if book.record:
            self.book = grow_book(book, book.tx_count, int(book.ev_count[0]) + 1,
                                  int(book.pay_count[0]) + int(book.tx_count[buyer]))
            self.view = make_view("book", self.book)

    def _weights(self, buyer: int) -> np.ndarray:
        """The scheme's weights of the buyer's open transactions."""
        book = self.book
        a = int(book.tx_off[buyer])
        b = a + int(book.tx_count[buyer])
        weights = np.zeros(b - a)
        rule = self.scheme.weights
        extra = ([self.view] if rule.wants_market else []) + ([self.rng] if rule.wants_rng else [])
        rule.func(buyer, book.tx_seller[a:b].copy(), book.tx_site[a:b].copy(), book.tx_dir[a:b].copy(), weights,
                  *extra, *book.pparams[:len(rule.params)])
        return weights

    def deposit(self, buyer: int) -> None:
        """The buyer deposits an item: the scheme weighs its open transactions and the round trip is paid."""
        self._grow_log(buyer)
        distribute(self.view, buyer, self._weights(buyer))
        self._check()


def replay_events(events: Iterable, robots: int, *, scheme: str = "delayed", initial_wealth: float = 1.0,
                  reward: float = 1.0, information_share: float = 0.5, stake: float = 0.0,
                  params: dict | None = None, stake_expiry: int = 0, reputation_decay: float = 1.0) -> Replayed:
    """Apply purchases and deposits in order; return the final balances and pots and, per purchase,
    whether it was accepted.  Events are LedgerEvent-like objects or mappings with the same fields
    (a DataFrame's ``itertuples()`` works; 'refused' events are replayed as purchases).

    ``stake_expiry`` = T > 0 applies the stake-expiry rule (docs/chain.md): at the start of each step
    s (before its first event), a buyer whose first open transaction was opened at a step t with
    t + T <= s has its whole round trip settled by the scheme's weights as a deposit would settle it,
    the share paid from its own balance as far as it goes (``ledger.kernels.settle_expired``).
    ``reputation_decay`` < 1 keeps the decayed reputation record (``payment.reputation_decay``)."""
    ledger = Ledger(robots, scheme=scheme, initial_wealth=initial_wealth, reward=reward,
                    information_share=information_share, stake=stake, params=params, stake_expiry=stake_expiry,
                    reputation_decay=reputation_decay)
    accepted: list[bool] = []
    step = None
    for ev in events:
        get = ev.get if isinstance(ev, dict) else (lambda k, e=ev: getattr(e, k))
        kind = str(get("kind"))
        if stake_expiry:
            now = int(get("step"))
            if step is None or now > step:  # a new step begins: the engine's expiry, then the event
                step = now
                ledger.begin_step(step)
        if kind in ("purchase", "refused"):
            accepted.append(ledger.purchase(int(get("buyer")), int(get("seller")), int(get("site")),
                                            float(get("direction_deg"))))
        elif kind == "deposit":
            ledger.deposit(int(get("buyer")))
        else:
            raise ConfigError(f"unknown ledger event kind {kind!r} (purchase, refused or deposit)")
    book = ledger.book
    return Replayed(book.balance.copy(), book.pot.copy(), accepted, {f: getattr(book, f).copy() for f in REPUTATION})
