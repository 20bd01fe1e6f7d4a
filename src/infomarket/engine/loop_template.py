"""Template of the compiled step loop.  Never imported as is: ``engine.specialise`` writes a module made of
the step options (``TERRAIN``, ``PATHS``, ``LEDGER``), this source, and the three dispatch functions for the
configured rules (below, declared and left to the generator), so each rule call is a direct, inlinable
call and the whole kernel is cached on disk.  Every step piece it calls is in ``engine.step``, written
once; ``engine.step.variant(TERRAIN, PATHS)`` gives them compiled for this kernel's options, so the code of
a variant the kernel does not use is pruned before numba types it.

Order of operations per step (docs/model.md §3): neighbours; communication (offers from start-of-step
tables, then every robot buys in id order); move (foraging and payment, install the new table,
behaviour step, noisy motion), robots in id order.  An offer is read only by the seller's neighbours, so
a robot without one is not asked for an offer, unless its sell rule draws random numbers (``SELL_DRAWS``:
then it is asked, so the run's draws stay in order); nor does it buy, when its buy rule is registered as
doing nothing without a neighbour (``BUY_ALONE`` false: ``registry.register_behaviour``'s
``needs_neighbours``).  A robot copies its table into the new one it buys into (``begin_communication``)
just before its buy rule runs, and installs it when it moves, only if the rule ran: a robot that bought
nothing keeps its table as it is.

``LEDGER`` names the ledger (``ledger.backends``): ``"instant"``, the paper's, or ``"poa"``, the chain
model (docs/chain-model.md), where a step also opens with a gossip round after the neighbours, purchases
and deposits become pending transactions, and it closes with the signers' blocks.  The loop calls the
same operations on either (``ledger.backends.operations``), chosen before anything compiles, so a
kernel compiles none of the other ledger's code.

Before a step changes anything, ``has_room`` checks that the step cannot outgrow a capacity (neighbour
lists, pending lists, the transaction pool, the event log); if it could, the world's status is NEED_ROOM
with the step not begun, the host grows the arrays (``build.make_room``) and calls again.
"""
import numpy as np

from infomarket.engine.step import record_history, variant
from infomarket.jit import njit
from infomarket.ledger.backends import operations
from infomarket.ledger.kernels import burn_fuel, distribute, settle_expired, settlement, trip_expired
from infomarket.ledger.poa.lists import keep_weights, weighed_before, weights_of
from infomarket.state.view import unlock

DONE = 0
NEED_ROOM = 1
FLAGGED = 2

# ---- provided by the generator (engine.specialise) --------------------------------------------------
#: TERRAIN, PATHS (bools), LEDGER (a name of ledger.backends.LEDGERS): the step options, written above this
#: template
#: sell_dispatch(kind, w, i, site, rng) -> (valid, x, y, age): robot i's offer for ``site``
#: buy_dispatch(kind, w, i, nbrs, rng): robot i buys from its neighbours
#: pay_dispatch(w, buyer, sellers, sites, directions, weights, rng): the scheme's weights
#: SELL_DRAWS: per kind, whether its sell rule takes ``rng`` (a tuple of bools)
#: BUY_ALONE: per kind, whether its buy rule is called for a robot without a neighbour (a tuple of bools)
sell_dispatch = buy_dispatch = pay_dispatch = SELL_DRAWS = BUY_ALONE = None

#: This kernel's step pieces (engine.step.variant), chosen by its options before anything compiles.
find_neighbours, begin_communication, install_table, forage, sense_sites, behaviour_step, move = variant(TERRAIN, PATHS)
#: The chain model's ledger (a constant: numba prunes the branches it turns off).
POA = LEDGER == "poa"


@njit(cache=True)
def has_room(w):
    """Can this step fit?  Per robot and site a buy rule may make one purchase per neighbour, and add
    one pending entry per neighbour; the ledger's operations say whether its transactions fit."""
    nbr_count = w.nbr_count
    kn = w.nbr.shape[1]
    kp = w.pend_seller.shape[2]
    for i in range(nbr_count.shape[0]):
        c = nbr_count[i]
        if c > kn:
            return False
        if w.pend_count[i, 0] + c > kp or w.pend_count[i, 1] + c > kp:
            return False
    return ledger_has_room(w)


@njit(cache=True)
def weigh(w, i, weights, rng):
    """The scheme's weights of robot i's open transactions (ledger.kernels.settlement), into ``weights``."""
    sellers, sites, directions = settlement(w, i)
    pay_dispatch(w, i, sellers, sites, directions, weights, rng)


