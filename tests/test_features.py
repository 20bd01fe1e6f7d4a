"""Features of the model that the paper's runs leave at zero or never use, each with a worked answer:
fuel and the burned account, communication stop and cooldown, the greedy and free-rider behaviours,
and the seller-position columns of the event log."""
import math

import numpy as np
import pytest

import infomarket as im
from infomarket.engine.world import FOOD, headings

from .shared_kernel import simulate

def config(groups, **top):
    data = {"steps": 100, "swarm": {"robots": sum(c for _, c in groups),
                                    "groups": [{"behaviour": b, "count": c} for b, c in groups]}}
    for k, v in top.items():
        data[k] = v
    return im.Experiment.model_validate(data)


def place(sim, i, x, y, heading):
    w = sim.world
    w.pos[i] = (x, y)
    w.hdir[i] = (math.cos(math.radians(heading)), math.sin(math.radians(heading)))


def test_fuel_is_burned_per_move_and_a_robot_that_cannot_pay_stands_still():
    # one robot, 1.0 to start, 0.3 per move: it pays for three moves (1.0 -> 0.1), then stands still
    cfg = config([("naive", 1)], robot={"fuel_cost": 0.3})
    sim = im.Simulation(cfg, seed=3)
    place(sim, 0, 600.0, 300.0, 0.0)  # far from both sites and walls: no sensing, no deposit
    trail = []
    for _ in range(8):
        sim.step(1)
        trail.append((sim.world.pos[0].copy(), float(sim.world.balance[0]), float(sim.result().totals["burned"])))
    assert [b for _, b, _ in trail] == pytest.approx([0.7, 0.4, 0.1] + [0.1] * 5)
    assert [b for _, _, b in trail] == pytest.approx([0.3, 0.6, 0.9] + [0.9] * 5)
    moved = [not np.array_equal(trail[k][0], trail[k - 1][0]) for k in range(1, 8)]
    assert moved == [True, True] + [False] * 5
    assert np.linalg.norm(trail[0][0] - [600.0, 300.0]) == pytest.approx(2.5)
    assert sim.world.tab_age[0].tolist() == [3, 3]  # an unpaid step does not age the table either


def test_communication_stop_and_cooldown():
    """stop_time 3, cooldown 4: a purchase at step 1 stops both robots in steps 1-3 (from the step of
    the purchase, see docs/model.md), and neither may trade before step 1 + 3 + 4 = 8."""
    cfg = config([("naive", 2)], robot={"stop_time": 3, "cooldown": 4}, steps=12)
    sim = im.Simulation(cfg, seed=1, record_events=True)
    w = sim.world
    place(sim, 0, 600.0, 300.0, 0.0)
    place(sim, 1, 610.0, 300.0, 0.0)
    w.tab_valid[1, FOOD], w.tab_age[1, FOOD] = True, 5  # robot 1 knows where food is, robot 0 does not
    w.tab_vec[1, FOOD] = (-410.0, 0.0)
    w.tab_age[0, FOOD] = 100
    start = w.pos.copy()
    positions = []
    for _ in range(12):
        sim.step(1)
        positions.append(w.pos.copy())
    ev = sim.result().events
    bought = ev[ev.kind == "purchase"]
    assert bought.step.tolist() == [1, 8]
    assert (bought.buyer == 0).all() and (bought.seller == 1).all() and (bought.site == FOOD).all()
    for k in range(3):  # steps 1-3: neither robot moves
        np.testing.assert_array_equal(positions[k], start)
    assert (np.linalg.norm(positions[3] - start, axis=1) > 2).all()  # step 4: both move again
    np.testing.assert_array_equal(positions[8], positions[7])  # step 8's purchase stops them again at once


def test_greedy_robot_sells_its_entry_claiming_age_one():
    cfg = config([("naive", 24), ("greedy", 1)], steps=3000)
    r = simulate(cfg, 4, record_events=True)  # on the rule checks' kernel
    sold = r.events[r.events.kind == "purchase"]
    greedy = sold[sold.seller == 24]
    assert len(greedy) >= 20 and (greedy.age == 1).all()
    assert sold[sold.seller != 24].age.median() > 1  # honest robots sell their real ages


def test_free_rider_buys_naively_and_never_sells():
    cfg = config([("naive", 24), ("free_rider", 1)], steps=3000)
    r = simulate(cfg, 4, record_events=True)  # on the rule checks' kernel
    ev = r.events
    assert not (ev.seller == 24).any()  # nobody ever buys from it (no refused purchase either)
    mine = ev[(ev.kind == "purchase") & (ev.buyer == 24)]
    assert len(mine) >= 5
    assert mine.groupby(["step", "site"]).size().max() == 1  # a naive buyer: one purchase per site and step


def test_event_columns_seller_x_y_are_the_sellers_position_in_the_buyers_frame():
    cfg = config([("naive", 10)], arena={"width": 300, "height": 200},
                 food={"x": 60, "y": 100, "radius": 30}, nest={"x": 240, "y": 100, "radius": 30}, steps=600)
    sim = im.Simulation(cfg, seed=5, record_events=True)
    checked = 0
    for step in range(1, 601):
        pos, heading = sim.world.pos.copy(), headings(sim.world)  # trades use start-of-step positions
        sim.step(1)
        ev = sim.result().events
        for e in ev[(ev.step == step) & (ev.kind != "deposit")].itertuples():
            dx, dy = pos[e.seller] - pos[e.buyer]
            a = math.radians(heading[e.buyer])  # into the buyer's frame: rotate by -heading
            want = (dx * math.cos(a) + dy * math.sin(a), -dx * math.sin(a) + dy * math.cos(a))
            assert (e.seller_x, e.seller_y) == pytest.approx(want, abs=1e-9)
            assert math.hypot(e.seller_x, e.seller_y) < cfg.robot.communication_range
            checked += 1
        if checked >= 40:
            break
    assert checked >= 40
