"""A k-seller vote for a robot that knows nothing: the sceptic's blind spot, closed.

A sceptic checks a purchase against its own entry, so when that entry is invalid (never known, or it
just failed) it takes the first offer unchecked, and a liar's vector goes in whole.  The ``vote_k``
buyer, when its entry for a site is invalid, buys from up to ``k`` distinct sellers, holds the
purchases (the pending list, dead-reckoned by the engine), and installs their robust combination only
once it holds ``k``; with a valid entry it is the paper's sceptic (docs/defences.md).

Written through the public API alone (the combinations are ``behaviours.robust``'s); registered as
``vote_k`` by ``infomarket.builtins``.
"""
import numpy as np

from ..jit import njit

from .api import buy, install, next_candidate, own_entry, pending_clear, pending_count, pending_find, pending_get
from .api import pending_remove
from .robust import GEOMETRIC, MEDIAN, remember, robust_combination
from .sceptical import sceptical_site


@njit(cache=True)
def install_vote(w, me, site, method, iterations):
    """Install the combination (``robust.MEDIAN`` or ``robust.GEOMETRIC``) of the held votes, unweighted,
    aged the lower median of their ages, and forget the votes."""
    k = pending_count(w, me, site)
    xs = np.empty(k)
    ys = np.empty(k)
    ages = np.empty(k, dtype=np.int64)
    for j in range(k):
        _, x, y, age = pending_get(w, me, site, j)
        xs[j] = x
        ys[j] = y
        ages[j] = age
    cx, cy = robust_combination(xs, ys, np.ones(k), method, 0, iterations)
    install(w, me, site, cx, cy, np.sort(ages)[(k - 1) // 2])
    pending_clear(w, me, site)


@njit(forceinline=True, cache=True)
def vote_site(w, me, nbrs, site, k, method, iterations, horizon):
    """Gather votes for ``site`` while the robot's entry is invalid: votes older than ``horizon`` steps are
    dropped (dead reckoning has drifted them), then every offering neighbour is bought in (offered age,
    id) order, except one whose held vote is no older than its offer, until ``k`` are held; then the vote
    is installed.  Returns whether it was."""
    for j in range(pending_count(w, me, site) - 1, -1, -1):
        if w.pend_age[me, site, j] > horizon:
            pending_remove(w, me, site, j)
    s = -1
    while pending_count(w, me, site) < k:
        s = next_candidate(w, nbrs, site, -1 if s < 0 else w.off_age[s, site], s)
        if s < 0:
            break
        j = pending_find(w, me, site, s)
        if j >= 0 and w.pend_age[me, site, j] <= w.off_age[s, site]:
            continue
        ok, x, y, age = buy(w, me, s, site)
        if ok:
            remember(w, me, site, s, x, y, age, k)
    if pending_count(w, me, site) >= k:
        install_vote(w, me, site, method, iterations)
        return True
    return False


def vote_k_buy(w, me, nbrs, k=3.0, geometric=1.0, iterations=30.0, horizon=200.0, threshold=0.25):
    """Per site: with an invalid start-of-step entry, vote (``vote_site``: the geometric median of ``k``
    votes, or with ``geometric`` = 0 their coordinate-wise median); with a valid one, the sceptical rule
    with ``threshold``.  ``k`` = 1 takes the first offer, as the sceptic does."""
    for site in range(2):
        valid, _, _, _ = own_entry(w, me, site)
        if valid:
            sceptical_site(w, me, nbrs, site, threshold, -1)
        else:
            vote_site(w, me, nbrs, site, int(k), GEOMETRIC if geometric > 0.0 else MEDIAN, int(iterations), horizon)
