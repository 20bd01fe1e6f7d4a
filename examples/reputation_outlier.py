"""Outlier penalisation that also weighs each seller by its record: liars caught before earn less."""
import infomarket as im
from infomarket.behaviours.market import seller_reputation
from infomarket.engine.geometry import angular_distance


@im.payment("reputation_outlier", description="outlier weight times the seller's reputation")
def reputation_outlier(buyer, sellers, sites, directions, weights, market, theta=30.0):
    for x in range(len(sellers)):
        agree = 0
        for y in range(len(sellers)):
            if sites[y] == sites[x] and angular_distance(directions[x], directions[y]) < theta:
                agree += 1
        weights[x] = agree * seller_reputation(market, sellers[x])
