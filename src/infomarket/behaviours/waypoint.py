"""Waypoint robots: naive buyers that trade paths once a straight line has failed them.
(Registered as ``waypoint`` by ``infomarket.builtins``, with ``paths=True``.)"""
from .api import buy, combine, next_younger
from .paths import buy_path, offered_path_length, path_length, was_blocked


def waypoint_buy(w, me, nbrs):
    """As ``naive_buy`` (per site, the freshest offer younger than the own entry; one purchase per site
    per step), except that the robot buys the seller's *path* (``paths.buy_path``: the seller's position
    as first waypoint, then the seller's waypoints) and replaces its entry with it when the straight
    line is known to fail: it bumped while seeking that site, or it already follows a path, or the
    offer is itself a path.  Otherwise it buys and averages a vector exactly as a naive robot."""
    for site in range(2):
        s = -1
        while True:
            s = next_younger(w, me, nbrs, site, s)
            if s < 0:
                break
            if was_blocked(w, me, site) or path_length(w, me, site) > 0 or offered_path_length(w, s, site) > 0:
                ok, _ = buy_path(w, me, s, site)
                if ok:
                    break
            else:
                ok, x, y, age = buy(w, me, s, site)
                if ok:
                    combine(w, me, site, x, y, age)
                    break
