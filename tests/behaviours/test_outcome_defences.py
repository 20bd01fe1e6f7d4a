"""The outcome, fusion and vote defences (``outcome_trust``, ``gated_fusion``, ``vote_k``) on a world, by hand.

Buyer and sellers stand on one spot facing the same way, so a bought vector is the offered one (no
rotation, no offset) and every expected entry is computed by hand from the offers.
"""
import math

import numpy as np
import pytest

from infomarket.behaviours import fusion, outcome
from infomarket.behaviours.api import pending_add, trust_add, trust_get, trust_record
from infomarket.engine.swarm import TRUST_SLOTS
from infomarket.engine.world import FOOD, open_transactions
from infomarket.errors import ConfigError
from infomarket.registry import get_behaviour

from ..conftest import Handle, make_config


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
    return tuple(w.new_vec[0, FOOD]), int(w.new_age[0, FOOD]), bool(w.new_valid[0, FOOD]), held


def _sellers(h):
    return [int(s) for s in open_transactions(h.world, 0)[0]]


# --- outcome_trust -------------------------------------------------------------------------------------------

def test_the_beta_mean():
    assert outcome.beta_mean(0.0, 0.0, 1.0) == 0.5  # a seller never judged
    assert outcome.beta_mean(3.0, 1.0, 1.0) == pytest.approx(4 / 6)  # (3 + 1) / (3 + 1 + 2)
    assert outcome.beta_mean(0.0, 4.0, 0.5) == pytest.approx(0.5 / 5)  # (0 + .5) / (0 + 4 + 1)


@pytest.mark.parametrize("own, good, bad", [(None, 0.0, 1.0), ((3.0, 4.0, 1), 1.0, 0.0), ((3.0, 4.0, 5), 0.0, 0.0)])
def test_a_trip_judges_every_seller_used_since_the_last_outcome(own, good, bad):
    # users 1 and 2 on record for food, the last with the entry's age 5 (its purchase installed it).  An
    # invalid entry: the trip failed (one bad each); a valid entry aged 1 < 5: the site sensed since (one
    # good each); a valid entry still aged 5: no outcome yet, the users kept.
    h = _market(3, own=own)
    for s, age in ((1, 9), (2, 5)):
        pending_add(h.view, 0, FOOD, s, 1.0, 1.0, age)
    judged = outcome.settle_outcome(h.view, 0, FOOD)
    assert judged == (0 if good == bad == 0.0 else 2)
    for s in (1, 2):
        assert trust_get(h.view, 0, s) == (good, bad)
    assert h.world.pend_count[0, FOOD] == (2 if judged == 0 else 0)


def test_a_distrusted_seller_is_skipped_for_an_older_offer():
    # seller 1 (the freshest, age 5) has 0 good and 3 bad trips: Beta mean (0 + 1) / (3 + 2) = 0.2 < 0.3.
    # Seller 2 (age 6) is never judged: 0.5.  The invalid entry takes seller 2's (0, 10), aged (1000 + 6) // 2.
    h = _market(3, offers=[(1, 10.0, 0.0, 5), (2, 0.0, 10.0, 6)])
    trust_add(h.view, 0, 1, 0.0, 3.0)
    vec, age, valid, held = _buy(h, "outcome_trust", 1.0, 0.3, 1.0, 8.0)
    assert vec == (0.0, 10.0) and age == 503 and valid and held == [2] and _sellers(h) == [2]
    assert h.world.pend_age[0, FOOD, 0] == 503  # the user is recorded with the age of the entry it installed


@pytest.mark.parametrize("power, x", [(0.0, 1000.0 / 19.0), (1.0, 500.0 / 11.0)])
def test_a_purchase_weighs_its_age_weight_times_the_beta_mean(power, x):
    # own (0, 0) age 10, offer (100, 0) age 9: age weights 10/19 (bought) and 9/19 (own).  Seller record
    # 2 good, 0 bad: mean 3/4.  Power 0: k = 10/19 -> 1000/19 (the naive robot's eqs. 4-5).  Power 1:
    # k = (10/19 * 3/4) / (10/19 * 3/4 + 9/19) = 7.5 / 16.5 = 5/11 -> 500/11.  Age (10 + 9) // 2 = 9.
    h = _market(2, own=(0.0, 0.0, 10), offers=[(1, 100.0, 0.0, 9)])
    trust_add(h.view, 0, 1, 2.0, 0.0)
    vec, age, _, held = _buy(h, "outcome_trust", 1.0, 0.3, power, 8.0)
    assert vec == pytest.approx((x, 0.0), abs=1e-12) and age == 9 and held == [1]


