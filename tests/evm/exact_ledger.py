"""A slow, exact reference of the payment rules (docs/model.md §5) in rational arithmetic.

The contract floors every share to a whole unit; this model does not round at all, so the tests can
check the contract against the rules themselves (within the rounding bound), not against a copy of
the contract's own integer arithmetic. Directions are compared in degrees, as the simulation does; the
contract compares vectors, so tests build each vector from its direction (``vector_for``) far enough
from Theta that the micro-unit rounding cannot matter. With ``expiry`` = T > 0 it also applies the
stake-expiry rule: at ``advance(step)``, a buyer whose first open transaction was opened at a step t
with t + T <= step has its whole round trip settled as a deposit settles it, by the scheme's weights,
with no reward: the buyer pays the share, min(share, its balance), and the sellers share that and
their stakes (buyers in id order).

Under ``capped_outlier`` (cap ``cap``) a seller's live records after its first ``cap`` are void, and the
weights are the simulated rule's (``payments.consensus``): they add up to what the rule reads as the
round trip's amount, share + pot, a void record weighing its stake and the counted ones the rest by
eq. 7 among themselves; the ledger pays the amount in proportion. So at a deposit a void record gets
exactly its stake back, and at an expiry whose buyer could not pay the whole share its stake times
(paid share + pot) / (share + pot).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from fractions import Fraction

#: Where every test seller stands in its buyer's frame, and how long its rotated vector is.
SELLER_POSITION = (1.5, -0.5)
VECTOR_LENGTH = 7.0


def vector_for(direction_deg: float) -> tuple[float, float]:
    """The purchased vector (buyer's frame) of a seller at ``SELLER_POSITION`` whose rotated vector
    points at ``direction_deg``."""
    rad = math.radians(direction_deg)
    return (SELLER_POSITION[0] + VECTOR_LENGTH * math.cos(rad), SELLER_POSITION[1] + VECTOR_LENGTH * math.sin(rad))


def circular_distance(a: Fraction, b: Fraction) -> Fraction:
    d = abs(a - b) % 360
    return min(d, 360 - d)


@dataclass
class ExactLedger:
    """Balances and pots in tokens (Fractions); directions in degrees (Fractions)."""

    robots: int
    scheme: str
    reward: Fraction
    share: Fraction
    stake: Fraction
    theta: Fraction
    initial: Fraction
    expiry: int = 0
    cap: int = 0
    balance: list[Fraction] = field(init=False)
    pot: list[Fraction] = field(init=False)
    open: list[list[tuple[int, int, Fraction, int]]] = field(init=False)
    bound: list[int] = field(init=False)

    def __post_init__(self) -> None:
        self.balance = [self.initial] * self.robots
        self.pot = [Fraction(0)] * self.robots
        self.open = [[] for _ in range(self.robots)]
        self.bound = [0] * self.robots

    def advance(self, step: int) -> None:
        """Start ``step``: settle every round trip whose first transaction's age expires it."""
        if not self.expiry:
            return
        for buyer, txs in enumerate(self.open):
            if txs and txs[0][3] + self.expiry <= step:
                short = self.balance[buyer] < self.share * self.reward
                # a short share is the buyer's whole balance: on chain within the buyer's rounding bound,
                # which every payment from it may then carry
                self._settle(buyer, min(self.share * self.reward, self.balance[buyer]),
                             self.bound[buyer] + 1 if short else 0)

    def purchase(self, buyer: int, seller: int, site: int, direction: Fraction, step: int = 0) -> bool:
        """Record a sale; False (nothing recorded) when the seller cannot lock the stake."""
        if self.stake > 0:
            if self.balance[seller] < self.stake:
                return False
            self.balance[seller] -= self.stake
            self.pot[buyer] += self.stake
        self.open[buyer].append((seller, site, direction, step))
        return True

    def deposit(self, robot: int) -> None:
        self.balance[robot] += self.reward
        self._settle(robot, self.share * self.reward)

    def _settle(self, robot: int, share: Fraction, carried: int = 0) -> None:
        """The robot's round trip paid: ``share`` and its stakes from the robot to its sellers, by weight
        (each payment's rounding bound grows by ``carried`` units besides its own)."""
        txs = self.open[robot]
        self.balance[robot] += self.pot[robot]
        amount = share + self.pot[robot]
        pot, self.pot[robot] = self.pot[robot], Fraction(0)
        if txs:
            if self.scheme == "delayed":
                weights = [1] * len(txs)
            elif self.scheme == "capped_outlier":
                counted = [sum(1 for t in txs[:k] if t[0] == seller) < self.cap
                           for k, (seller, _, _, _) in enumerate(txs)]
                counts = [sum(1 for c2, (_, s2, d2, _) in zip(counted, txs)
                              if c2 and s2 == s and circular_distance(d, d2) < self.theta) if c else 0
                          for c, (_, s, d, _) in zip(counted, txs)]
                rest = self.share * self.reward + pot - counted.count(False) * self.stake
                weights = [rest * Fraction(w, sum(counts)) if c else self.stake for c, w in zip(counted, counts)]
            elif self.scheme == "outlier_distinct":
                # distinct sellers with a same-site transaction within theta, over the seller's sales for the site
                weights = [Fraction(len({s2 for (s2, site2, d2, _) in txs
                                         if site2 == site and circular_distance(d, d2) < self.theta}),
                                    sum(1 for t in txs if t[0] == seller and t[1] == site))
                           for (seller, site, d, _) in txs]
            else:
                weights = [sum(1 for (_, s2, d2, _) in txs if s2 == s and circular_distance(d, d2) < self.theta)
                           for (_, s, d, _) in txs]
            total = sum(weights)
            for (seller, _, _, _), w in zip(txs, weights):
                self.balance[seller] += amount * w / total if total else 0
                self.bound[seller] += 1 + carried
            self.balance[robot] -= amount if total else 0
            self.bound[robot] += len(txs)
        self.open[robot] = []
