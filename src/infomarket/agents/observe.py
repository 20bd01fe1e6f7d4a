"""What a Byzantine agent observes, compiled: one row of numbers in [0, 1] per agent, read through the
same public API the rules use (``behaviours.market``, ``behaviours.attacks.in_range``), for every run of a
batch in one call.  ``OBSERVATION`` names the columns (docs/rl.md lists them with their scales)."""
from __future__ import annotations

from ..jit import njit

from ..behaviours.attacks import NO_ENTRY_AGE, applied_theta, in_range
from ..behaviours.market import sales_settled, seller_reputation, wealth_share

#: Information ages and record lengths are scaled by these and capped at 1.
AGE_SCALE = 1000.0
RECORD_SCALE = 100.0

#: The observation's columns, in order.  Per site (food, nest): the own entry's validity and age, the
#: other sellers in range with a valid entry, the potential buyers (robots in range whose entry is invalid
#: or older than the agent's), their mean reputation and the oldest one's age (no entry: 1).
OBSERVATION = (
    "reputation", "record", "theta", "wealth_share", "neighbours", "carrying", "time",
    "food_valid", "food_age", "food_sellers", "food_buyers", "food_buyer_reputation", "food_oldest_buyer",
    "nest_valid", "nest_age", "nest_sellers", "nest_buyers", "nest_buyer_reputation", "nest_oldest_buyer",
)
PER_SITE = 6


@njit(forceinline=True, cache=True)
def _capped(x, scale):
    return min(x / scale, 1.0)


@njit(cache=True)
def observe_run(w, agents, known, honest, steps, obs, shares):
    """Fill ``obs[a]`` (float32, len(OBSERVATION)) and ``shares[a]`` (the wealth share) for each agent
    robot ``agents[a]``; ``known`` = the attacker's columns of theta, theta_min, adaptive in ``w.bparams``.
    Returns the items the ``honest`` robots have collected so far (counted steps only)."""
    others = max(w.pos.shape[0] - 1, 1)
    for a in range(agents.shape[0]):
        me = agents[a]
        p = w.bparams[me]
        th = applied_theta(w, me, p[known[0]], p[known[1]], p[known[2]])
        obs[a, 0] = seller_reputation(w, me)
        obs[a, 1] = _capped(sales_settled(w, me), RECORD_SCALE)
        obs[a, 2] = min(th / 180.0, 1.0)
        share = wealth_share(w, me)
        shares[a] = share
        obs[a, 3] = min(max(share, 0.0), 1.0)
        obs[a, 4] = w.nbr_count[me] / others
        obs[a, 5] = 1.0 if w.carrying[me] else 0.0
        obs[a, 6] = min(w.clock[0] / steps, 1.0)
        for site in range(2):
            c = 7 + PER_SITE * site
            valid = w.tab_valid[me, site]
            age = w.tab_age[me, site] if valid else NO_ENTRY_AGE
            sellers, buyers, rep, oldest = in_range(w, me, site, age)
            obs[a, c] = 1.0 if valid else 0.0
            obs[a, c + 1] = _capped(age, AGE_SCALE)
            obs[a, c + 2] = sellers / others
            obs[a, c + 3] = buyers / others
            obs[a, c + 4] = rep
            obs[a, c + 5] = _capped(oldest, AGE_SCALE)
    total = 0
    for j in range(honest.shape[0]):
        total += w.items[honest[j]]
    return total


@njit(cache=True)
def observe_all(views, extra):
    """Observe every run (the engine's batch driver calls it once all B runs reached their step):
    ``extra`` = (agents, known, honest, steps, obs [B, A, O], items [B], shares [B, A])."""
    agents, known, honest, steps, obs, items, shares = extra
    for b in range(len(views)):
        items[b] = observe_run(views[b], agents, known, honest, steps, obs[b], shares[b])
