"""Stake slashed by trip outcomes: the market-side half of outcome-based trust.

Every other market rule judges a record by its direction (the Θ-outlier flag, the consensus), which a
liar under Θ or a colluding majority passes.  What no seller can fake is where its vector led the buyer:
a damaging lie always ends with the buyer at the spot finding nothing (docs/model.md §3).  Buyers that
keep outcome records (``outcome_trust``: a Beta record of each seller, or with provenance of each origin,
fed by its trips) report them to the market when they deposit: ``outcome_slash`` reads the depositing
buyer's record of each seller (``api.trust_record`` through its ``market`` argument) and gives back only
the share of the stake that record supports, sharing the rest among the sellers by that share times the
paper's agreement count (eq. 7).  ``trip_slash`` charges the round trip's own failures instead: each
trip that failed on a seller's vector since the buyer's last settlement voids the stake of one of that
seller's records.  Registered by ``infomarket.builtins``; docs/defences.md gives the equations and where
the rules break.
"""
import numpy as np

from ..jit import njit

from ..behaviours.api import trust_record
from ..engine.geometry import angular_distance
from .consensus import payouts


def outcome_slash_weights(buyer, sellers, sites, directions, weights, market, theta=30.0, grace=1.0):
    """Seller x, of whose vectors the buyer recorded ``g`` good and ``b`` failed trips, keeps the fraction
    ``(g + grace) / (g + b + grace)`` of its stake (all of it when never judged: a failure costs only once
    recorded, and ``grace`` successes of doubt soften the first ones), and shares the rest of the round
    trip's amount by that fraction times its eq. 7 count (same-site records within ``theta`` degrees,
    itself included)."""
    k = weights.shape[0]
    keep = np.empty(k)
    share = np.empty(k)
    for x in range(k):
        good, bad, _ = trust_record(market, buyer, sellers[x])
        keep[x] = (good + grace) / (good + bad + grace)
        share[x] = keep[x] * agreement(sites, directions, x, theta)
    payouts(market, buyer, keep, share, weights)


@njit(forceinline=True, cache=True)
def agreement(sites, directions, x, theta):
    """Eq. 7's count for record x: same-site records within ``theta`` degrees of it, itself included."""
    c = 0.0
    for y in range(sites.shape[0]):
        if sites[y] == sites[x] and angular_distance(directions[x], directions[y]) < theta:
            c += 1.0
    return c


def trip_slash_weights(buyer, sellers, sites, directions, weights, market, theta=30.0):
    """Seller x, with ``m`` records in the round trip and ``f`` failed trips on its vectors recorded by the
    buyer since its last settlement (``due``), keeps the fraction ``1 - min(1, f / m)`` of each record's
    stake (a failed trip voids one record's stake), and shares the rest of the amount by that fraction
    times its eq. 7 count."""
    k = weights.shape[0]
    keep = np.empty(k)
    share = np.empty(k)
    for x in range(k):
        m = 0.0
        for y in range(k):
            if sellers[y] == sellers[x]:
                m += 1.0
        _, _, due = trust_record(market, buyer, sellers[x])
        keep[x] = 1.0 - min(1.0, due / m)
        share[x] = keep[x] * agreement(sites, directions, x, theta)
    payouts(market, buyer, keep, share, weights)
