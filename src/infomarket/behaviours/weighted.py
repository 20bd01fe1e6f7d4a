"""A defence by continuous trust: honest robots that average bought information in with a weight that
grows with the seller's reputation, instead of the sceptic's yes/no confirmation.
(Registered as ``reputation_weighted`` by ``infomarket.builtins``.)"""
from .api import buy, current, install, next_younger
from .market import seller_reputation


def reputation_weighted_buy(w, me, nbrs, power=2.0):
    """Per site, buy the freshest offer younger than the own entry (as the naive robot does) and average it
    in by eqs. (4)-(5), its age weight multiplied by ``reputation ** power`` (the seller's share of
    non-outlier sales, 0.5 for a newcomer): a seller with a record of outliers barely moves the entry,
    one with a clean record counts as the paper's weighting says.  An invalid entry takes the purchase;
    ``power`` = 0 is the naive robot."""
    for site in range(2):
        s = -1
        while True:
            s = next_younger(w, me, nbrs, site, s)
            if s < 0:
                break
            valid, ox, oy, oage = current(w, me, site)
            ok, x, y, age = buy(w, me, s, site)
            if not ok:
                continue
            total = oage + age
            if not valid:  # as ``api.combine``: the bought vector, the two ages still averaged
                install(w, me, site, x, y, total // 2)
                break
            wb = 0.5 if total == 0 else oage / total  # eqs. (4)-(5): the bought vector's age weight
            wb *= seller_reputation(w, s) ** power
            wo = 1.0 - (0.5 if total == 0 else oage / total)
            k = wb / (wb + wo) if wb + wo > 0.0 else 0.0
            install(w, me, site, ox + k * (x - ox), oy + k * (y - oy), (oage + age) // 2)
            break
