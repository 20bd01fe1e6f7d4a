"""Compiled ledger operations: the only code that changes the ledger's arrays (``ledger.state``).

They run on anything with the ledger's fields, its log and a clock: inside the engine on the flat world,
or alone on a ``ledger.state.Book`` (``ledger.replay``).  Everywhere else those arrays are read-only in
compiled code (``state.view``); each operation here ``unlock``s the arrays it writes.

Money is conserved by construction: the only operations are transfers between balances and pots,
the reward issued on a deposit, and (optionally) fuel burned by moving robots.
"""
import math

from ..jit import njit

from numba.extending import overload

from ..state import flags
from ..state.log import EV_DEPOSIT, EV_PURCHASE, EV_REFUSED
from ..state.view import unlock
from .instant import open_transaction as instant_open
from .poa.mempool import reveal as poa_reveal
from .poa.spec import runs_poa
#: A settled sale counts as an outlier in its seller's reputation record when the scheme weighed it
#: below this fraction of the best weight given to the same site in that settlement (or 0).  Half, not
#: "below the best": with outlier penalisation honest sales weigh anywhere near the best (drift spreads
#: them), while a rotated one agrees only with the other liars' and weighs a fraction of it.
OUTLIER_FRACTION = 0.5


@njit(cache=True)
def log_event(w, kind, buyer, seller, site, direction, x, y, age, stake, sx=0.0, sy=0.0):
    """Append one event to the log when recording; the host keeps enough room for a whole step."""
    if not w.record:
        return
    k = w.ev_count[0]
    if k >= w.ev_step.shape[0]:
        unlock(w.flags)[0] |= flags.EVENT_OVERFLOW
        return
    unlock(w.ev_step)[k] = w.clock[0]
    unlock(w.ev_kind)[k] = kind
    unlock(w.ev_buyer)[k] = buyer
    unlock(w.ev_seller)[k] = seller
    unlock(w.ev_site)[k] = site
    unlock(w.ev_dir)[k] = direction
    unlock(w.ev_x)[k] = x
    unlock(w.ev_y)[k] = y
    unlock(w.ev_age)[k] = age
    unlock(w.ev_stake)[k] = stake
    unlock(w.ev_sx)[k] = sx
    unlock(w.ev_sy)[k] = sy
    unlock(w.ev_count)[0] = k + 1


@njit(cache=True)
def log_payment(w, buyer, tx, weight, amount):
    """Append one row to the payments log: what the seller of pool transaction ``tx`` received."""
    k = w.pay_count[0]
    if k >= w.pay_step.shape[0]:
        unlock(w.flags)[0] |= flags.EVENT_OVERFLOW
        return
    unlock(w.pay_step)[k] = w.clock[0]
    unlock(w.pay_buyer)[k] = buyer
    unlock(w.pay_seller)[k] = w.tx_seller[tx]
    unlock(w.pay_site)[k] = w.tx_site[tx]
    unlock(w.pay_weight)[k] = weight
    unlock(w.pay_amount)[k] = amount
    unlock(w.pay_count)[0] = k + 1


def open_transaction(w, buyer, seller, site, direction):
    """Open a transaction (a purchase) with the world's ledger: True when the seller can pay the stake.
    The instant ledger (``ledger.instant``) locks the stake and records it at once; the chain model
    (``ledger.poa.mempool``) lets the seller's own view decide and sends a reveal that a block applies
    later.  Compiled code is resolved by the world's type (``ledger.backends.runs_poa``), so a kernel of
    one ledger compiles nothing of the other."""
    if runs_poa(w):
        return poa_reveal(w, buyer, seller, site, direction)
    return instant_open(w, buyer, seller, site, direction)


@overload(open_transaction, inline="always")
def _open_transaction(w, buyer, seller, site, direction):
    if runs_poa(w):
        return lambda w, buyer, seller, site, direction: poa_reveal(w, buyer, seller, site, direction)
    return lambda w, buyer, seller, site, direction: instant_open(w, buyer, seller, site, direction)


@njit(forceinline=True, cache=True)
def trip_expired(w, buyer):
    """Whether the buyer's open round trip has expired (never without stake expiry): its first
    transaction was opened at a step t with t + stake_expiry <= now.  It is then settled whole, as a
    deposit would settle it (``settle_expired``), at the start of the step."""
    if w.stake_expiry <= 0 or w.tx_count[buyer] == 0:
        return False
    return w.tx_step[w.tx_off[buyer]] + w.stake_expiry <= w.clock[0]


@njit(cache=True)
def settlement(w, buyer):
    """The buyer's open transactions as (sellers, sites, directions): views of its pool block, what the
    scheme weighs."""
    a = w.tx_off[buyer]
    b = a + w.tx_count[buyer]
    return w.tx_seller[a:b], w.tx_site[a:b], w.tx_dir[a:b]


