"""One seller, one voice: outlier penalisation in which a seller counts at most once (docs/chain.md).

The paper's outlier scheme (eq. 7) counts transactions, so a seller that sells the same vector many
times, or under many accounts, inflates the weight of its own sales.  ``outlier_distinct`` counts
sellers instead: a transaction weighs as many *distinct sellers* as have a same-site transaction
within ``theta`` degrees of it (its own seller included, once), and that weight is split across the seller's
transactions for the
same site in the round trip, so repeating a sale earns nothing more than selling it once.
Registered as ``outlier_distinct`` by ``infomarket.builtins``; the contract implements the same rule
(``Scheme.OutlierDistinct`` in contracts/InformationMarket.sol).
"""
import numpy as np

from ..engine.geometry import angular_distance


def outlier_distinct_weights(buyer, sellers, sites, directions, weights, theta=30.0):
    """w[x] = (distinct sellers with a same-site transaction within ``theta`` of x) / (x's seller's
    transactions for x's site in the round trip).  O(k^2) for k transactions."""
    k = weights.shape[0]
    first = np.empty(k, dtype=np.int64)  # index of the first transaction of each transaction's seller
    sales = np.zeros((k, 2), dtype=np.int64)  # transactions per seller and site, at the seller's first index
    for x in range(k):
        f = x
        for y in range(x):
            if sellers[y] == sellers[x]:
                f = first[y]
                break
        first[x] = f
        sales[f, sites[x]] += 1
    mark = np.full(k, -1, dtype=np.int64)  # mark[first index of a seller] = x once it counted for x
    for x in range(k):
        c = 0
        for y in range(k):
            if mark[first[y]] != x and sites[y] == sites[x] and angular_distance(directions[x], directions[y]) < theta:
                mark[first[y]] = x
                c += 1
        weights[x] = c / sales[first[x], sites[x]]
