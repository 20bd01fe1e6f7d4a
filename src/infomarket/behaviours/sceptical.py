"""Sceptical robots: use bought information only when something confirms it (eq. 6, pending list).
(Registered as ``sceptical`` by ``infomarket.builtins``.)"""
from ..jit import njit

from .api import buy, combine, confirm_or_wait, current, diff, next_younger, pending_clear, pending_has


def sceptical_buy(w, me, nbrs, threshold=0.25):
    """Per site, every candidate (in offered-age order) younger than the current entry and not already
    pending is bought; it is used if it agrees with the own entry (diff < threshold, or the entry is
    invalid), or with a pending purchase, which it is then averaged with; otherwise it waits, pending."""
    for site in range(2):
        sceptical_site(w, me, nbrs, site, threshold, -1)


@njit(forceinline=True, cache=True)
def sceptical_site(w, me, nbrs, site, threshold, ignore_kind):
    """The sceptical rule for one site, never buying from sellers of behaviour kind ``ignore_kind`` (-1:
    none; colluders pass their own, ``behaviours.attacks``)."""
    s = -1
    while True:
        s = next_younger(w, me, nbrs, site, s)
        if s < 0:
            break
        valid, ox, oy, oage = current(w, me, site)
        if w.kind[s] == ignore_kind or pending_has(w, me, site, s):
            continue
        ok, x, y, age = buy(w, me, s, site)
        if not ok:
            continue
        if not valid or diff(ox, oy, x, y) < threshold:
            combine(w, me, site, x, y, age)
            pending_clear(w, me, site)
            continue
        confirm_or_wait(w, me, site, s, x, y, age, threshold)
