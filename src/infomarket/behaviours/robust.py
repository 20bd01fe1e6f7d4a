"""Robust buyers: robots that keep their last few purchases per site, each from a different seller, and
steer by a robust combination of them (coordinate-wise median, trimmed mean or geometric median), so that
a minority of liars among the sellers moves them by a bounded amount (docs/defences.md).

Written through the public API alone (``behaviours.api``), as a user would: the purchase memory is the
robot's pending list, which the engine dead-reckons and ages like table entries (docs/model.md §4), so the
held vectors stay in the robot's own frame.  Registered as ``robust_median``, ``robust_trimmed`` and
``robust_geometric`` by ``infomarket.builtins``.

The combination functions (``weighted_median``, ``trimmed_mean``, ``coordinate_median``,
``coordinate_trimmed_mean``, ``geometric_median``) are plain compiled functions over numpy arrays, usable
(and tested) on their own.
"""
import math

import numpy as np
from ..jit import njit

from .api import buy, install, next_candidate, own_entry, pending_add, pending_clear, pending_count, pending_find
from .api import pending_get, pending_remove
from .market import seller_reputation

#: Combination methods (the buy rules pass one of these).
MEDIAN, TRIMMED, GEOMETRIC = 0, 1, 2
#: Distance below which a Weiszfeld iterate counts as sitting on a data point.
COINCIDENT = 1e-12


@njit(cache=True)
def weighted_median(v, wt):
    """The weighted median of ``v``: the smallest value at which the cumulative weight (values in
    increasing order, ties in index order) reaches half the total; halfway between it and the next value
    when it reaches exactly half, so unit weights give the ordinary median.  Zero total weight counts
    every value once."""
    k = v.shape[0]
    order = np.argsort(v, kind="mergesort")
    total = 0.0
    for i in range(k):
        total += wt[i]
    unit = total <= 0.0
    if unit:
        total = float(k)
    half = 0.5 * total
    c = 0.0
    for j in range(k):
        c += 1.0 if unit else wt[order[j]]
        if c >= half:
            if c == half and j + 1 < k:
                return 0.5 * (v[order[j]] + v[order[j + 1]])
            return v[order[j]]
    return v[order[k - 1]]


