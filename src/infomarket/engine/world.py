"""The world: every piece of simulation state as arrays (struct of arrays), in one named tuple.

One ``World`` is what every compiled function receives (``w``).  Its fields come in four groups, and
the group says who may write a field:

``PARAMS``  never change during a run (scalars, site geometry, sampling tables, rule parameters).  In
            compiled code their arrays are typed read-only, so a rule that writes one does not compile.
``ROBOTS``  the robots' state, written by the engine's step; a buy rule writes only its own robot's
            ``new_*`` table and pending list, through ``behaviours.api``.
``LEDGER``  the simulated blockchain: balances, pots and each buyer's open transactions, written only
            by ``ledger.kernels`` (a rule reaches it through ``api.buy``; payment rules only weigh).
``LOG``     output: the event log, the wealth history and the error flags.

Shapes use ``n`` robots, 2 sites (0 = food, 1 = nest) and small capacities that the host grows between
steps when the kernel asks for room (``build.make_room``): ``kn`` neighbours, ``kp`` pending entries
per site, the transaction pool ``P`` and the event log ``E``.  Nothing is [n, n]: memory is O(n·k).

PARAMS:
    width, height, radius, speed, comm_range, noise_sd: float
    site_pos [2, 2] float64 site centres;  site_r [2] float64 site radii
    reward, info_share, stake, fuel_cost: float;  stake_expiry, transitory, stop_time, cooldown: int
    cauchy_cdf [360] turn-angle CDF (whole degrees);  levy_cdf [steps + 1] step-length CDF
    cauchy_guide, levy_guide: int64 guide tables that make sampling those CDFs O(1) (build.guide_table)
    turn_cos, turn_sin [360]: cos and sin of each whole-degree turn (computed with the kernel's libm)
    bparams [n, P] per-robot behaviour parameters;  pparams [Q] payment parameters
    record: bool, whether to log events;  hist_every: int, wealth-history interval (0 = off)
    grid_cell: float cell side of the neighbour grid (>= comm_range);  grid_nx, grid_ny: int cells
    sites_xy [S, 2], sites_r [S], sites_kind [S] (FOOD / NEST): every site, in file order, food first
        (site_pos / site_r hold the first site of each kind, all the paper's plane needs)
    obs_kind [K], obs_geom [K, 4]: obstacles (engine.obstacles);  line_of_sight, collisions, sense_robots: bool

ROBOTS:
    clock [1] int64 the last completed step (the first step is 1)
    pos [n, 2] true positions;  hdir [n, 2] unit vector of the true heading (no angle is kept: the
        hot loop needs no trigonometry for it; ``headings(world)`` gives degrees)
    bias [n] odometry bias mu_i (degrees per step);  kind [n] behaviour index;  levy [n] steps left
    state [n] EXPLORING / SEEKING_FOOD / SEEKING_NEST;  carrying [n] bool
    tab_vec [n, 2, 2], tab_age [n, 2], tab_valid [n, 2]: navigation table (robot frame) as it was at
        the start of the step (what sellers sell)
    new_vec, new_age, new_valid: the table being bought into during the communication phase
    off_vec [n, 2, 2], off_age [n, 2], off_valid [n, 2]: this step's offers (seller frame)
    pend_vec [n, 2, kp, 2], pend_age [n, 2, kp], pend_seller [n, 2, kp], pend_count [n, 2]: pending
        (unconfirmed) purchases, per site, in the robot's frame, aged like table entries
    spot [n, 2, 2], has_spot [n, 2]: pick-up / drop spot per site
    last_site [n] (-1 none);  items [n] items counted after the transitory period
    stop_timer [n], cool_timer [n]: communication stop and cooldown
    nbr [n, kn], nbr_count [n]: neighbours in increasing id order (a count above kn asks for room)
    cell_start [grid_nx * grid_ny + 1], cell_items [n]: the neighbour grid, rebuilt every step
    spot_site [n, 2]: which site (index into sites_*) each spot lies in
    blocked [n, 2] bool: the robot bumped into something while seeking that site (its straight line
        failed) and has not been at such a site since (set by the path-aware step, engine.paths; rules read it)
    path_vec [n, 2, PATH_POINTS - 1, 2], path_count [n, 2]: waypoint paths (engine.paths).  When
        path_count > 0 the table entry tab_vec is the first waypoint and path_vec[:path_count] the
        further ones, the last being the site, all positions in the robot's frame (start-of-step
        copy, what sellers sell);  new_path_vec, new_path_count: the path being bought into

LEDGER:
    balance [n], pot [n] stakes locked by the robot's open purchases, burned [1] fuel burned
    tx_off [n], tx_cap [n], tx_count [n]: buyer i's open transactions (since its last deposit) are
        pool entries tx_off[i] .. tx_off[i] + tx_count[i] - 1, in purchase order
    tx_seller [P], tx_site [P], tx_dir [P] float64 degrees, tx_step [P] step opened, tx_stake [P] stake
        locked: the transaction pool;
        pool_top [1] the first unused pool entry
    money [1] the sum of all balances, kept up to date by every ledger operation (so a rule reads a
        wealth share in O(1); equal to balance.sum() up to rounding)
    REPUTATION (``REPUTATION``, part of the ledger): what the ledger itself knows about each robot, updated
        when its transactions settle; rules read it through ``behaviours.market``, never write it.
        rep_settled [n] transactions it sold that were settled by a deposit;  rep_reduced [n] of those,
        the ones weighed 0 or below half the largest weight of the same site in their settlement (outliers);
        rep_earned [n] money it was paid for them;  rep_stake_lost [n] stake it locked in them and did
        not get back (stake minus payment, when positive);  rep_deposits [n] deposits it made as buyer

LOG:
    ev_* [E] and ev_count [1]: event log (purchase / refused / deposit) when ``record``; ev_sx, ev_sy are
        the seller's position in the buyer's frame (what the on-chain light contract signs)
    pay_step, pay_buyer, pay_seller, pay_site [Q] int64, pay_weight, pay_amount [Q] float64 and
        pay_count [1]: the payments log when ``record``, one row per settled transaction: at the buyer's
        deposit, the seller's normalised weight and the amount it received (0 when weighted out)
    hist [m, n] wealth every ``hist_every`` steps;  flags [1] error bits (engine.flags)
    site_items [S]: items picked up at each food site and deposited at each nest (after the transitory
        period; counted by the terrain-aware step only)
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np

PARAMS = (
    "width", "height", "radius", "speed", "comm_range", "noise_sd", "site_pos", "site_r",
    "reward", "info_share", "stake", "stake_expiry", "fuel_cost", "transitory", "stop_time", "cooldown",
    "cauchy_cdf", "cauchy_guide", "levy_cdf", "levy_guide", "turn_cos", "turn_sin",
    "bparams", "pparams", "record", "hist_every", "grid_cell", "grid_nx", "grid_ny",
    # terrain (engine.terrain; only the terrain-aware step reads these)
    "sites_xy", "sites_r", "sites_kind", "obs_kind", "obs_geom", "line_of_sight", "collisions",
    "sense_robots",
)
ROBOTS = (
    "clock", "pos", "hdir", "bias", "kind", "state", "carrying", "levy",
    "tab_vec", "tab_age", "tab_valid", "new_vec", "new_age", "new_valid",
    "off_vec", "off_age", "off_valid",
    "pend_vec", "pend_age", "pend_seller", "pend_count",
    "spot", "has_spot", "last_site", "items", "stop_timer", "cool_timer",
    "nbr", "nbr_count", "cell_start", "cell_items",
    "spot_site",
    # waypoint paths (engine.paths; only the path-aware step moves them)
    "blocked", "path_vec", "path_count", "new_path_vec", "new_path_count",
)
#: The fields of one transaction in the pool (moved together when a block moves or is compacted).
TX_POOL = ("tx_seller", "tx_site", "tx_dir", "tx_step", "tx_stake")
#: The ledger's reputation record of every robot (read by rules through ``behaviours.market``).
REPUTATION = ("money", "rep_settled", "rep_reduced", "rep_earned", "rep_stake_lost", "rep_deposits")
LEDGER = ("balance", "pot", "burned", "tx_off", "tx_cap", "tx_count", *TX_POOL, "pool_top", *REPUTATION)
LOG = (
    "ev_step", "ev_kind", "ev_buyer", "ev_seller", "ev_site", "ev_dir", "ev_x", "ev_y", "ev_age",
    "ev_stake", "ev_sx", "ev_sy", "ev_count",
    "pay_step", "pay_buyer", "pay_seller", "pay_site", "pay_weight", "pay_amount", "pay_count",
    "hist", "flags",
    "site_items",
)
#: Everything but the parameters changes during a run.
STATE = ROBOTS + LEDGER + LOG

World = namedtuple("World", PARAMS + STATE)

#: Most points a waypoint path holds, the first one (the table entry itself) included.
PATH_POINTS = 4

# Robot states.
EXPLORING = 0
SEEKING_FOOD = 1
SEEKING_NEST = 2
STATE_NAMES = ("exploring", "seeking_food", "seeking_nest")

# Sites.
FOOD = 0
NEST = 1
SITE_NAMES = ("food", "nest")

# Event kinds in the event log.
EV_PURCHASE = 0
EV_REFUSED = 1
EV_DEPOSIT = 2
EVENT_NAMES = ("purchase", "refused", "deposit")


def headings(world: World) -> np.ndarray:
    """Each robot's true heading in degrees, [0, 360) (the state keeps only its unit vector)."""
    return np.degrees(np.arctan2(world.hdir[:, 1], world.hdir[:, 0])) % 360.0


def open_transactions(world: World, buyer: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Buyer's open transactions (sellers, sites, directions in degrees), oldest first (copies)."""
    a = int(world.tx_off[buyer])
    b = a + int(world.tx_count[buyer])
    return world.tx_seller[a:b].copy(), world.tx_site[a:b].copy(), world.tx_dir[a:b].copy()
