"""Behaviours that read the market (``behaviours.market``): the paper's proposed defence of scepticism
filtered by reputation, and two attacks aimed at reputation-based defences.  (Registered by
``infomarket.builtins``; docs/research.md explains them and what the ``future`` sweep found.)"""
from ..engine.geometry import rotate
from .api import buy, combine, confirm_or_wait, current, diff, next_younger, own_entry, pending_clear, pending_has
from .market import sales_settled, seller_reputation, wealth_share


def reputation_sceptic_buy(w, me, nbrs, threshold=0.25, trust_reputation=0.85, trust_share=0.06,
                           distrust_reputation=0.55, min_record=10.0):
    """The sceptical rule, with the seller's standing deciding how much confirmation it needs.  A seller
    with at least ``min_record`` settled sales and a reputation below ``distrust_reputation`` is ignored
    (never bought from, so never paid); one with a record and a reputation of at least
    ``trust_reputation``, or a wealth share of at least ``trust_share``, is believed without a second
    confirmation; anyone else is treated exactly as the sceptical robot treats every seller."""
    for site in range(2):
        s = -1
        while True:
            s = next_younger(w, me, nbrs, site, s)
            if s < 0:
                break
            valid, ox, oy, oage = current(w, me, site)
            if pending_has(w, me, site, s):
                continue
            known = sales_settled(w, s) >= min_record
            rep = seller_reputation(w, s)
            if known and rep < distrust_reputation:
                continue
            ok, x, y, age = buy(w, me, s, site)
            if not ok:
                continue
            trusted = (known and rep >= trust_reputation) or wealth_share(w, s) >= trust_share
            if not valid or trusted or diff(ox, oy, x, y) < threshold:
                combine(w, me, site, x, y, age)
                pending_clear(w, me, site)
                continue
            confirm_or_wait(w, me, site, s, x, y, age, threshold)


def reputation_farmer_sell(w, me, site, rotation_angle=90.0, farm_reputation=0.8, farm_record=10.0,
                           farm_share=0.06):
    """Sell the truth while building a record; lie (rotate by ``rotation_angle``) whenever the record
    is worth spending: at least ``farm_record`` settled sales with a reputation of at least
    ``farm_reputation``, or a wealth share of at least ``farm_share``.  Once caught it falls below the
    threshold and sells honestly again until the record has recovered: farm, spend, farm."""
    valid, x, y, age = own_entry(w, me, site)
    farmed = sales_settled(w, me) >= farm_record and seller_reputation(w, me) >= farm_reputation
    if farmed or wealth_share(w, me) >= farm_share:
        x, y = rotate(x, y, rotation_angle)
    return valid, x, y, age


def theta_surfer_sell(w, me, site, rotation_angle=90.0, margin=0.8, theta=30.0, theta_min=10.0, adaptive=0.0):
    """Lie by ``rotation_angle`` but never by more than ``margin`` times the outlier threshold the
    contract applies to this seller now: Θ itself, or, against the adaptive scheme (``adaptive`` = 1),
    ``theta_min + (theta - theta_min) * reputation``, which it can compute because a smart contract's
    rules and the ledger's record are public.  It exploits the adaptive-Θ defence: the better its
    record, the wider the lie it can afford, and it never lies wide enough to damage that record."""
    valid, x, y, age = own_entry(w, me, site)
    cap = theta
    if adaptive > 0.0:
        cap = theta_min + (theta - theta_min) * seller_reputation(w, me)
    x, y = rotate(x, y, min(rotation_angle, margin * cap))
    return valid, x, y, age
