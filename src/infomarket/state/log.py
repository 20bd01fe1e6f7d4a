"""The log: what a run records (the clock, error bits, the event and payment logs, the wealth history,
items per site), its builder and its growth.

Written only by the engine's loop (clock, history, items per site) and by ledger operations (events,
payments, error bits): in compiled code every log array is read-only elsewhere (``state.view``).  The
event and payment logs are empty unless recorded; the host grows them between steps when the kernel
asks for room (``grow_log``), so a step never outgrows them.
"""
from __future__ import annotations

import numpy as np

from .spec import Spec, fields

# Event kinds in the event log.
EV_PURCHASE = 0
EV_REFUSED = 1
EV_DEPOSIT = 2
EVENT_NAMES = ("purchase", "refused", "deposit")

#: First capacity of the event and payment logs when recording.
EVENT_CAPACITY = 4096

_EVENTS = [
    ("ev_step", "int64", "E", "step of each event"),
    ("ev_kind", "int64", "E", "EV_PURCHASE / EV_REFUSED / EV_DEPOSIT"),
    ("ev_buyer", "int64", "E", "buyer (the depositing robot for a deposit)"),
    ("ev_seller", "int64", "E", "seller (-1 for a deposit)"),
    ("ev_site", "int64", "E", "0 food, 1 nest (-1 for a deposit)"),
    ("ev_dir", "float64", "E", "direction of the bought vector in the buyer's frame, degrees"),
    ("ev_x", "float64", "E", "bought vector in the buyer's frame, x"),
    ("ev_y", "float64", "E", "bought vector in the buyer's frame, y"),
    ("ev_age", "int64", "E", "age of the bought information, steps"),
    ("ev_stake", "float64", "E", "stake locked by the purchase"),
    ("ev_sx", "float64", "E", "seller's position in the buyer's frame, x (what the light contract signs)"),
    ("ev_sy", "float64", "E", "seller's position in the buyer's frame, y"),
]
_PAYMENTS = [
    ("pay_step", "int64", "E", "step of the deposit that settled the transaction"),
    ("pay_buyer", "int64", "E", "the depositing buyer"),
    ("pay_seller", "int64", "E", "the transaction's seller"),
    ("pay_site", "int64", "E", "0 food, 1 nest"),
    ("pay_weight", "float64", "E", "the seller's normalised weight in the settlement"),
    ("pay_amount", "float64", "E", "money the seller received (0 when weighted out)"),
]

SPEC = Spec("log", [
    *fields("host", [
        ("record", "bool", "", "whether events and payments are logged"),
        ("hist_every", "int", "", "wealth-history interval in steps (0 = off)"),
    ]),
    *fields("log", [
        ("clock", "int64", "1", "the last completed step (the first step is 1)"),
        ("flags", "int64", "1", "error bits (state.flags): compiled code cannot raise"),
        *_EVENTS,
        ("ev_count", "int64", "1", "events logged"),
        *_PAYMENTS,
        ("pay_count", "int64", "1", "payment rows logged"),
        ("hist", "float64", "m,n", "every robot's wealth every hist_every steps (row k: step (k + 1) * hist_every)"),
        ("site_items", "int64", "S", "items picked up at each food site and deposited at each nest "
                                     "(after the transitory period; counted by the terrain step)"),
    ]),
])
EVENT_FIELDS = tuple(name for name, *_ in _EVENTS)
PAYMENT_FIELDS = tuple(name for name, *_ in _PAYMENTS)


def build_log(robots: int, *, record_events: bool, history_every: int, history_rows: int, sites: int) -> dict:
    """An empty log for ``robots`` robots: event and payment logs with room to start when recording."""
    cap = EVENT_CAPACITY if record_events else 0
    z = np.zeros
    log = {"record": bool(record_events), "hist_every": int(history_every),
           "clock": z(1, np.int64), "flags": z(1, np.int64), "ev_count": z(1, np.int64),
           "pay_count": z(1, np.int64), "hist": z((history_rows, robots)), "site_items": z(sites, np.int64)}
    for f in SPEC.fields:
        if f.name in EVENT_FIELDS or f.name in PAYMENT_FIELDS:
            log[f.name] = z(cap, np.dtype(f.dtype))
    SPEC.check(log)
    return log


def _grown(old: np.ndarray, size: int) -> np.ndarray:
    new = np.zeros(size, old.dtype)
    new[:old.shape[0]] = old
    return new


def grow_log(log, events_needed: int, payments_needed: int) -> dict:
    """Replacement arrays (field -> array) so the event log holds ``events_needed`` rows and the payment
    log ``payments_needed``; capacities at least double, so growth is amortised.  ``log``: any object
    with the log's fields (the flat world, or a ledger's book)."""
    changes = {}
    cap = log.ev_step.shape[0]
    if events_needed > cap:
        changes.update({f: _grown(getattr(log, f), max(2 * cap, events_needed)) for f in EVENT_FIELDS})
    cap = log.pay_step.shape[0]
    if payments_needed > cap:
        changes.update({f: _grown(getattr(log, f), max(2 * cap, payments_needed)) for f in PAYMENT_FIELDS})
    return changes
