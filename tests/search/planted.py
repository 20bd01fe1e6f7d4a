"""A defence whose weakness is known by construction, for the search's tests.

``planted_oracle`` robots know the true direction to each site (the defence is planted, not realistic).
An offer that points within ``theta`` degrees of the truth is used as it is, so a lie rotated by less than
``theta`` does the more damage the larger its rotation; an offer further off is penalised: turned back
towards the truth, its error halved at once (just beyond ``theta``) and shrunk further to none at 180°.
The most damaging attack is therefore a rotation just below ``theta`` (30°): a smaller one does less harm
the smaller it is, a larger one at most half as much, the less the larger it is; so a searcher far away
has a slope to follow, and a random point rarely lands in the narrow band below ``theta``.
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
            off = math.degrees(math.atan2(tx * y - ty * x, tx * x + ty * y))  # signed, from the truth
            if abs(off) > theta:  # penalised: the error halved, and shrunk linearly to 0 at 180 degrees
                err = math.copysign(0.5 * theta * (180.0 - abs(off)) / (180.0 - theta), off)
                a = math.atan2(ty, tx) + math.radians(err)
                x, y = nb * math.cos(a), nb * math.sin(a)
            combine(w, me, site, x, y, age)


im.register_behaviour("planted_oracle", buy=oracle_buy, sell="naive", honest=True, replace=True,
                      description="uses an offer only within theta degrees of the truth (a planted defence)")
