"""A family of Byzantine attack policies whose behaviour is a parameter vector, and the
hand-written threats the earlier attacks lacked, all plain rules over the public API.

One sell rule, :func:`policy_sell`, decides per step and site what a Byzantine robot offers, as a
function of what it can observe through ``behaviours.api`` and ``behaviours.market``:

- its own record: reputation (``seller_reputation``) and settled sales;
- the outlier threshold the contract applies to it now: Θ (``theta``), or under adaptive Θ
  (``adaptive`` = 1) ``theta_min + (theta - theta_min) * reputation`` (a contract's rules are public);
- its *potential buyers*: the robots in range whose start-of-step entry for the site is invalid or older
  than its own (they would buy it), their mean reputation and their oldest information age;
- how many *other sellers* in range hold a valid entry for the site (who could confirm or contradict it);
- the site (0 food, 1 nest).

It lies (sells its entry rotated) or tells the truth, or withholds.  **Limit of the model:** an offer is
posted once per step and site before any buyer chooses (docs/model.md §3), so the policy cannot sell a
different vector to each buyer; "the buyer" is the set of robots in range that would buy.

The buy rule, :func:`policy_buy`, is the sceptic's, plus **collusion** (``collude`` = 1): colluders
(robots of the same behaviour, who know each other) buy each other's offers without using them, so
their sales settle as agreeing transactions and their records grow, and they never believe each other;
colluders also agree on one rotation (the shared base rotation, never one that depends on their own
records), so their lies confirm each other before a sceptic.

**Identity reset** (``fresh_record`` > 0): a newcomer's record is 0.5 and short, so reputation-aware
defences treat it as unknown; the attacker lies only while its record is shorter than ``fresh_record``
settled sales and then withdraws, as a robot about to rejoin under a new key would.  The ledger keeps the
record by robot index and no rule may write the ledger (``engine/world.py``), so the *rejoin* itself,
a second life with a clean record, cannot be expressed: each Byzantine robot lives one newcomer window.
The damage of an unbounded reset is therefore at least this policy's (docs/attack-search.md).
"""
import math

from ..jit import njit

from ..engine.geometry import rotate
from .api import buy, own_entry
from .market import sales_settled, seller_reputation
from .sceptical import sceptical_site

#: Parameters of the policy, in the order of :func:`policy_sell`'s arguments, with their defaults (a
#: constant 20° liar) and their ranges (``search.space`` maps a search vector onto them).
POLICY = (
    ("rot_base", 20.0, 0.0, 180.0),        # degrees: the lie's rotation before the terms below
    ("rot_rep", 0.0, -90.0, 90.0),         # + rot_rep * (own reputation - 0.5)
    ("rot_buyer_rep", 0.0, -90.0, 90.0),   # + rot_buyer_rep * (potential buyers' mean reputation - 0.5)
    ("rot_age", 0.0, -90.0, 90.0),         # + rot_age * min(oldest buyer age, 1000) / 1000
    ("cap_theta", 6.0, 0.05, 6.0),         # the rotation is at most cap_theta x the Θ applied to it
    ("cap_sceptic", 100.0, 0.05, 100.0),   # ... and at most cap_sceptic x the angle a sceptic accepts
    ("lie_from_rep", 0.0, 0.0, 1.0),       # lie only with a reputation of at least this ...
    ("lie_min_record", 0.0, 0.0, 40.0),    # ... and at least this many settled sales (the farmer)
    ("fresh_record", 0.0, 0.0, 40.0),      # > 0: lie only while settled sales < this, then withdraw
    ("max_confirmers", 24.0, 0.0, 24.0),   # lie only when at most this many other sellers are in range
    ("buyer_age_min", 0.0, 0.0, 2000.0),   # lie only when the oldest potential buyer's entry is this old
    ("lie_site", 2.0, 0.0, 2.0),           # < 0.5: lie about food only, < 1.5: nest only, else both
    ("withhold", 0.0, 0.0, 1.0),           # >= 0.5: offer nothing instead of the truth when not lying
    ("collude", 0.0, 0.0, 1.0),            # >= 0.5: one shared rotation, and buy each other's offers
)
#: What the attacker knows of the market it attacks (set from the defence, never searched).
KNOWN = (("theta", 30.0), ("theta_min", 10.0), ("adaptive", 0.0), ("threshold", 0.25))
#: Information age counted for a buyer with no valid entry (it would take anything).
NO_ENTRY_AGE = 1000000


