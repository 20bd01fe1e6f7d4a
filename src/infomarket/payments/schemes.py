"""Built-in payment schemes (docs/model.md §5), registered through the public ``register_payment``.

A scheme only weighs the buyer's transactions; the ledger moves the money (``ledger.kernels.distribute``).
Staking is a ledger setting (``payment.stake``), so any scheme can be run with or without it.
"""
from ..engine.geometry import angular_distance


def delayed_weights(buyer, sellers, sites, directions, weights):
    """Delayed payment: every transaction weighs the same, so sellers are paid per transaction."""
    for x in range(weights.shape[0]):
        weights[x] = 1.0


def outlier_weights(buyer, sellers, sites, directions, weights, theta=30.0):
    """Outlier penalisation (eqs. 7-8): a transaction weighs as many same-site transactions (itself
    included) as point within ``theta`` degrees of it, so isolated directions earn little."""
    k = weights.shape[0]
    for x in range(k):  # itself
        weights[x] = 1.0 if angular_distance(directions[x], directions[x]) < theta else 0.0
    for x in range(k):  # each pair once: the distance is symmetric, bit for bit, and counts add exactly
        for y in range(x + 1, k):
            if sites[y] == sites[x] and angular_distance(directions[x], directions[y]) < theta:
                weights[x] += 1.0
                weights[y] += 1.0