def test_failures_are_due_until_the_round_trip_is_settled():
    # two failures and a success on seller 1: 2 due.  While robot 0 has an open transaction its buy rule
    # keeps them due; once it has none (its round trip settled) it clears them, the record stays.
    from infomarket.jit import njit

    @njit
    def record(w, me, seller):  # trust_record is for compiled rules: it reads a world's type
        return trust_record(w, me, seller)

    h = _market(2)
    trust_add(h.view, 0, 1, 0.0, 2.0)
    trust_add(h.view, 0, 1, 1.0, 0.0)
    assert record(h.view, 0, 1) == (1.0, 2.0, 2.0) and record(h.view, 0, 5) == (0.0, 0.0, 0.0)
    h.world.tx_count[0] = 1
    _buy(h, "outcome_trust", 1.0, 0.3, 1.0, 8.0, 0.0)
    assert record(h.view, 0, 1) == (1.0, 2.0, 2.0)
    h.world.tx_count[0] = 0
    _buy(h, "outcome_trust", 1.0, 0.3, 1.0, 8.0, 0.0)
    assert record(h.view, 0, 1) == (1.0, 2.0, 0.0)


def test_the_record_forgets_the_least_judged_seller_when_full():
    h = _market(2)
    v = h.view
    for s in range(TRUST_SLOTS):  # sellers 100.. with 2 outcomes each, except seller 105 with 1
        trust_add(v, 0, 100 + s, 1.0, 0.0 if s == 5 else 1.0)
    trust_add(v, 0, 100, 1.0, 0.0)  # a known seller accumulates in place
    assert trust_get(v, 0, 100) == (2.0, 1.0)
    trust_add(v, 0, 7, 0.0, 1.0)  # a new one evicts seller 105, the least judged
    assert trust_get(v, 0, 105) == (0.0, 0.0) and trust_get(v, 0, 7) == (0.0, 1.0)
    assert h.world.trust_seller[0, 5] == 7


# --- gated_fusion --------------------------------------------------------------------------------------------

def test_the_variance_of_a_vector_grows_with_its_age_and_length():
    # |(300, 400)| = 500; 10 steps at 0.1 degrees: an arc of 500 * 1 degree = 500 pi / 180 = 8.72665
    assert fusion.age_variance(300.0, 400.0, 10, 0.1, 10.0) == pytest.approx(100.0 + 8.726646259971648 ** 2)
    assert fusion.age_variance(300.0, 400.0, 0, 0.1, 10.0) == 100.0


@pytest.mark.parametrize("offer, accepted, fused", [(30.0, True, 15.0), (31.0, False, 0.0)])
def test_the_gate(offer, accepted, fused):
    # both variances 100: d2 = 2 d^2 / 200 = d^2 / 100: 9.0 passes the gate 9.21, 9.61 does not; K = 1/2
    ok, fx, fy, _ = fusion.gate_and_fuse(0.0, 0.0, 100.0, offer, 0.0, 100.0, 9.21)
    assert ok == accepted and (fx, fy) == (fused, 0.0)


def test_gated_fusion_rejects_the_far_offer_and_fuses_the_near_one():
    # drift 0, floor 10: every variance is 100.  Own (0, 0) age 10.  Seller 1 (40, 0) age 2: d2 = 16,
    # rejected (but bought).  Seller 2 (20, 0) age 3: d2 = 4, fused with K = 1/2 -> (10, 0), age
    # floor(10 / 2 + 3 / 2) = 6.
    h = _market(3, own=(0.0, 0.0, 10), offers=[(1, 40.0, 0.0, 2), (2, 20.0, 0.0, 3)])
    vec, age, _, _ = _buy(h, "gated_fusion", 0.0, 10.0, 9.21)
    assert vec == (10.0, 0.0) and age == 6 and _sellers(h) == [1, 2]


def test_gated_fusion_trusts_the_younger_vector_more():
    # own (100, 0) age 100 at 0.1 degrees per step: arc 100 * 10 degrees = 1000 pi / 180; variance
    # 100 + arc^2.  Offer (110, 0) age 0: variance 100.  K = p_own / (p_own + 100); age floor((1 - K) * 100).
    arc = 1000.0 * math.pi / 180.0
    p_own = 100.0 + arc * arc
    k = p_own / (p_own + 100.0)
    h = _market(2, own=(100.0, 0.0, 100), offers=[(1, 110.0, 0.0, 0)])
    vec, age, _, _ = _buy(h, "gated_fusion", 0.1, 10.0, 9.21)
    assert vec == pytest.approx((100.0 + 10.0 * k, 0.0)) and age == math.floor((1.0 - k) * 100.0)
    assert k == pytest.approx(0.8018, abs=1e-4)


def test_gated_fusion_with_no_entry_takes_the_first_offer():
    h = _market(3, offers=[(1, 40.0, 0.0, 2), (2, 20.0, 0.0, 3)])
    vec, age, valid, _ = _buy(h, "gated_fusion", 0.1, 10.0, 9.21)
    assert vec == (40.0, 0.0) and age == 2 and valid and _sellers(h) == [1]


# --- vote_k --------------------------------------------------------------------------------------------------