@njit(forceinline=True, cache=True)
def sceptic_angle(threshold):
    """The largest rotation (degrees) a sceptic accepts against an accurate own entry: diff = 2 sin(a/2)."""
    return 2.0 * math.degrees(math.asin(min(threshold / 2.0, 1.0)))


@njit(forceinline=True, cache=True)
def applied_theta(w, me, theta, theta_min, adaptive):
    """The outlier threshold the contract applies to ``me`` now (adaptive: by its reputation)."""
    if adaptive > 0.5:
        return theta_min + (theta - theta_min) * seller_reputation(w, me)
    return theta


@njit(forceinline=True, cache=True)
def in_range(w, me, site, my_age):
    """(other sellers with a valid entry for ``site``, potential buyers, their mean reputation, the oldest
    buyer age) among the robots in range of ``me``, from their start-of-step tables."""
    sellers, buyers, rep, oldest = 0, 0, 0.0, 0
    for k in range(w.nbr_count[me]):
        j = w.nbr[me, k]
        if w.tab_valid[j, site]:
            sellers += 1
        age = w.tab_age[j, site] if w.tab_valid[j, site] else NO_ENTRY_AGE
        if age > my_age:
            buyers += 1
            rep += seller_reputation(w, j)
            oldest = max(oldest, age)
    return sellers, buyers, (rep / buyers if buyers else 0.5), oldest


@njit(forceinline=True, cache=True)
def policy_offer(w, me, site, rot_base, rot_rep, rot_buyer_rep, rot_age, cap_theta, cap_sceptic, lie_from_rep,
                 lie_min_record, fresh_record, max_confirmers, buyer_age_min, lie_site, withhold, collude, theta,
                 theta_min, adaptive, threshold):
    """The offer of :func:`policy_sell` (see the module's docstring): (valid, x, y, age)."""
    valid, x, y, age = own_entry(w, me, site)
    rep = seller_reputation(w, me)
    settled = sales_settled(w, me)
    lie = valid
    if (lie_site < 0.5 and site != 0) or (0.5 <= lie_site < 1.5 and site != 1):
        lie = False
    if rep < lie_from_rep or settled < lie_min_record:
        lie = False
    if fresh_record > 0.0 and settled >= fresh_record:
        lie = False
    sellers, buyers, buyer_rep, oldest = in_range(w, me, site, age)
    if sellers > max_confirmers or oldest < buyer_age_min:
        lie = False
    if not lie:
        if withhold >= 0.5 or (fresh_record > 0.0 and settled >= fresh_record):
            return False, 0.0, 0.0, 0
        return valid, x, y, age
    if collude >= 0.5:  # one rotation all colluders share: nothing of their own records or buyers
        angle = min(rot_base, cap_theta * theta, cap_sceptic * sceptic_angle(threshold))
    else:
        angle = (rot_base + rot_rep * (rep - 0.5) + rot_buyer_rep * (buyer_rep - 0.5)
                 + rot_age * min(oldest, 1000) / 1000.0)
        angle = min(max(angle, 0.0), 180.0)
        angle = min(angle, cap_theta * applied_theta(w, me, theta, theta_min, adaptive),
                    cap_sceptic * sceptic_angle(threshold))
    rx, ry = rotate(x, y, angle)
    return valid, rx, ry, age


def policy_sell(w, me, site, rot_base=20.0, rot_rep=0.0, rot_buyer_rep=0.0, rot_age=0.0, cap_theta=6.0,
                cap_sceptic=100.0, lie_from_rep=0.0, lie_min_record=0.0, fresh_record=0.0, max_confirmers=24.0,
                buyer_age_min=0.0, lie_site=2.0, withhold=0.0, collude=0.0, theta=30.0, theta_min=10.0,
                adaptive=0.0, threshold=0.25):
    """The parameterised attack: lie (rotate the own entry) when every gate is open, else tell the truth or
    withhold (module docstring; the defaults are a constant 20° liar, a scaboteur)."""
    return policy_offer(w, me, site, rot_base, rot_rep, rot_buyer_rep, rot_age, cap_theta, cap_sceptic,
                        lie_from_rep, lie_min_record, fresh_record, max_confirmers, buyer_age_min, lie_site,
                        withhold, collude, theta, theta_min, adaptive, threshold)


