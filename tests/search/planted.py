"""A defence whose weakness is known by construction, for the search's tests.

``planted_oracle`` robots buy every fresher offer and use it only when it points within ``theta`` degrees
of the true direction to the site (they know the truth: the defence is planted, not realistic).  A lie
rotated by less than ``theta`` is used, and does the more damage the larger its rotation; a lie rotated by
more is always refused and does none.  So the most damaging attack is a rotation just below ``theta`` (30°),
and every rotation above it is as harmless as the truth: a plateau that gives a searcher started there no
slope to follow.
"""
import math

import infomarket as im
from infomarket.behaviours.api import buy, combine, next_younger
from infomarket.engine.geometry import to_frame

THETA = 30.0


def oracle_buy(w, me, nbrs, theta=30.0):
    for site in range(2):
        s = -1
        while True:
            s = next_younger(w, me, nbrs, site, s)
            if s < 0:
                break
            ok, x, y, age = buy(w, me, s, site)
            if not ok:
                continue
            tx, ty = to_frame(w, me, w.sites_xy[site, 0] - w.pos[me, 0], w.sites_xy[site, 1] - w.pos[me, 1])
            nb, nt = math.hypot(x, y), math.hypot(tx, ty)
            if nb == 0.0 or nt == 0.0:
                continue
            cos = (x * tx + y * ty) / (nb * nt)
            if math.degrees(math.acos(max(-1.0, min(1.0, cos)))) < theta:
                combine(w, me, site, x, y, age)


im.register_behaviour("planted_oracle", buy=oracle_buy, sell="naive", honest=True, replace=True,
                      description="uses an offer only within theta degrees of the truth (a planted defence)")
