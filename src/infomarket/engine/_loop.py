"""Template of the compiled step loop.  Never called from here: ``engine.specialise`` writes a module
made of this source plus ``sell_dispatch``, ``buy_dispatch`` and ``pay_dispatch`` for the configured
rules, so each rule call is a direct, inlinable call and the whole kernel is cached on disk.

Order of operations per step (MODEL.md §3): neighbours; communication (offers from start-of-step
tables, then every robot buys in id order); move (foraging and payment, install the new table,
behaviour step, noisy motion), robots in id order.
"""
import numpy as np
from numba import njit

from infomarket.engine.kernels import (begin_communication, behaviour_step, find_neighbours, forage,
                                       install_table, move, record_history)
from infomarket.ledger.kernels import distribute

DONE = 0
NEED_ROOM = 1


@njit(cache=True)
def has_room(w):
    """Enough transaction and event capacity for one more step (the host grows the arrays if not)."""
    n = w.pos.shape[0]
    reserve = 2 * n
    for i in range(n):
        if w.tx_count[i] + reserve > w.tx_seller.shape[1]:
            return False
    if w.record and w.ev_count[0] + 2 * n * n + n > w.ev_step.shape[0]:
        return False
    return True


@njit(cache=True)
def settle(w, i):
    k = w.tx_count[i]
    weights = np.zeros(k)
    pay_dispatch(w, i, w.tx_seller[i, :k], w.tx_site[i, :k], w.tx_dir[i, :k], weights)  # noqa: F821
    distribute(w, i, weights)


@njit(cache=True)
def run_steps(w, rng, t_end):
    """Advance the world until step ``t_end`` (or until the host must grow the logs): DONE or NEED_ROOM."""
    n = w.pos.shape[0]
    while w.clock[0] < t_end:
        if not has_room(w):
            return NEED_ROOM
        w.clock[0] += 1
        find_neighbours(w)
        begin_communication(w)
        for i in range(n):
            for site in range(2):
                if w.cool_timer[i] == 0:
                    valid, x, y, age = sell_dispatch(w.kind[i], w, i, site)  # noqa: F821
                    w.off_valid[i, site] = valid
                    w.off_vec[i, site, 0] = x
                    w.off_vec[i, site, 1] = y
                    w.off_age[i, site] = age
                else:
                    w.off_valid[i, site] = False
        for i in range(n):
            if w.cool_timer[i] == 0:
                buy_dispatch(w.kind[i], w, i, w.nbr[i, :w.nbr_count[i]])  # noqa: F821
        for i in range(n):
            if forage(w, i, rng):
                settle(w, i)
            install_table(w, i)
            if w.stop_timer[i] > 0:
                w.stop_timer[i] -= 1
            elif w.fuel_cost > 0.0 and w.balance[i] < w.fuel_cost:
                pass
            else:
                if w.fuel_cost > 0.0:
                    w.balance[i] -= w.fuel_cost
                    w.burned[0] += w.fuel_cost
                dx, dy = behaviour_step(w, i, rng)
                move(w, i, dx, dy, rng)
            if w.cool_timer[i] > 0:
                w.cool_timer[i] -= 1
        record_history(w)
    return DONE
