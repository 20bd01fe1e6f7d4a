"""What a behaviour's rules may call: reading offers, buying, combining, and the pending list.

All helpers are compiled functions over the world tuple ``w`` (fields in ``engine.world``), so a rule
written with them runs inside the compiled step loop.  Sites are 0 (food) and 1 (nest); vectors are in
the calling robot's own frame (x axis along its heading).

Timing (docs/model.md §3): during the communication phase sellers sell from the table they had at the start
of the step (``own_entry``), while a buyer's purchases go into its new table (``current`` / ``install``
/ ``combine``), which it starts using when it moves.  Stakes and the pending list change at once.
"""
from typing import Any

from numba.extending import overload

from ..jit import njit

from ..engine.geometry import direction, norm
from ..engine.geometry import to_frame, to_world
from ..ledger.kernels import open_transaction, purchase_events

#: ``diff`` of a zero vector (eq. 6 divides by its norm).
DIFF_OF_ZERO = 1000.0


@njit(forceinline=True, cache=True)
def own_entry(w, me, site):
    """The robot's own table entry as it was at the start of the step: (valid, x, y, age)."""
    return w.tab_valid[me, site], w.tab_vec[me, site, 0], w.tab_vec[me, site, 1], w.tab_age[me, site]


@njit(forceinline=True, cache=True)
def current(w, me, site):
    """The robot's table entry including this step's purchases: (valid, x, y, age)."""
    return w.new_valid[me, site], w.new_vec[me, site, 0], w.new_vec[me, site, 1], w.new_age[me, site]


@njit(forceinline=True, cache=True)
def offer(w, seller, site):
    """What a buyer sees of a seller's offer before buying: (valid, age)."""
    return w.off_valid[seller, site], w.off_age[seller, site]


@njit(forceinline=True, cache=True)
def next_candidate(w, nbrs, site, after_age, after_id):
    """The neighbour with a valid offer that comes next after (after_age, after_id) in (age, id) order,
    or -1.  Start with (-1, -1) to get the freshest offer; ties go to the lower id."""
    best = -1
    best_age = 0
    off_valid, off_age = w.off_valid, w.off_age
    for j in range(nbrs.shape[0]):
        s = nbrs[j]
        if not off_valid[s, site]:
            continue
        a = off_age[s, site]
        if a < after_age or (a == after_age and s <= after_id):
            continue
        if best < 0 or a < best_age or (a == best_age and s < best):
            best = s
            best_age = a
    return best


@njit(forceinline=True, cache=True)
def next_younger(w, me, nbrs, site, after):
    """The candidate after ``after`` (-1 to start) in (offered age, id) order whose offer is younger than
    the robot's current entry for ``site``, or -1: the walk every buy rule makes (``next_candidate``,
    stopping at the first offer no fresher than what the robot already has)."""
    s = next_candidate(w, nbrs, site, -1 if after < 0 else w.off_age[after, site], after)
    if s >= 0 and w.off_age[s, site] >= w.new_age[me, site]:
        return -1
    return s


@njit(forceinline=True, cache=True)
def buy(w, me, seller, site):
    """Buy the seller's offer for ``site``: (ok, x, y, age), the vector in the buyer's frame.

    The offer is rotated into the buyer's frame and recorded as a transaction (direction before the
    position offset); under staking the seller locks the stake first and a seller that cannot pay is
    refused (ok False, nothing recorded).  Robots in communication cooldown cannot trade.  The returned
    vector is the rotated offer plus the seller's position in the buyer's frame.
    """
    if not w.off_valid[seller, site] or w.cool_timer[me] > 0 or w.cool_timer[seller] > 0:
        return False, 0.0, 0.0, 0
    gx, gy = to_world(w, seller, w.off_vec[seller, site, 0], w.off_vec[seller, site, 1])
    rx, ry = to_frame(w, me, gx, gy)
    d = direction(rx, ry)
    ox, oy = to_frame(w, me, w.pos[seller, 0] - w.pos[me, 0], w.pos[seller, 1] - w.pos[me, 1])
    age = w.off_age[seller, site]
    ok = open_transaction(w, me, seller, site, d)
    purchase_events(w, ok, me, seller, site, d, rx + ox, ry + oy, age, ox, oy)
    if not ok:
        return False, 0.0, 0.0, 0
    if w.stop_time > 0 or w.cooldown > 0:
        for r in (me, seller):
            w.stop_timer[r] = w.stop_time
            w.cool_timer[r] = w.stop_time + w.cooldown
    return True, rx + ox, ry + oy, age