@njit(cache=True)
def settle(w, i, rng):
    """Robot i's deposit is settled: the scheme weighs its open transactions, then
    ``ledger.kernels.distribute`` pays.  In the chain model a list that any branch settled before keeps
    its weights (``ledger.poa.lists``) when the scheme reads nothing but the list."""
    if POA:
        if weighed_before(w, i):
            distribute(w, i, weights_of(w, i))
            return
    weights = np.zeros(w.tx_count[i])
    weigh(w, i, weights, rng)
    if POA:
        keep_weights(w, i, weights)
    distribute(w, i, weights)


@njit(cache=True)
def expire(w, i, rng):
    """Robot i's round trip expired (``ledger.kernels.trip_expired``): the scheme weighs it as at a
    deposit and ``ledger.kernels.settle_expired`` pays it, with no reward (the chain model has no expiry)."""
    weights = np.zeros(w.tx_count[i])
    weigh(w, i, weights, rng)
    settle_expired(w, i, weights)


#: This kernel's ledger operations (ledger.backends), around its settlement.
ledger_has_room, begin_step, deposit, end_of_step = operations(LEDGER, settle)


@njit(cache=True)
def step_all(views, rngs, t_end, status, clocks):
    """Advance world b (``views[b]``, drawing from ``rngs[b]``) until step ``t_end[b]``, one world after
    the other, and write its clock in ``clocks[b]`` and in ``status[b]`` DONE, NEED_ROOM (the host must
    grow an array first: the step is not begun) or FLAGGED (an error bit is set); -1 is left on the world
    whose step raised.  Returns the count of worlds that are not DONE.  A single run is a batch of one:
    the kernel's code is compiled once, into this one function, whether its runs go alone or together."""
    short = 0
    for b in range(len(views)):
        status[b] = -1  # left there if a rule raises: the host names this run
        w = views[b]
        rng = rngs[b]
        done = DONE
        n = w.pos.shape[0]
        clock, kind, balance = unlock(w.clock), w.kind, w.balance
        cool, stop = w.cool_timer, w.stop_timer
        off_valid, off_vec, off_age = w.off_valid, w.off_vec, w.off_age
        nbr, nbr_count = w.nbr, w.nbr_count
        fuel = w.fuel_cost
        bits = rng.bit_generator  # the engine's own draws (engine.draws); rules get the Generator
        opened = np.zeros(n, np.bool_)  # this step, robot i's buy rule ran (so it has a new table to install)
        while clock[0] < t_end[b]:
            find_neighbours(w)
            if not has_room(w):
                done = NEED_ROOM
                break
            clock[0] += 1
            begin_step(w)
            if w.stake_expiry > 0:
                for i in range(n):
                    if trip_expired(w, i):
                        expire(w, i, rng)
            for i in range(n):
                if nbr_count[i] == 0 and not SELL_DRAWS[kind[i]]:
                    continue  # no neighbour can buy its offer this step, and asking for it draws nothing
                for site in range(2):
                    if cool[i] == 0:
                        valid, x, y, age = sell_dispatch(kind[i], w, i, site, rng)
                        off_valid[i, site] = valid
                        off_vec[i, site, 0] = x
                        off_vec[i, site, 1] = y
                        off_age[i, site] = age
                    else:
                        off_valid[i, site] = False
            for i in range(n):
                opened[i] = cool[i] == 0 and (nbr_count[i] > 0 or BUY_ALONE[kind[i]])
                if opened[i]:
                    begin_communication(w, i)
                    buy_dispatch(kind[i], w, i, nbr[i, :nbr_count[i]], rng)
            for i in range(n):
                if forage(w, i, bits):
                    deposit(w, i, rng)
                if opened[i]:
                    install_table(w, i)
                if stop[i] > 0:
                    stop[i] -= 1
                elif fuel > 0.0 and balance[i] < fuel:
                    pass
                else:
                    if fuel > 0.0:
                        burn_fuel(w, i)
                    dx, dy = behaviour_step(w, i, bits)
                    move(w, i, dx, dy, bits)
                if cool[i] > 0:
                    cool[i] -= 1
            end_of_step(w, rng)
            record_history(w)
        clocks[b] = clock[0]
        status[b] = FLAGGED if w.flags[0] != 0 else done
        if status[b] != DONE:
            short += 1
    return short
