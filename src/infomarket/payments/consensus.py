"""Market-side rules that decide, at settlement, how much of each seller's stake comes back: stake slashed
in proportion to how far a record lies from the settled consensus (``consensus_slash``), and a per-seller
cap on records per round trip (``capped_outlier``).  Registered by ``infomarket.builtins``; docs/defences.md
gives their equations.

A weight rule cannot move money, but it can read the market (its ``market`` argument) and so knows what
the ledger will share: ``info_share * reward + pot`` in proportion to the weights
(``ledger.kernels.distribute``).  Weights that add up to exactly that amount are therefore payouts:
``payouts`` turns "give back this fraction of each stake, share the rest by these weights" into them.
"""
import numpy as np
from ..jit import njit

from ..engine.geometry import angular_distance


@njit(forceinline=True, cache=True)
def round_trip_amount(market, buyer):
    """What the ledger shares among the sellers when ``buyer`` deposits: information share of the reward
    plus every stake its open purchases locked."""
    return market.info_share * market.reward + market.pot[buyer]


@njit(forceinline=True, cache=True)
def stake_of(market, buyer, x):
    """The stake locked by the buyer's x-th open transaction (a rule weighs them all, in order)."""
    return market.tx_stake[market.tx_off[buyer] + x]


@njit(cache=True)
def payouts(market, buyer, refund, share, weights):
    """Weights that pay seller x back ``refund[x]`` (a fraction in [0, 1]) of its stake, and share what
    is left of the round trip's amount in proportion to ``share`` (equally when ``share`` sums to 0):
    they sum to that amount, so the ledger pays each weight as it is."""
    k = weights.shape[0]
    first = market.tx_count[buyer] - k  # 0: every open transaction is weighed
    rest = round_trip_amount(market, buyer)
    total = 0.0
    for x in range(k):
        weights[x] = refund[x] * stake_of(market, buyer, first + x)
        rest -= weights[x]
        total += share[x]
    rest = max(rest, 0.0)
    for x in range(k):
        weights[x] += rest * (share[x] / total if total > 0.0 else 1.0 / k)


@njit(cache=True)
def consensus_directions(sites, directions):
    """Per transaction, the settled consensus of its site: the direction among the site's records that
    lies nearest to all of them (the smallest sum of angular distances; ties to the earliest record), a
    medoid that a minority of far-off records cannot drag."""
    k = directions.shape[0]
    best = np.full(2, -1, dtype=np.int64)
    best_sum = np.zeros(2)
    for x in range(k):
        d = 0.0
        for y in range(k):
            if sites[y] == sites[x]:
                d += angular_distance(directions[x], directions[y])
        s = sites[x]
        if best[s] < 0 or d < best_sum[s]:
            best[s] = x
            best_sum[s] = d
    out = np.empty(k)
    for x in range(k):
        out[x] = directions[best[sites[x]]]
    return out


def consensus_slash_weights(buyer, sellers, sites, directions, weights, market, slash_angle=90.0):
    """A record ``d`` degrees from its site's settled consensus loses the fraction min(1, d / slash_angle)
    of its stake and earns that much less of the information share: seller x is paid back
    (1 - s_x) of its stake and shares the rest of the round trip's amount by (1 - s_x)."""
    k = weights.shape[0]
    consensus = consensus_directions(sites, directions)
    keep = np.empty(k)
    for x in range(k):
        keep[x] = 1.0 - min(1.0, angular_distance(directions[x], consensus[x]) / slash_angle)
    payouts(market, buyer, keep, keep, weights)


def capped_outlier_weights(buyer, sellers, sites, directions, weights, market, theta=30.0, cap=3.0):
    """At most ``cap`` records per seller count in a round trip: its later records (in purchase order,
    either site) are void: their stake is paid back and they earn nothing nor count for anyone.  The
    counted records are weighed as in the paper's outlier penalisation (eq. 7) among themselves."""
    k = weights.shape[0]
    counted = np.zeros(k, dtype=np.bool_)
    for x in range(k):
        before = 0
        for y in range(x):
            if sellers[y] == sellers[x]:
                before += 1
        counted[x] = before < cap
    refund = np.empty(k)
    share = np.zeros(k)
    for x in range(k):
        refund[x] = 0.0 if counted[x] else 1.0
        if counted[x]:
            for y in range(k):
                if counted[y] and sites[y] == sites[x] and angular_distance(directions[x], directions[y]) < theta:
                    share[x] += 1.0
    payouts(market, buyer, refund, share, weights)
