"""A slow, exact reference of the payment rules (MODEL.md section 5) in rational arithmetic.

The contract floors every share to a whole unit; this model does not round at all, so the tests can
check the contract against the rules themselves (within the rounding bound), not against a copy of
the contract's own integer arithmetic.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction


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
    balance: list[Fraction] = field(init=False)
    pot: list[Fraction] = field(init=False)
    open: list[list[tuple[int, int, Fraction]]] = field(init=False)
    bound: list[int] = field(init=False)

    def __post_init__(self) -> None:
        self.balance = [self.initial] * self.robots
        self.pot = [Fraction(0)] * self.robots
        self.open = [[] for _ in range(self.robots)]
        self.bound = [0] * self.robots

    def purchase(self, buyer: int, seller: int, site: int, direction: Fraction) -> bool:
        """Record a sale; False (nothing recorded) when the seller cannot lock the stake."""
        if self.stake > 0:
            if self.balance[seller] < self.stake:
                return False
            self.balance[seller] -= self.stake
            self.pot[buyer] += self.stake
        self.open[buyer].append((seller, site, direction))
        return True

    def deposit(self, robot: int) -> None:
        txs = self.open[robot]
        self.balance[robot] += self.reward + self.pot[robot]
        amount = self.share * self.reward + self.pot[robot]
        self.pot[robot] = Fraction(0)
        if txs:
            if self.scheme == "delayed":
                weights = [1] * len(txs)
            else:
                weights = [sum(1 for (_, s2, d2) in txs if s2 == s and circular_distance(d, d2) < self.theta)
                           for (_, s, d) in txs]
            total = sum(weights)
            for (seller, _, _), w in zip(txs, weights):
                self.balance[seller] += amount * w / total
                self.bound[seller] += 1
            self.balance[robot] -= amount
            self.bound[robot] += len(txs)
        self.open[robot] = []
