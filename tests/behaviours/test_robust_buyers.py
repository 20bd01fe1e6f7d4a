"""The robust buyers' rules on a world, by hand, and in a run among naive robots and saboteurs.

Buyer and sellers stand on one spot facing the same way, so a bought vector is the offered one (no
rotation, no offset) and every expected entry is computed by hand from the offers.
"""
from pathlib import Path

import numpy as np
import pytest

import infomarket as im
from infomarket import registry
from infomarket.behaviours import robust
from infomarket.engine.world import FOOD, open_transactions
from infomarket.registry import get_behaviour

from ..conftest import Handle, make_config
from ..shared_kernel import simulation


def _market(robots, own=None, offers=()):
    """Robots on one spot, facing +x; robot 0's food entry ``own`` = (x, y, age) or None (invalid, age 1000);
    ``offers``: (seller, x, y, age) for food."""
    h = Handle(make_config(robots))
    for i in range(robots):
        h.place(i, 100.0, 100.0, 0.0)
    w = h.world
    x, y, age = own if own else (0.0, 0.0, 1000)
    for pre in ("tab", "new"):  # the start-of-step entry and the one being bought into
        getattr(w, f"{pre}_vec")[0, FOOD] = (x, y)
        getattr(w, f"{pre}_age")[0, FOOD] = age
        getattr(w, f"{pre}_valid")[0, FOOD] = own is not None
    for s, ox, oy, oage in offers:
        h.offer(s, FOOD, ox, oy, oage)
    return h


def _buy(h, name, *params):
    nbrs = np.arange(1, h.world.pos.shape[0], dtype=np.int64)
    get_behaviour(name).buy.func(h.view, 0, nbrs, *params)
    w = h.world
    held = [int(s) for s in w.pend_seller[0, FOOD, :w.pend_count[0, FOOD]]]
    return tuple(w.new_vec[0, FOOD]), int(w.new_age[0, FOOD]), held


def test_median_buyer_with_one_rotated_liar_steers_by_the_median():
    # offers (100, 0) age 5, (90, 10) age 6 and (100, 0) rotated by 90 degrees, (0, 100) age 7; no own entry.
    # All three are younger than the own entry (1000): bought in age order, held, and the median of the
    # three is (90, 10) (x: 0, 90, 100; y: 0, 10, 100), aged 6 (the median of 5, 6, 7).
    h = _market(4, offers=[(1, 100.0, 0.0, 5), (2, 90.0, 10.0, 6), (3, 0.0, 100.0, 7)])
    vec, age, held = _buy(h, "robust_median", 3.0, 0.0)
    assert vec == (90.0, 10.0) and age == 6 and held == [1, 2, 3]
    assert list(open_transactions(h.world, 0)[0]) == [1, 2, 3]  # each purchase paid for as any purchase


def test_trimmed_buyer_counts_its_own_entry_and_trims_the_planted_liar():
    # own (50, 50) age 100 is one more voice; offers (40, 50), (60, 50), (50, 40) and a liar (50, 1000).
    # x: 40, 60, 50, 50, 50 -> trimmed 50; y: 50, 50, 40, 1000, 50 -> 40 and 1000 dropped -> 50.
    # Age: lower median of the purchases' 5, 6, 7, 8 -> 6.
    h = _market(5, own=(50.0, 50.0, 100),
                offers=[(1, 40.0, 50.0, 5), (2, 60.0, 50.0, 6), (3, 50.0, 40.0, 7), (4, 50.0, 1000.0, 8)])
    vec, age, held = _buy(h, "robust_trimmed", 4.0, 1.0, 0.0)
    assert vec == (50.0, 50.0) and age == 6 and held == [1, 2, 3, 4]


def test_geometric_buyer_takes_the_centre_of_a_symmetric_cross():
    # four purchases (+-10, 0), (0, +-10) about no own entry: the geometric median is the centre
    h = _market(5, offers=[(1, 10.0, 0.0, 5), (2, -10.0, 0.0, 5), (3, 0.0, 10.0, 5), (4, 0.0, -10.0, 5)])
    vec, age, held = _buy(h, "robust_geometric", 4.0, 30.0, 0.0)
    assert vec == pytest.approx((0.0, 0.0), abs=1e-12) and age == 5 and held == [1, 2, 3, 4]


@pytest.mark.parametrize("power, expected", [(0.0, (50.0, 50.0)), (1.0, (100.0, 0.0))])
def test_reputation_weights_the_voices(power, expected):
    # seller 1 (100, 0): 8 settled sales, none an outlier: reputation 9/10; seller 2 (0, 100): 8 of 8
    # outliers: 1/10.  Unweighted, the median of two voices is their mean; with power 1 the weights are
    # 0.9 and 0.1, so in each coordinate seller 1's value alone passes half the weight: (100, 0).
    h = _market(3, offers=[(1, 100.0, 0.0, 5), (2, 0.0, 100.0, 6)])
    w = h.world
    w.rep_settled[1:3] = 8
    w.rep_reduced[2] = 8
    vec, _, held = _buy(h, "robust_median", 3.0, power)
    assert vec == pytest.approx(expected, abs=1e-12) and held == [1, 2]


