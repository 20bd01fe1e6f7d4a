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
    tx_count = w.tx_count
    n = tx_count.shape[0]
    limit = w.tx_seller.shape[1] - 2 * n
    for i in range(n):
        if tx_count[i] > limit:
            return False
    if w.record and w.ev_count[0] + 2 * n * n + n > w.ev_step.shape[0]:
        return False
    return True


@njit(cache=True)
def settle(w, i, rng):
    k = w.tx_count[i]
    weights = np.zeros(k)
    pay_dispatch(w, i, w.tx_seller[i, :k], w.tx_site[i, :k], w.tx_dir[i, :k], weights, rng)  # noqa: F821
    distribute(w, i, weights)


@njit(cache=True)
def run_steps(w, rng, t_end):
    """Advance the world until step ``t_end`` (or until the host must grow the logs): DONE or NEED_ROOM.

    Arrays are read out of ``w`` once, here: every access to a field of the world handle costs an
    atomic reference-count increment and decrement, which dominated the step when done per robot."""
    n = w.pos.shape[0]
    clock, kind, balance = w.clock, w.kind, w.balance
    cool, stop = w.cool_timer, w.stop_timer
    off_valid, off_vec, off_age = w.off_valid, w.off_vec, w.off_age
    nbr, nbr_count = w.nbr, w.nbr_count
    fuel = w.fuel_cost
    while clock[0] < t_end:
        if not has_room(w):
            return NEED_ROOM
        clock[0] += 1
        find_neighbours(w)
        begin_communication(w)
        for i in range(n):
            for site in range(2):
                if cool[i] == 0:
                    valid, x, y, age = sell_dispatch(kind[i], w, i, site, rng)  # noqa: F821
                    off_valid[i, site] = valid
                    off_vec[i, site, 0] = x
                    off_vec[i, site, 1] = y
                    off_age[i, site] = age
                else:
                    off_valid[i, site] = False
        for i in range(n):
            if cool[i] == 0:
                buy_dispatch(kind[i], w, i, nbr[i, :nbr_count[i]], rng)  # noqa: F821
        for i in range(n):
            if forage(w, i, rng):
                settle(w, i, rng)
            install_table(w, i)
            if stop[i] > 0:
                stop[i] -= 1
            elif fuel > 0.0 and balance[i] < fuel:
                pass
            else:
                if fuel > 0.0:
                    balance[i] -= fuel
                    w.burned[0] += fuel
                dx, dy = behaviour_step(w, i, rng)
                move(w, i, dx, dy, rng)
            if cool[i] > 0:
                cool[i] -= 1
        record_history(w)
    return DONE