@njit(cache=True)
def trimmed_mean(v, wt, trim):
    """Mean of ``v`` after dropping the ``trim`` smallest and ``trim`` largest values (at most
    (k - 1) // 2 from each end, so something is always left), the kept values weighed by ``wt`` (equally
    when their weights sum to zero)."""
    k = v.shape[0]
    t = min(trim, (k - 1) // 2)
    order = np.argsort(v, kind="mergesort")
    num = 0.0
    den = 0.0
    plain = 0.0
    for j in range(t, k - t):
        i = order[j]
        num += wt[i] * v[i]
        den += wt[i]
        plain += v[i]
    if den <= 0.0:
        return plain / (k - 2 * t)
    return num / den


@njit(cache=True)
def coordinate_median(xs, ys, wt):
    """Coordinate-wise (weighted) median of the vectors (xs[i], ys[i])."""
    return weighted_median(xs, wt), weighted_median(ys, wt)


@njit(cache=True)
def coordinate_trimmed_mean(xs, ys, wt, trim):
    """Coordinate-wise trimmed mean: each coordinate trimmed by ``trim`` at both ends (Yin et al. 2018)."""
    return trimmed_mean(xs, wt, trim), trimmed_mean(ys, wt, trim)


@njit(cache=True)
def geometric_median(xs, ys, wt, iterations):
    """The (weighted) geometric median, the point minimising sum_i wt_i |p - x_i|: ``iterations`` steps
    of Weiszfeld's algorithm in Vardi and Zhang's form (which handles an iterate on a data point: it
    stays there when that point is the minimum, else moves off it), from the coordinate-wise median.
    A fixed count and no tolerance test keep it deterministic and its cost known."""
    k = xs.shape[0]
    w = wt.copy()
    total = 0.0
    for i in range(k):
        total += w[i]
    if total <= 0.0:
        w[:] = 1.0
    px, py = coordinate_median(xs, ys, w)
    for _ in range(iterations):
        nx = 0.0
        ny = 0.0
        den = 0.0
        rx = 0.0
        ry = 0.0
        eta = 0.0
        for i in range(k):
            if w[i] <= 0.0:
                continue
            dx = xs[i] - px
            dy = ys[i] - py
            d = math.sqrt(dx * dx + dy * dy)
            if d <= COINCIDENT:
                eta += w[i]
                continue
            nx += w[i] * xs[i] / d
            ny += w[i] * ys[i] / d
            den += w[i] / d
            rx += w[i] * dx / d
            ry += w[i] * dy / d
        if den == 0.0:
            break
        tx = nx / den
        ty = ny / den
        if eta == 0.0:
            px, py = tx, ty
            continue
        r = math.sqrt(rx * rx + ry * ry)
        if r <= eta:
            break  # the data point under the iterate is the minimum
        g = eta / r
        px, py = (1.0 - g) * tx + g * px, (1.0 - g) * ty + g * py
    return px, py


@njit(cache=True)
def robust_combination(xs, ys, wt, method, trim, iterations):
    """The combination ``method`` (MEDIAN, TRIMMED or GEOMETRIC) of the vectors."""
    if method == MEDIAN:
        return coordinate_median(xs, ys, wt)
    if method == TRIMMED:
        return coordinate_trimmed_mean(xs, ys, wt, trim)
    return geometric_median(xs, ys, wt, iterations)


@njit(forceinline=True, cache=True)
def remember(w, me, site, seller, x, y, age, vectors):
    """Hold a purchase in the robot's memory for ``site``: it replaces the seller's earlier one (one voice
    per seller), and the oldest purchases go until at most ``vectors`` are held."""
    j = pending_find(w, me, site, seller)
    if j >= 0:
        pending_remove(w, me, site, j)
    while pending_count(w, me, site) >= max(vectors, 1):
        pending_remove(w, me, site, 0)
    pending_add(w, me, site, seller, x, y, age)


@njit(cache=True)
def install_combination(w, me, site, method, trim, iterations, power):
    """Install the robust combination of the held purchases and the robot's own start-of-step entry (one
    more voice, weight 1, when valid); each purchase weighs its seller's reputation ** ``power``.  The
    entry's age is the lower median of the held purchases' ages."""
    k = pending_count(w, me, site)
    valid, ox, oy, _ = own_entry(w, me, site)
    n = k + (1 if valid else 0)
    xs = np.empty(n)
    ys = np.empty(n)
    wt = np.empty(n)
    ages = np.empty(k, dtype=np.int64)
    for j in range(k):
        seller, x, y, age = pending_get(w, me, site, j)
        xs[j] = x
        ys[j] = y
        wt[j] = 1.0 if power == 0.0 else seller_reputation(w, seller) ** power
        ages[j] = age
    if valid:
        xs[k] = ox
        ys[k] = oy
        wt[k] = 1.0
    cx, cy = robust_combination(xs, ys, wt, method, trim, iterations)
    install(w, me, site, cx, cy, np.sort(ages)[(k - 1) // 2])


@njit(forceinline=True, cache=True)
def robust_site(w, me, nbrs, site, method, vectors, trim, iterations, power, horizon):
    """One site of a robust buy rule.  A robot whose entry is invalid (never known, or it failed it), or
    fresher than every purchase held (it has sensed the site since), forgets its purchases, and it
    forgets any purchase older than ``horizon`` steps (dead reckoning has drifted it).  Then every
    candidate whose offer is younger than the robot's start-of-step entry is bought, in (offered age, id)
    order, except a seller whose held purchase is no older than its offer (nothing new from it); after
    each purchase the combination is installed.  Comparing with the start-of-step entry, not the current
    one as the naive robot does, is what lets it gather several opinions in one meeting."""
    valid, _, _, oage = own_entry(w, me, site)
    k = pending_count(w, me, site)
    if not valid:
        pending_clear(w, me, site)
    elif k > 0:
        freshest = w.pend_age[me, site, 0]
        for j in range(1, k):
            freshest = min(freshest, w.pend_age[me, site, j])
        if oage < freshest:
            pending_clear(w, me, site)
    for j in range(pending_count(w, me, site) - 1, -1, -1):
        if w.pend_age[me, site, j] > horizon:
            pending_remove(w, me, site, j)
    s = -1
    while True:
        s = next_candidate(w, nbrs, site, -1 if s < 0 else w.off_age[s, site], s)
        if s < 0 or w.off_age[s, site] >= oage:
            break
        j = pending_find(w, me, site, s)
        if j >= 0 and w.pend_age[me, site, j] <= w.off_age[s, site]:
            continue
        ok, x, y, age = buy(w, me, s, site)
        if not ok:
            continue
        remember(w, me, site, s, x, y, age, vectors)
        install_combination(w, me, site, method, trim, iterations, power)


def robust_median_buy(w, me, nbrs, vectors=5.0, power=0.0, horizon=1e9):
    """Hold the last ``vectors`` purchases per site from distinct sellers, none older than ``horizon``
    steps; steer by their coordinate-wise median with the own entry (weighted by the sellers'
    reputation ** ``power``; 0: unweighted)."""
    for site in range(2):
        robust_site(w, me, nbrs, site, MEDIAN, int(vectors), 0, 0, power, horizon)


def robust_trimmed_buy(w, me, nbrs, vectors=5.0, trim=1.0, power=0.0, horizon=1e9):
    """As ``robust_median_buy`` with the coordinate-wise mean after dropping ``trim`` values at each end."""
    for site in range(2):
        robust_site(w, me, nbrs, site, TRIMMED, int(vectors), int(trim), 0, power, horizon)


def robust_geometric_buy(w, me, nbrs, vectors=5.0, iterations=30.0, power=0.0, horizon=1e9):
    """As ``robust_median_buy`` with the geometric median (``iterations`` Weiszfeld steps)."""
    for site in range(2):
        robust_site(w, me, nbrs, site, GEOMETRIC, int(vectors), 0, int(iterations), power, horizon)