def test_vote_k_waits_for_k_sellers():
    # k = 3, no entry, two offers: both bought and held, nothing installed
    h = _market(4, offers=[(1, 100.0, 0.0, 5), (2, 0.0, 100.0, 6)])
    vec, _, valid, held = _buy(h, "vote_k", 3.0, 0.0, 30.0, 200.0, 0.25)
    assert not valid and held == [1, 2] and _sellers(h) == [1, 2]
    # a third seller appears: the coordinate-wise median of (100, 0), (0, 100), (90, 10) is (90, 10), aged
    # the lower median of 5, 6, 7; the held sellers are not bought again, the votes are forgotten
    h.offer(3, FOOD, 90.0, 10.0, 7)
    vec, age, valid, held = _buy(h, "vote_k", 3.0, 0.0, 30.0, 200.0, 0.25)
    assert vec == (90.0, 10.0) and age == 6 and valid and held == [] and _sellers(h) == [1, 2, 3]


def test_vote_k_geometric_median_of_a_cross_is_its_centre():
    h = _market(5, offers=[(1, 10.0, 0.0, 5), (2, -10.0, 0.0, 5), (3, 0.0, 10.0, 5), (4, 0.0, -10.0, 5)])
    vec, age, valid, _ = _buy(h, "vote_k", 4.0, 1.0, 30.0, 200.0, 0.25)
    assert vec == pytest.approx((0.0, 0.0), abs=1e-12) and age == 5 and valid


def test_vote_k_of_one_takes_the_first_offer():
    h = _market(3, offers=[(1, 40.0, 0.0, 2), (2, 20.0, 0.0, 3)])
    vec, age, valid, _ = _buy(h, "vote_k", 1.0, 1.0, 30.0, 200.0, 0.25)
    assert vec == (40.0, 0.0) and age == 2 and valid and _sellers(h) == [1]


def test_vote_k_with_an_entry_is_the_sceptic():
    # own (100, 0) age 50; offer (0, 100) age 5: diff |(100, -100)| / 100 = 1.41 > 0.25, kept pending
    h = _market(2, own=(100.0, 0.0, 50), offers=[(1, 0.0, 100.0, 5)])
    vec, age, valid, held = _buy(h, "vote_k", 3.0, 1.0, 30.0, 200.0, 0.25)
    assert vec == (100.0, 0.0) and age == 50 and held == [1]


def test_vote_k_drops_votes_older_than_the_horizon():
    h = _market(3)
    for s, age in ((1, 10), (2, 300)):
        pending_add(h.view, 0, FOOD, s, 1.0, 1.0, age)
    assert _buy(h, "vote_k", 3.0, 1.0, 30.0, 300.0, 0.25)[3] == [1, 2]  # 300 is not older than 300
    assert _buy(h, "vote_k", 3.0, 1.0, 30.0, 299.0, 0.25)[3] == [1]


# --- configuration -------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name, params, text", [
    ("outcome_trust", {"distrust": 1.5}, "in [0, 1]"), ("outcome_trust", {"prior": 0}, "> 0"),
    ("outcome_trust", {"provenance": 0.5}, "0 or 1"),
    ("gated_fusion", {"floor": 0}, "> 0"), ("gated_fusion", {"drift": -1}, ">= 0"),
    ("vote_k", {"k": 0}, ">= 1 and <= 32"), ("vote_k", {"geometric": 0.5}, "0 or 1")])
def test_bad_parameters_are_refused_by_name(name, params, text):
    with pytest.raises(ConfigError) as e:
        make_config(3, name, swarm={"robots": 3, "groups": [{"behaviour": name, "count": 3, "params": params}]})
    assert text in str(e.value) and list(params)[0] in str(e.value)


def test_in_a_run_outcome_trust_blames_liars_more_than_honest_sellers():
    """A run on the shared kernel: every record is of a seller the robot bought from, and the 90-degree
    saboteurs' judged trips fail more often than the honest sellers' (docs/defences.md measures how much)."""
    from infomarket import Experiment

    from ..shared_kernel import simulation

    groups = [{"behaviour": "outcome_trust", "count": 22}, {"behaviour": "saboteur", "count": 3}]
    cfg = Experiment.model_validate({"steps": 6000, "swarm": {"robots": 25, "groups": groups},
                                     "payment": {"scheme": "outlier"}})
    sim = simulation(cfg, 0, record_events=True)
    sim.run()
    w = sim.world
    bought = set(zip(w.ev_buyer[:w.ev_count[0]], w.ev_seller[:w.ev_count[0]]))
    tally = {True: [0.0, 0.0], False: [0.0, 0.0]}  # liar? -> good, bad
    for buyer in range(22):
        for j in range(TRUST_SLOTS):
            s = int(w.trust_seller[buyer, j])
            if s >= 0:
                assert (buyer, s) in bought
                tally[s >= 22][0] += w.trust_good[buyer, j]
                tally[s >= 22][1] += w.trust_bad[buyer, j]
    honest, liar = (t[1] / (t[0] + t[1]) for t in (tally[False], tally[True]))
    assert sum(tally[True]) > 0 and liar > honest