@njit(forceinline=True, cache=True)
def weighted(ax, ay, a_age, bx, by, b_age):
    """Age-weighted average of eqs. (4)-(5): the younger information gets the larger weight.
    Returns (x, y, age) with age floor((a + b) / 2); equal weights when both ages are 0."""
    total = a_age + b_age
    if total == 0:
        return 0.5 * (ax + bx), 0.5 * (ay + by), 0
    wa = a_age / total  # weight of b (the other's) information is a's age share, and vice versa
    wb = b_age / total
    return wa * bx + wb * ax, wa * by + wb * ay, total // 2


@njit(forceinline=True, cache=True)
def install(w, me, site, x, y, age):
    """Make (x, y, age) the robot's valid entry for ``site`` (takes effect when it moves)."""
    w.new_vec[me, site, 0] = x
    w.new_vec[me, site, 1] = y
    w.new_age[me, site] = age
    w.new_valid[me, site] = True


@njit(forceinline=True, cache=True)
def combine(w, me, site, x, y, age):
    """Combine bought information with the robot's current entry (eqs. 4-5) and install the result;
    an invalid entry is replaced by the bought vector (its age still averaged, as the original does)."""
    valid, ox, oy, oage = current(w, me, site)
    nx, ny, nage = weighted(ox, oy, oage, x, y, age)
    if not valid:
        nx, ny = x, y
    install(w, me, site, nx, ny, nage)


@njit(forceinline=True, cache=True)
def diff(ax, ay, bx, by):
    """Difference score of eq. (6): |a - b| / |a|, and 1000 when |a| = 0."""
    na = norm(ax, ay)
    if na == 0.0:
        return DIFF_OF_ZERO
    return norm(ax - bx, ay - by) / na


@njit(forceinline=True, cache=True)
def pending_count(w, me, site):
    """How many offers for ``site`` robot ``me`` holds pending (bought but not yet used)."""
    return w.pend_count[me, site]


@njit(forceinline=True, cache=True)
def pending_get(w, me, site, j):
    """The j-th pending entry (insertion order): (seller, x, y, age)."""
    return (w.pend_seller[me, site, j], w.pend_vec[me, site, j, 0], w.pend_vec[me, site, j, 1],
            w.pend_age[me, site, j])


@njit(forceinline=True, cache=True)
def pending_has(w, me, site, seller):
    """Whether robot ``me`` holds a pending offer for ``site`` from ``seller`` (a buy rule asks before buying
    twice)."""
    for j in range(w.pend_count[me, site]):
        if w.pend_seller[me, site, j] == seller:
            return True
    return False


@njit(forceinline=True, cache=True)
def pending_add(w, me, site, seller, x, y, age):
    """Append a purchase to the pending list; the list holds at most one entry per seller."""
    k = w.pend_count[me, site]
    if k >= w.pend_seller.shape[2]:
        return False
    w.pend_seller[me, site, k] = seller
    w.pend_vec[me, site, k, 0] = x
    w.pend_vec[me, site, k, 1] = y
    w.pend_age[me, site, k] = age
    w.pend_count[me, site] = k + 1
    return True


@njit(forceinline=True, cache=True)
def pending_clear(w, me, site):
    """Forget all of robot ``me``'s pending offers for ``site`` (e.g. once it has acted on them)."""
    w.pend_count[me, site] = 0


@njit(forceinline=True, cache=True)
def pending_find(w, me, site, seller):
    """Index of the seller's pending entry for ``site``, or -1."""
    for j in range(w.pend_count[me, site]):
        if w.pend_seller[me, site, j] == seller:
            return j
    return -1


@njit(forceinline=True, cache=True)
def pending_remove(w, me, site, j):
    """Drop the j-th pending entry, keeping the others in insertion order (the list doubles as a memory
    of recent purchases: the engine dead-reckons and ages its entries like table entries)."""
    k = w.pend_count[me, site]
    for i in range(j, k - 1):
        w.pend_seller[me, site, i] = w.pend_seller[me, site, i + 1]
        w.pend_vec[me, site, i, 0] = w.pend_vec[me, site, i + 1, 0]
        w.pend_vec[me, site, i, 1] = w.pend_vec[me, site, i + 1, 1]
        w.pend_age[me, site, i] = w.pend_age[me, site, i + 1]
    w.pend_count[me, site] = k - 1


@njit(forceinline=True, cache=True)
def confirm_or_wait(w, me, site, seller, x, y, age, threshold):
    """The sceptic's second chance for a purchase that disagrees with its own entry: if a pending
    purchase agrees with it (diff < threshold), install their age-weighted average and clear the
    pending list (True); otherwise keep it pending, unconfirmed (False)."""
    for j in range(pending_count(w, me, site)):
        _, px, py, page = pending_get(w, me, site, j)
        if diff(px, py, x, y) < threshold:
            cx, cy, cage = weighted(px, py, page, x, y, age)
            install(w, me, site, cx, cy, cage)
            pending_clear(w, me, site)
            return True
    pending_add(w, me, site, seller, x, y, age)
    return False


