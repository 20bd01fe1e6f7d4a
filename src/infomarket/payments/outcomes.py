"""Stake slashed by trip outcomes: the market-side half of outcome-based trust.

Every other market rule judges a record by its direction (the Θ-outlier flag, the consensus), which a
liar under Θ or a colluding majority passes.  What no seller can fake is where its vector led the buyer:
a damaging lie always ends with the buyer at the spot finding nothing (docs/model.md §3).  Buyers that
keep outcome records (``outcome_trust``: a Beta record of each seller, or with provenance of each origin,
fed by its trips) report them to the market when they deposit: ``outcome_slash`` reads the depositing
buyer's record of each seller (``api.trust_record`` through its ``market`` argument) and gives back only
the share of the stake that record supports, sharing the rest among the sellers by that share times the
paper's agreement count (eq. 7).  Registered by ``infomarket.builtins``; docs/defences.md gives the
equations and where the rule breaks.
"""
import numpy as np

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
        good, bad = trust_record(market, buyer, sellers[x])
        keep[x] = (good + grace) / (good + bad + grace)
    for x in range(k):
        c = 0.0
        for y in range(k):
            if sites[y] == sites[x] and angular_distance(directions[x], directions[y]) < theta:
                c += 1.0
        share[x] = keep[x] * c
    payouts(market, buyer, keep, share, weights)
