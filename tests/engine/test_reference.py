"""The compiled engine against the plain-Python reference step (tests/reference.py), step by step.

Both start from the same state and the same random Generator state; after every step the test compares
positions, headings, navigation tables, pending lists, states, Lévy counters, spots, items, balances,
pots and open transactions; the event logs (every event stamped with its step) are compared whole at
the end.  Floats are compared to 1e-9 (1e-7 for angles in degrees): the reference turns vectors with
cos/sin of angles, the engine with stored unit vectors, so the last bits differ.  After each comparison
the reference's floats are set to the engine's, so rounding differences cannot accumulate over the run
and any real difference shows in the step where it is made.  Discrete state must match exactly.

Checked to fail when the engine is broken: one sign flipped in ``engine.geometry.to_frame`` (step 1),
the age of eqs. 4-5 changed, or the weights of eqs. 4-5 swapped (``behaviours.api.weighted``).
"""
from __future__ import annotations

import copy

from infomarket.config import validate
from infomarket.engine.world import headings, open_transactions

from ..reference import Params, Reference, Robot
from ..shared_kernel import simulation

STEPS = 2500
TOL = 1e-9

#: 9 robots in a 300 x 200 arena with close sites: deposits within a few hundred steps, many trades,
#: a saboteur and a scaboteur whose vectors are rotated, sceptics with pending lists, and a small
#: initial wealth so that sellers run out of money for stakes and purchases are refused.
SETUP = {
    "name": "reference", "steps": STEPS, "transitory": 300,
    "arena": {"width": 300, "height": 200},
    "food": {"x": 60, "y": 100, "radius": 30}, "nest": {"x": 240, "y": 100, "radius": 30},
    "swarm": {"robots": 9, "groups": [
        {"behaviour": "naive", "count": 4},
        {"behaviour": "sceptical", "count": 3, "params": {"threshold": 0.25}},
        {"behaviour": "saboteur", "count": 1, "params": {"rotation_angle": 90.0}},
        {"behaviour": "scaboteur", "count": 1, "params": {"rotation_angle": 90.0, "threshold": 0.25}},
    ]},
    "payment": {"scheme": "outlier", "stake": 0.04, "initial_wealth": 0.1, "params": {"theta": 30.0}},
}


def start_reference(cfg, sim) -> Reference:
    """The reference world from the engine's start state (read once) and a copy of its Generator."""
    w = sim.world
    p = Params(width=cfg.arena.width, height=cfg.arena.height, radius=cfg.robot.radius, speed=cfg.robot.speed,
               comm_range=cfg.robot.communication_range, noise_sd=cfg.robot.noise_sd,
               sites=[(cfg.food.x, cfg.food.y, cfg.food.radius), (cfg.nest.x, cfg.nest.y, cfg.nest.radius)],
               reward=cfg.payment.reward, info_share=cfg.payment.information_share, stake=cfg.payment.stake,
               scheme=cfg.payment.scheme, theta=cfg.payment_params().get("theta", 0.0), transitory=cfg.transitory,
               rho=cfg.random_walk.rho, alpha=cfg.random_walk.alpha, steps=cfg.steps)
    robots = []
    for g in cfg.swarm.groups:
        for _ in range(g.count):
            i = len(robots)
            robots.append(Robot(pos=[float(w.pos[i, 0]), float(w.pos[i, 1])], heading=float(headings(w)[i]),
                                bias=float(w.bias[i]), behaviour=g.behaviour, params=dict(g.params),
                                balance=cfg.payment.initial_wealth))
    return Reference(p, robots, copy.deepcopy(sim.rng))


def close(a, b, tol: float = TOL) -> bool:
    return all(abs(x - y) <= tol for x, y in zip(a, b, strict=True))