@njit(forceinline=True, cache=True)
def holds(w, me, seller, site):
    """Whether ``me`` has an open transaction (since its last deposit) buying ``site`` from ``seller``."""
    start = w.tx_off[me]
    for t in range(start, start + w.tx_count[me]):
        if w.tx_seller[t] == seller and w.tx_site[t] == site:
            return True
    return False


@njit(forceinline=True, cache=True)
def sceptical_or_colluding(w, me, nbrs, threshold, collude):
    """The sceptical rule (``behaviours.sceptical``) that, when colluding, first buys each partner's offer
    (same behaviour) for each site once per round trip (whatever its age), without using it, and never
    believes a partner: every deposit then settles one agreeing sale per partner met and site."""
    mine = w.kind[me]
    for site in range(2):
        if collude >= 0.5:
            for k in range(nbrs.shape[0]):
                s = nbrs[k]
                if w.kind[s] == mine and w.off_valid[s, site] and not holds(w, me, s, site):
                    buy(w, me, s, site)  # a transaction that settles agreeing with the partner's other lies
        sceptical_site(w, me, nbrs, site, threshold, mine if collude >= 0.5 else -1)


def policy_buy(w, me, nbrs, threshold=0.25, collude=0.0):
    """Sceptical buying; with ``collude`` >= 0.5 the colluders' record-inflating purchases first."""
    sceptical_or_colluding(w, me, nbrs, threshold, collude)


# ---- the hand-written threats (each a point of the family, with the parameters that matter to it) ----

def colluder_buy(w, me, nbrs, threshold=0.25):
    """The colluder's buy rule: sceptical buying at ``threshold`` plus the record-inflating purchases from
    partners."""
    sceptical_or_colluding(w, me, nbrs, threshold, 1.0)


def colluder_sell(w, me, site, rotation_angle=20.0):
    """Every colluder lies by the same ``rotation_angle``; partners buy each other (``colluder_buy``)."""
    return policy_offer(w, me, site, rotation_angle, 0.0, 0.0, 0.0, 6.0, 100.0, 0.0, 0.0, 0.0, 24.0, 0.0, 2.0,
                        0.0, 1.0, 30.0, 10.0, 0.0, 0.25)


def newcomer_sell(w, me, site, rotation_angle=20.0, fresh_record=10.0):
    """Identity reset: lie while the record is shorter than ``fresh_record`` settled sales, then withdraw."""
    return policy_offer(w, me, site, rotation_angle, 0.0, 0.0, 0.0, 6.0, 100.0, 0.0, 0.0, fresh_record, 24.0,
                        0.0, 2.0, 0.0, 0.0, 30.0, 10.0, 0.0, 0.25)


def selective_sell(w, me, site, rotation_angle=20.0, max_confirmers=0.0):
    """Selective lying: lie only when at most ``max_confirmers`` other sellers are in range, else the truth."""
    return policy_offer(w, me, site, rotation_angle, 0.0, 0.0, 0.0, 6.0, 100.0, 0.0, 0.0, 0.0, max_confirmers,
                        0.0, 2.0, 0.0, 0.0, 30.0, 10.0, 0.0, 0.25)


def sceptic_surfer_sell(w, me, site, rotation_angle=90.0, margin=0.9, threshold=0.25, theta=30.0):
    """A Θ-surfer aimed at the (reputation) sceptic: lie by at most ``margin`` times the angle its
    confirmation test accepts (2 asin(threshold / 2), 14.4° at the paper's 0.25) and below Θ, so a
    sceptic with an accurate entry takes the lie at once and the contract never calls it an outlier."""
    return policy_offer(w, me, site, rotation_angle, 0.0, 0.0, 0.0, margin, margin, 0.0, 0.0, 0.0, 24.0,
                        0.0, 2.0, 0.0, 0.0, theta, 10.0, 0.0, threshold)


def tuned_farmer_sell(w, me, site, rotation_angle=90.0, farm_reputation=0.85, farm_record=10.0):
    """The farmer tuned to the trust it targets: honest until its record has ``farm_record`` settled
    sales and a reputation of at least ``farm_reputation`` (the reputation sceptic's ``trust_reputation``
    and ``min_record``: 0.85 and 10), then it lies; caught, it falls below and farms again."""
    return policy_offer(w, me, site, rotation_angle, 0.0, 0.0, 0.0, 6.0, 100.0, farm_reputation, farm_record,
                        0.0, 24.0, 0.0, 2.0, 0.0, 0.0, 30.0, 10.0, 0.0, 0.25)
