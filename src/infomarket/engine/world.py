"""The world: every piece of simulation state as arrays (struct of arrays), in one named tuple.

One ``World`` is what every compiled function receives (``w``).  Rules read it and write the few
arrays that are theirs to write (the buyer's new table, the pending lists).  Shapes use ``n`` for the
number of robots, ``2`` sites (0 = food, 1 = nest), ``cap`` for the transaction capacity per buyer and
``ecap`` for the event-log capacity (both grown by the host between steps, see ``engine.simulation``).

Parameters (scalars and lookup tables, never written):
    width, height, radius, speed, comm_range, noise_sd: float
    site_pos: [2, 2] float64 site centres;  site_r: [2] float64 site radii
    reward, info_share, stake, fuel_cost: float;  transitory, stop_time, cooldown: int
    cauchy_cdf: [360] float64 turn-angle CDF (whole degrees);  levy_cdf: [steps + 1] float64 step-length CDF
    cauchy_guide, levy_guide: int64 guide tables that make sampling those CDFs O(1) (build.guide_table)
    bparams: [n, P] float64 per-robot behaviour parameters;  pparams: [Q] float64 payment parameters
    record: bool, whether to log events;  hist_every: int, wealth-history interval (0 = off)

State:
    clock: [1] int64, the last completed step (the first step is 1)
    pos: [n, 2] float64 true positions;  heading: [n] float64 true heading, degrees
    hdir: [n, 2] float64 unit vector of the heading (kept so the hot loop needs no trigonometry)
    bias: [n] float64 odometry bias mu_i (degrees per step);  kind: [n] int64 behaviour index
    state: [n] int64 EXPLORING / SEEKING_FOOD / SEEKING_NEST;  carrying: [n] bool;  levy: [n] int64
    tab_vec [n, 2, 2], tab_age [n, 2] int64, tab_valid [n, 2] bool: navigation table (robot frame),
        as it was at the start of the step (what sellers sell)
    new_vec, new_age, new_valid: the table being bought into during the communication phase
    off_vec [n, 2, 2], off_age [n, 2], off_valid [n, 2]: this step's offers (seller frame)
    pend_vec [n, 2, n, 2], pend_age [n, 2, n], pend_seller [n, 2, n], pend_count [n, 2]: pending
        (unconfirmed) purchases, per site, in the robot's frame, aged like table entries
    spot [n, 2, 2], has_spot [n, 2]: pick-up / drop spot per site
    last_site [n] int64 (-1 none);  items [n] int64 items counted after the transitory period
    balance [n] float64, pot [n] float64 stakes locked by the robot's open purchases, burned [1] float64
    tx_seller [n, cap] int64, tx_site [n, cap] int64, tx_dir [n, cap] float64, tx_count [n] int64:
        each buyer's transactions since its last deposit
    nbr [n, n] int64, nbr_count [n] int64: neighbours, increasing id order
    stop_timer [n], cool_timer [n] int64: communication stop and cooldown
    ev_* [ecap] and ev_count [1]: event log (purchase / refused / deposit), when ``record``; ev_sx, ev_sy
        are the seller's position in the buyer's frame (what the on-chain light contract signs)
    hist [m, n] float64: wealth every ``hist_every`` steps;  flags [1] int64: error bits (engine.flags)
"""
from __future__ import annotations

from collections import namedtuple

PARAM_FIELDS = (
    "width", "height", "radius", "speed", "comm_range", "noise_sd", "site_pos", "site_r",
    "reward", "info_share", "stake", "fuel_cost", "transitory", "stop_time", "cooldown",
    "cauchy_cdf", "cauchy_guide", "levy_cdf", "levy_guide", "bparams", "pparams", "record", "hist_every",
)
STATE_FIELDS = (
    "clock", "pos", "heading", "hdir", "bias", "kind", "state", "carrying", "levy",
    "tab_vec", "tab_age", "tab_valid", "new_vec", "new_age", "new_valid",
    "off_vec", "off_age", "off_valid",
    "pend_vec", "pend_age", "pend_seller", "pend_count",
    "spot", "has_spot", "last_site", "items", "balance", "pot", "burned",
    "tx_seller", "tx_site", "tx_dir", "tx_count",
    "nbr", "nbr_count", "stop_timer", "cool_timer",
    "ev_step", "ev_kind", "ev_buyer", "ev_seller", "ev_site", "ev_dir", "ev_x", "ev_y", "ev_age",
    "ev_stake", "ev_sx", "ev_sy", "ev_count", "hist", "flags",
)

World = namedtuple("World", PARAM_FIELDS + STATE_FIELDS)

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