@njit(forceinline=True, cache=True)
def purchase_events(w, ok, buyer, seller, site, direction, x, y, age, sx, sy):
    """Log a purchase (or, if refused, the refusal) in the event log; an accepted one records the stake it locked."""
    log_event(w, EV_PURCHASE if ok else EV_REFUSED, buyer, seller, site, direction, x, y, age,
              w.stake if ok else 0.0, sx, sy)


@njit(forceinline=True, cache=True)
def _record_sale(w, seller, weight, top, pay, stake):
    """The seller's reputation record for one settled transaction (ledger.state, REPUTATION): O(1)."""
    unlock(w.rep_settled)[seller] += 1
    outlier = weight <= 0.0 or weight < OUTLIER_FRACTION * top
    if outlier:
        unlock(w.rep_reduced)[seller] += 1
    if w.rep_decay < 1.0:  # the decayed record: older sales count rep_decay times less at each new one
        good, bad = unlock(w.rep_good), unlock(w.rep_bad)
        good[seller] = w.rep_decay * good[seller] + (0.0 if outlier else 1.0)
        bad[seller] = w.rep_decay * bad[seller] + (1.0 if outlier else 0.0)
    unlock(w.rep_earned)[seller] += pay
    if stake > pay:
        unlock(w.rep_stake_lost)[seller] += stake - pay


@njit(cache=True)
def distribute(w, buyer, weights):
    """Settle a deposit: reward and pot to the buyer, then ``info_share * reward + pot`` from the buyer
    to the sellers of its open transactions in proportion to ``weights`` (one per transaction); clear
    them.  Each seller's reputation record is updated from its weight (an outlier when below half the
    best weight of its site in this settlement), so rules can read how the market has judged it."""
    _settle(w, buyer, weights, w.reward, w.info_share * w.reward, True)


@njit(cache=True)
def settle_expired(w, buyer, weights):
    """The stake-expiry rule (docs/chain.md): an expired round trip (``trip_expired``) is settled as a
    deposit settles it, every transaction weighed, but with no reward: the buyer pays the information
    share from its balance, as far as that goes, and its next deposit keeps the whole reward unless it
    bought again.  So a seller is paid by weight however late (a liar's many records are no better paid
    for expiring) and a buyer gains nothing by waiting for its transactions to expire."""
    share = min(w.info_share * w.reward, max(w.balance[buyer], 0.0))
    _settle(w, buyer, weights, 0.0, share, False)


@njit(cache=True)
def _settle(w, buyer, weights, reward, share, deposit):
    """Reward and pot to the buyer, then ``share + pot`` from the buyer to its sellers by ``weights``;
    the deposit's reputation count and event when ``deposit``."""
    n = w.tx_count[buyer]
    balance, tx_count = unlock(w.balance), unlock(w.tx_count)
    balance[buyer] += reward
    pot = w.pot[buyer]
    balance[buyer] += pot
    unlock(w.pot)[buyer] = 0.0
    unlock(w.money)[0] += reward + pot
    if deposit:
        unlock(w.rep_deposits)[buyer] += 1
    total = 0.0
    top0 = 0.0
    top1 = 0.0
    a = w.tx_off[buyer]
    for x in range(n):
        wx = weights[x]
        if not (wx >= 0.0) or math.isinf(wx):
            unlock(w.flags)[0] |= flags.BAD_WEIGHTS
            tx_count[buyer] = 0
            return
        total += wx
        if w.tx_site[a + x] == 0:
            top0 = max(top0, wx)
        else:
            top1 = max(top1, wx)
    amount = share + pot
    paid = n > 0 and total > 0.0
    for x in range(n):
        seller = w.tx_seller[a + x]
        pay = amount * (weights[x] / total) if paid else 0.0
        if paid:
            balance[seller] += pay
        _record_sale(w, seller, weights[x], top0 if w.tx_site[a + x] == 0 else top1, pay, w.tx_stake[a + x])
    if paid:
        balance[buyer] -= amount
        if not deposit and balance[buyer] < 0.0:  # it paid its whole balance: no float residue below 0
            unlock(w.money)[0] -= balance[buyer]
            balance[buyer] = 0.0
        if w.record:
            for x in range(n):
                log_payment(w, buyer, a + x, weights[x] / total, amount * (weights[x] / total))
    elif w.record:
        for x in range(n):
            log_payment(w, buyer, a + x, 0.0, 0.0)
    tx_count[buyer] = 0
    if deposit:
        log_event(w, EV_DEPOSIT, buyer, -1, -1, 0.0, 0.0, 0.0, 0, 0.0, 0.0, 0.0)


@njit(forceinline=True, cache=True)
def burn_fuel(w, i):
    """Robot i pays the fuel cost of one move (the caller checked it can): burned, not paid to anyone."""
    fuel = w.fuel_cost
    unlock(w.balance)[i] -= fuel
    unlock(w.burned)[0] += fuel
    unlock(w.money)[0] -= fuel
