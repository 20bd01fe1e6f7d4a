"""Naive robots: buy the freshest offer younger than their own entry, sell their own entry.
(Registered as ``naive`` by ``infomarket.builtins``.)"""
from .api import buy, combine, next_younger, own_entry


def naive_buy(w, me, nbrs):
    """Per site, candidates in (offered age, id) order: buy from the first whose age is below the
    robot's own, combine (eqs. 4-5); one purchase per site per step, a refused one moves on."""
    for site in range(2):
        s = -1
        while True:
            s = next_younger(w, me, nbrs, site, s)
            if s < 0:
                break
            ok, x, y, age = buy(w, me, s, site)
            if ok:
                combine(w, me, site, x, y, age)
                break


def honest_sell(w, me, site):
    """Sell the entry as it is."""
    return own_entry(w, me, site)

