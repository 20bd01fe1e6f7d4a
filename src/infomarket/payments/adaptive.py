"""Adaptive-Θ outlier penalisation: the paper's proposed "Θ as a function of the reputation of the robot
providing information", using the ledger's own record (``behaviours.market``).  Registered as
``adaptive_outlier`` by ``infomarket.builtins``; runs with or without staking like every scheme."""
from ..behaviours.market import seller_reputation
from ..engine.geometry import angular_distance


def adaptive_outlier_weights(buyer, sellers, sites, directions, weights, market, theta=30.0, theta_min=10.0):
    """Eqs. (7)-(8) with a threshold per seller: a transaction weighs as many same-site transactions
    (itself included) as point within ``theta_min + (theta - theta_min) * reputation`` degrees of it,
    where reputation is the seller's share of settled sales not judged outliers (Laplace; 0.5 for a
    newcomer).  A seller with a record of outliers must agree more closely to be paid."""
    k = weights.shape[0]
    for x in range(k):
        limit = theta_min + (theta - theta_min) * seller_reputation(market, sellers[x])
        c = 0
        for y in range(k):
            if sites[y] == sites[x] and angular_distance(directions[x], directions[y]) < limit:
                c += 1
        weights[x] = c