def test_the_memory_holds_one_purchase_per_seller_and_the_last_ones():
    h = _market(4)
    v = h.view
    for s in (1, 2, 1, 3):  # seller 1 again replaces its first purchase; then 3 pushes the oldest (2) out
        robust.remember(v, 0, FOOD, s, float(s), 0.0, 10, 2)
    w = h.world
    assert w.pend_count[0, FOOD] == 2 and list(w.pend_seller[0, FOOD, :2]) == [1, 3]


def test_a_seller_with_nothing_newer_is_not_bought_again():
    h = _market(2, own=(5.0, 5.0, 100), offers=[(1, 7.0, 7.0, 9)])
    robust.remember(h.view, 0, FOOD, 1, 7.0, 7.0, 9, 3)  # seller 1's age-9 vector already held
    _buy(h, "robust_median", 3.0, 0.0)
    assert len(open_transactions(h.world, 0)[0]) == 0
    h.offer(1, FOOD, 8.0, 8.0, 4)  # now it offers something younger: bought, and replaces the old one
    vec, age, held = _buy(h, "robust_median", 3.0, 0.0)
    assert len(open_transactions(h.world, 0)[0]) == 1 and held == [1]
    assert vec == (6.5, 6.5) and age == 4  # median of two voices: own (5, 5) and (8, 8)


@pytest.mark.parametrize("own_age, kept", [(3, 0), (20, 2)])
def test_an_entry_fresher_than_every_purchase_held_forgets_them(own_age, kept):
    # purchases held at ages 10 and 12; an own entry aged 3 is fresher than both (the robot sensed the
    # site since): they are forgotten.  An own entry aged 20 (their combination, aged) keeps them.
    h = _market(3, own=(1.0, 1.0, own_age))
    for s, age in ((1, 10), (2, 12)):
        robust.remember(h.view, 0, FOOD, s, 1.0, 1.0, age, 3)
    _buy(h, "robust_median", 3.0, 0.0)
    assert h.world.pend_count[0, FOOD] == kept


def test_a_purchase_older_than_the_horizon_is_forgotten():
    h = _market(3, own=(1.0, 1.0, 20))
    for s, age in ((1, 10), (2, 300)):
        robust.remember(h.view, 0, FOOD, s, 1.0, 1.0, age, 3)
    assert _buy(h, "robust_median", 3.0, 0.0, 300.0)[2] == [1, 2]  # 300 is not older than 300
    assert _buy(h, "robust_median", 3.0, 0.0, 299.0)[2] == [1]


def test_robust_buyers_run_among_naive_robots_and_saboteurs():
    """A run on the shared kernel: the memories hold at most `vectors` distinct sellers, each of whom the
    robot really bought from for that site, and the robust buyers forage."""
    groups = [{"behaviour": "naive", "count": 10}, {"behaviour": "saboteur", "count": 3},
              {"behaviour": "robust_median", "count": 4, "params": {"vectors": 3}},
              {"behaviour": "robust_trimmed", "count": 4, "params": {"vectors": 4, "trim": 1}},
              {"behaviour": "robust_geometric", "count": 4, "params": {"vectors": 3}}]
    cfg = im.Experiment.model_validate({"steps": 3000, "swarm": {"robots": 25, "groups": groups},
                                        "payment": {"scheme": "outlier", "stake": 0.04}})
    sim = simulation(cfg, 3, record_events=True)
    result = sim.run()
    w = sim.world
    bought = set(zip(w.ev_buyer[:w.ev_count[0]], w.ev_site[:w.ev_count[0]], w.ev_seller[:w.ev_count[0]]))
    robust_ids = range(13, 25)
    for i in robust_ids:
        cap = 4 if 17 <= i < 21 else 3
        for site in (0, 1):
            held = list(w.pend_seller[i, site, :w.pend_count[i, site]])
            assert len(held) <= cap and len(set(held)) == len(held)
            assert all((i, site, s) in bought for s in held)
    assert result.robots.items_collected[13:].sum() > 0
    assert max(w.pend_count[i, s] for i in robust_ids for s in (0, 1)) >= 2  # they do gather opinions


def test_the_defences_page_example_steers_by_the_median_of_its_memory(monkeypatch):
    text = (Path(__file__).parents[2] / "docs" / "defences.md").read_text()
    code = text.split("## Writing a new defence")[1].split("```python\n")[1].split("```")[0]
    check = 'checks.check_behaviour("median_of_memory")'
    assert check in code
    monkeypatch.setattr(registry, "_BEHAVIOURS", dict(registry._BEHAVIOURS))  # registered for this test only
    exec(compile(code.replace(check, ""), "docs/defences.md", "exec"), {})  # the full check compiles two kernels
    h = _market(4, offers=[(1, 100.0, 0.0, 5), (2, 90.0, 10.0, 6), (3, 0.0, 100.0, 7)])
    vec, age, held = _buy(h, "median_of_memory", 3.0)
    assert vec == (90.0, 10.0) and age == 7 and held == [1, 2, 3]  # the last purchase's age