def compare_and_resync(ref: Reference, w, step: int) -> None:
    """Assert the reference equals the engine's world; then copy the engine's floats into it."""
    pos, heading, balance, pot = w.pos.tolist(), headings(w).tolist(), w.balance.tolist(), w.pot.tolist()
    discrete = list(zip(w.state.tolist(), w.carrying.tolist(), w.levy.tolist(), w.last_site.tolist(),
                        w.items.tolist()))
    tab_vec, tab_age, tab_valid = w.tab_vec.tolist(), w.tab_age.tolist(), w.tab_valid.tolist()
    spot, has_spot, pend_count = w.spot.tolist(), w.has_spot.tolist(), w.pend_count.tolist()
    tx_count = w.tx_count.tolist()
    for i, r in enumerate(ref.robots):
        at = f"step {step}, robot {i}"
        assert close(r.pos, pos[i]), f"{at}: position {r.pos} != {pos[i]}"
        gap = abs(r.heading - heading[i]) % 360.0
        assert min(gap, 360.0 - gap) < TOL, f"{at}: heading {r.heading} != {heading[i]}"
        assert (r.state, r.carrying, r.levy, r.last_site, r.items) == discrete[i], \
            f"{at}: (state, carrying, levy, last site, items) {(r.state, r.carrying, r.levy, r.last_site, r.items)}" \
            f" != {discrete[i]}"
        assert close([r.balance, r.pot], [balance[i], pot[i]]), f"{at}: balance, pot {r.balance, r.pot}" \
            f" != {balance[i], pot[i]}"
        for site in range(2):
            e = r.table[site]
            assert (e.valid, e.age) == (tab_valid[i][site], tab_age[i][site]), f"{at} site {site}: validity, age"
            assert close(e.vec, tab_vec[i][site]), f"{at} site {site}: table {e.vec} != {tab_vec[i][site]}"
            e.vec = tab_vec[i][site]
            assert (r.spot[site] is not None) == has_spot[i][site], f"{at} site {site}: has a spot"
            if r.spot[site] is not None:
                assert close(r.spot[site], spot[i][site]), f"{at} site {site}: spot"
                r.spot[site] = spot[i][site]
            k = pend_count[i][site]
            pend = r.pending[site]
            assert [(p.seller, p.age) for p in pend] == list(zip(w.pend_seller[i, site, :k].tolist(),
                                                               w.pend_age[i, site, :k].tolist())), \
                f"{at} site {site}: pending (seller, age)"
            vecs = w.pend_vec[i, site, :k].tolist()
            for p, v in zip(pend, vecs):
                assert close(p.vec, v), f"{at} site {site}: pending vector {p.vec} != {v}"
                p.vec = v
        k = tx_count[i]
        theirs = list(zip(*(a.tolist() for a in open_transactions(w, i))))
        assert [t[:2] for t in r.transactions] == [t[:2] for t in theirs], f"{at}: open transactions"
        assert close([t[2] for t in r.transactions], [t[2] for t in theirs], 1e-7), f"{at}: directions"
        r.transactions = theirs
        r.pos, r.heading, r.balance, r.pot = pos[i], heading[i], balance[i], pot[i]


def compare_events(mine: list[tuple], theirs) -> None:
    """Every event of the run, in order, each stamped with its step."""
    cols = ["step", "kind", "buyer", "seller", "site", "direction_deg", "x", "y", "age", "stake",
            "seller_x", "seller_y"]
    rows = list(zip(*(theirs[c].astype(object if c == "kind" else None).tolist() for c in cols)))
    for a, b in zip(mine, rows):
        assert a[:5] + a[8:9] == b[:5] + b[8:9], f"event {a} != {b}"
        assert close(a[5:8] + a[9:], b[5:8] + b[9:], 1e-7), f"event {a} != {b}"
    assert len(mine) == len(rows), f"{len(mine)} events in the reference, {len(rows)} in the engine"


def compare_payments(mine: list[tuple], theirs) -> None:
    """Every payment of the run: who received what at which deposit, in settlement order."""
    cols = ["step", "buyer", "seller", "site", "weight", "amount"]
    rows = list(zip(*(theirs[c].tolist() for c in cols)))
    for a, b in zip(mine, rows):
        assert a[:4] == b[:4] and close(a[4:], b[4:]), f"payment {a} != {b}"
    assert len(mine) == len(rows), f"{len(mine)} payments in the reference, {len(rows)} in the engine"


def run_side_by_side(setup: dict, seed: int, steps: int) -> tuple[Reference, list[tuple]]:
    cfg = validate(setup)
    sim = simulation(cfg, seed, record_events=True)  # on the rule checks' kernel: nothing new to compile
    ref = start_reference(cfg, sim)
    all_events = []
    for step in range(1, steps + 1):
        sim.step(1)
        all_events += ref.step()
        compare_and_resync(ref, sim.world, step)
    result = sim.result()
    compare_events(all_events, result.events)
    compare_payments(ref.payments, result.payments)
    return ref, all_events


def test_engine_matches_the_reference_step_by_step():
    ref, events = run_side_by_side(SETUP, 11, STEPS)
    kinds = [e[1] for e in events]
    # the run exercised what the comparison is for
    assert kinds.count("deposit") >= 10 and kinds.count("purchase") >= 100 and kinds.count("refused") >= 10
    assert any(r.items for r in ref.robots)  # deposits after the transitory period
    byzantine = {7, 8}
    assert any(e[1] == "purchase" and e[3] in byzantine for e in events)
    assert sum(e[1] == "purchase" and e[2] in (4, 5, 6) for e in events) >= 20  # sceptics buy
    assert len(ref.payments) >= 50 and any(p[2] in byzantine for p in ref.payments)  # Byzantines get paid too


#: The other built-in behaviours and the delayed scheme without a stake.
OTHERS = {**SETUP, "transitory": 0, "swarm": {"robots": 9, "groups": [
    {"behaviour": "naive", "count": 3}, {"behaviour": "sceptical", "count": 3},
    {"behaviour": "greedy", "count": 2}, {"behaviour": "free_rider", "count": 1}]},
    "payment": {"scheme": "delayed", "initial_wealth": 1.0}}


def test_engine_matches_the_reference_with_greedy_free_riders_and_delayed_payment():
    _, events = run_side_by_side(OTHERS, 12, 1200)
    sold = [e for e in events if e[1] == "purchase"]
    assert sum(e[1] == "deposit" for e in events) >= 5
    assert sum(e[3] in (6, 7) for e in sold) >= 10 and not any(e[3] == 8 for e in sold)
    assert any(e[2] == 8 for e in sold)  # the free rider buys
