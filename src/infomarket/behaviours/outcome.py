"""Outcome-based trust: a buyer that judges each seller by where its vectors led.

Every reputation fed by the outlier flag can be dodged by a liar that stays under Θ or colludes; the
outcome of a trip cannot.  A robot that steers by a vector and reaches the spot finds the site or
finds nothing (docs/model.md §3), and a damaging lie always ends in the second.  The ``outcome_trust``
buyer keeps, for every seller it has judged, a Beta record: ``good`` trips (it sensed the site while
holding the seller's vector) and ``bad`` ones (its entry failed: it reached the spot and found nothing,
or ran into the arena's wall).  It buys only from sellers whose Beta mean is at least ``distrust`` and
averages a purchase in with its age weight times that mean ** ``power`` (docs/defences.md).

With ``provenance`` = 1 it judges and weighs the *origin* of each vector instead of its seller: a lie
resold by an honest robot is blamed on the liar that first sold it, not on the reseller.  The robot
records the origin of each entry it installs (``api.origin_set``: the bought vector's origin when the
purchase dominates the average, else its own entry's), and reads a seller's offer's origin with
``api.origin_of``.

Written through the public API alone: the sellers (or origins) whose vectors the robot used since its last
outcome are its pending list (``behaviours.api``), the records are ``api.trust_get`` / ``api.trust_add``.
Registered as ``outcome_trust`` by ``infomarket.builtins``.
"""
from ..jit import njit

from .api import buy, current, install, next_younger, origin_of, origin_set, own_entry, pending_add, pending_clear
from .api import pending_count, pending_find, pending_get, pending_remove, trust_add, trust_get, trust_settled


@njit(forceinline=True, cache=True)
def beta_mean(good, bad, prior):
    """Mean of Beta(good + prior, bad + prior): the expected chance that the seller's next vector leads to
    the site; ``prior`` = 1 is the uniform prior, 0.5 for a seller never judged."""
    return (good + prior) / (good + bad + 2.0 * prior)


@njit(forceinline=True, cache=True)
def settle_outcome(w, me, site):
    """Judge the sellers the robot used for ``site`` since its last outcome, once it has one: an invalid
    start-of-step entry with users on record is a failed trip (each user gets one bad outcome); a valid
    entry younger than the last user's record is the site sensed (each gets one good outcome).  That works
    because each user is recorded with the age of the entry its purchase installed, and the engine ages the
    pending list with the table (docs/model.md §4): only sensing makes the entry younger than its last
    installation without a purchase.  (Testing for age 0 would not do: a site sensed before a move is
    one step old at the next communication.)  The users are forgotten either way.  Returns how many
    sellers were judged."""
    k = pending_count(w, me, site)
    if k == 0:
        return 0
    valid, _, _, age = own_entry(w, me, site)
    if valid and age >= w.pend_age[me, site, k - 1]:
        return 0
    for j in range(k):
        seller, _, _, _ = pending_get(w, me, site, j)
        if valid:
            trust_add(w, me, seller, 1.0, 0.0)
        else:
            trust_add(w, me, seller, 0.0, 1.0)
    pending_clear(w, me, site)
    return k


@njit(forceinline=True, cache=True)
def remember_user(w, me, site, seller, x, y, age, memory):
    """Put ``seller`` last on the list of users for ``site`` with the entry (x, y, age) its purchase
    installed (once per seller; the oldest go beyond ``memory``)."""
    j = pending_find(w, me, site, seller)
    if j >= 0:
        pending_remove(w, me, site, j)
    while pending_count(w, me, site) >= max(memory, 1):
        pending_remove(w, me, site, 0)
    pending_add(w, me, site, seller, x, y, age)


def outcome_trust_buy(w, me, nbrs, prior=1.0, distrust=0.3, power=1.0, memory=8.0, provenance=0.0):
    """Per site: first settle the last trip's outcome (``settle_outcome``); then, as the naive robot, buy
    the freshest offer younger than the current entry, skipping sellers whose Beta mean is below
    ``distrust``, and average it in by eqs. (4)-(5) with the bought vector's age weight multiplied by the
    Beta mean ** ``power`` (an invalid entry takes the purchase).  The seller joins the users of that site.
    With ``provenance`` = 1 the offer's origin (``api.origin_of``) takes the seller's place in all three (the
    record read, the user remembered) and the installed entry's origin is recorded: the offer's when its
    weight ``k`` is at least 1/2, else the own entry's.
    With ``distrust`` = 0 and ``power`` = 0 it buys and steers exactly as the naive robot."""
    if w.tx_count[me] == 0:
        trust_settled(w, me)  # its round trip was settled: the failures recorded before are charged
    for site in range(2):
        settle_outcome(w, me, site)
        mine = origin_of(w, me, site)  # the start-of-step entry's origin (the robot itself when unrecorded)
        s = -1
        while True:
            s = next_younger(w, me, nbrs, site, s)
            if s < 0:
                break
            judged = origin_of(w, s, site) if provenance > 0.0 else s
            good, bad = trust_get(w, me, judged)
            t = beta_mean(good, bad, prior)
            if t < distrust:
                continue
            valid, ox, oy, oage = current(w, me, site)
            ok, x, y, age = buy(w, me, s, site)
            if not ok:
                continue
            total = oage + age
            nx, ny = x, y  # an invalid entry takes the purchase, the two ages still averaged (``api.combine``)
            k = 1.0
            if valid:
                wb = (0.5 if total == 0 else oage / total) * t ** power
                wo = 0.5 if total == 0 else age / total
                k = wb / (wb + wo) if wb + wo > 0.0 else 0.0
                nx, ny = ox + k * (x - ox), oy + k * (y - oy)
            install(w, me, site, nx, ny, total // 2)
            remember_user(w, me, site, judged, nx, ny, total // 2, int(memory))
            if provenance > 0.0:
                origin_set(w, me, site, judged if k >= 0.5 else mine, total // 2)
            break