@njit(forceinline=True, cache=True)
def trust_get(w, me, seller):
    """Robot ``me``'s outcome record of ``seller``: (good, bad), the trips its vectors led to the site and
    those that found nothing there; (0, 0) for a seller it has not judged.  The record is the robot's own
    (no other robot reads or writes it), so a seller cannot fake it as it can fake an offer."""
    for j in range(w.trust_seller.shape[1]):
        if w.trust_seller[me, j] == seller:
            return w.trust_good[me, j], w.trust_bad[me, j]
    return 0.0, 0.0


@njit(forceinline=True, cache=True)
def trust_add(w, me, seller, good, bad):
    """Add ``good`` and ``bad`` outcomes to robot ``me``'s record of ``seller``.  A robot keeps records of at
    most ``kt`` sellers (``engine.swarm.TRUST_SLOTS``): a new seller takes a free slot, else the slot with
    the fewest outcomes (the lowest on a tie), so a long run forgets its least-known sellers first."""
    slot = -1
    for j in range(w.trust_seller.shape[1]):
        if w.trust_seller[me, j] == seller:
            slot = j
            break
    if slot < 0:
        least = 0.0
        for j in range(w.trust_seller.shape[1]):
            seen = w.trust_good[me, j] + w.trust_bad[me, j]
            if w.trust_seller[me, j] < 0:
                slot = j
                break
            if slot < 0 or seen < least:
                slot = j
                least = seen
        w.trust_seller[me, slot] = seller
        w.trust_good[me, slot] = 0.0
        w.trust_bad[me, slot] = 0.0
        w.trust_due[me, slot] = 0.0
    w.trust_good[me, slot] += good
    w.trust_bad[me, slot] += bad
    w.trust_due[me, slot] += bad


@njit(forceinline=True, cache=True)
def trust_settled(w, me):
    """Robot ``me``'s round trip has been settled (its open transactions are none): the failures on its
    records are charged, none is due any more.  A buy rule calls it when ``w.tx_count[me]`` is 0."""
    for j in range(w.trust_due.shape[1]):
        w.trust_due[me, j] = 0.0


@njit(forceinline=True, cache=True)
def _trust_with_due(w, me, seller):
    for j in range(w.trust_seller.shape[1]):
        if w.trust_seller[me, j] == seller:
            return w.trust_good[me, j], w.trust_bad[me, j], w.trust_due[me, j]
    return 0.0, 0.0, 0.0


def trust_record(w, me, seller):
    """Robot ``me``'s record of ``seller`` for a payment rule: (good, bad, due), ``due`` the failed trips
    recorded since its round trip was last settled (``trust_settled``).  A payment rule reads the buyer's
    record through its ``market`` argument, and is also run on a ledger alone (``ledger.replay``, the
    payment checker), where every seller is unjudged: (0, 0, 0)."""
    if not _has_field(w, "trust_seller"):
        return 0.0, 0.0, 0.0
    return _trust_with_due(w, me, seller)


def _has_field(w, name):
    """Does the world (or, compiling, its numba type) hold field ``name``?"""
    names: Any = getattr(w, "field_dict", None) or getattr(w, "_fields", ())
    return name in names


@overload(trust_record, inline="always")
def _trust_record(w, me, seller):
    if _has_field(w, "trust_seller"):
        return lambda w, me, seller: _trust_with_due(w, me, seller)
    return lambda w, me, seller: (0.0, 0.0, 0.0)


@njit(forceinline=True, cache=True)
def origin_set(w, me, site, origin, age):
    """Record that robot ``me``'s entry for ``site``, just installed with ``age``, carries the information of
    robot ``origin`` (provenance: who first sensed it, as far as the robot knows).  Buyers read it as the
    origin of the robot's offers (``origin_of``); only the robot's own buy rule writes it."""
    w.origin[me, site, 0] = origin
    w.origin[me, site, 1] = age
    w.origin[me, site, 2] = w.clock[0]


@njit(forceinline=True, cache=True)
def origin_of(w, seller, site):
    """The robot a seller's offer for ``site`` came from: its recorded origin (``origin_set``) while the
    offer is that record's entry, else the seller itself.  The offer is the start-of-step entry, so a record
    made this step (after it) does not describe it; and an offer younger by two steps or more than the
    recorded age plus the steps since (ages only grow, ±1 for when in the step they do) was sensed since,
    by the seller.  A seller whose rule records nothing (a naive robot, a liar) is its offers' origin."""
    o = w.origin[seller, site, 0]
    if o < 0:
        return seller
    since = w.clock[0] - w.origin[seller, site, 2]
    if since <= 0 or w.off_age[seller, site] + 1 < w.origin[seller, site, 1] + since:
        return seller
    return o
