"""A buyer that always takes a path: the seller's position first, then the seller's waypoints."""
import infomarket as im
from infomarket.behaviours.api import current, next_candidate
from infomarket.behaviours.paths import buy_path


def path_buy(w, me, nbrs):
    for site in range(2):
        s = next_candidate(w, nbrs, site, -1, -1)  # the freshest offer
        if s >= 0 and w.off_age[s, site] < current(w, me, site)[3]:
            buy_path(w, me, s, site)


im.register_behaviour("path_follower", buy=path_buy, sell="naive", honest=True, paths=True,
                      description="always buys the freshest younger offer as a path")
