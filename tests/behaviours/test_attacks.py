"""The attack family (behaviours/attacks.py) and reputation-weighted averaging do what they say.

As in test_reputation_rules.py, a rule is compared with a built-in it must equal at some parameters
(same seed, same numbers), so a broken gate shows as a difference; the gates that no built-in has are
checked by calling the compiled sell rule on a running world and comparing with what a hand count of
its neighbours says it must offer.
"""
import math

import numpy as np
import pytest

import infomarket as im
from infomarket.engine.geometry import rotate
from infomarket.registry import get_behaviour

from ..shared_kernel import simulate, simulation  # the kernel the rule checks compile


def _cfg(behaviour, params=None, steps=3000, scheme="outlier", stake=0.04, byz=5):
    return im.Experiment.model_validate({
        "steps": steps, "transitory": 0,
        "swarm": {"robots": 25, "groups": [{"behaviour": "naive", "count": 25 - byz},
                                           {"behaviour": behaviour, "count": byz, "params": params or {}}]},
        "payment": {"scheme": scheme, "stake": stake}})


def _same(a, b):
    return (np.array_equal(a.robots.items_collected, b.robots.items_collected)
            and np.array_equal(a.robots.wealth, b.robots.wealth))


def _run(behaviour, params=None, seed=5, **kw):
    return simulate(_cfg(behaviour, params, **kw), seed)


def test_the_attackers_defaults_are_a_20_degree_scaboteur():
    assert _same(_run("attacker"), _run("scaboteur", {"rotation_angle": 20.0}))
    assert not _same(_run("attacker", {"rot_base": 40.0}), _run("scaboteur", {"rotation_angle": 20.0}))


def test_an_attacker_whose_reputation_gate_never_opens_is_an_honest_sceptic():
    # Laplace's reputation (settled - reduced + 1) / (settled + 2) is below 1 for every record
    assert _same(_run("attacker", {"rot_base": 90.0, "lie_from_rep": 1.0}), _run("sceptical"))
    assert not _same(_run("attacker", {"rot_base": 90.0, "lie_from_rep": 0.0}), _run("sceptical"))


@pytest.mark.parametrize("name, params, preset", [
    ("colluder", {"rotation_angle": 30.0}, {"rot_base": 30.0, "collude": 1.0}),
    ("newcomer", {"rotation_angle": 30.0, "fresh_record": 4.0}, {"rot_base": 30.0, "fresh_record": 4.0}),
    ("selective_liar", {"rotation_angle": 30.0, "max_confirmers": 0.0}, {"rot_base": 30.0, "max_confirmers": 0.0}),
    ("sceptic_surfer", {"rotation_angle": 90.0, "margin": 0.9},
     {"rot_base": 90.0, "cap_theta": 0.9, "cap_sceptic": 0.9}),
    ("tuned_farmer", {"rotation_angle": 90.0, "farm_reputation": 0.6, "farm_record": 3.0},
     {"rot_base": 90.0, "lie_from_rep": 0.6, "lie_min_record": 3.0}),
])
def test_each_named_threat_is_the_attacker_preset_the_study_compares_with(name, params, preset):
    assert _same(_run(name, params), _run("attacker", preset))


def test_the_sceptic_surfer_lies_by_the_largest_angle_a_sceptic_accepts():
    # diff = |a - rot(a)| / |a| = 2 sin(angle / 2) < 0.25  <=>  angle < 2 asin(0.125) = 14.36 degrees
    accepted = 2.0 * math.degrees(math.asin(0.125))
    surfer = _run("sceptic_surfer", {"rotation_angle": 90.0, "margin": 1.0, "threshold": 0.25, "theta": 30.0})
    assert _same(surfer, _run("scaboteur", {"rotation_angle": accepted}))


def test_the_tuned_farmer_targets_the_trust_the_reputation_sceptic_gives():
    farmer, sceptic = get_behaviour("tuned_farmer").defaults, get_behaviour("reputation_sceptic").defaults
    assert farmer["farm_reputation"] == sceptic["trust_reputation"] == 0.85
    assert farmer["farm_record"] == sceptic["min_record"] == 10.0


def _offers(name, params, steps=1500, seed=3, every=7):
    """(world, robot, site, offer, own entry) for every Byzantine robot and site every ``every`` steps,
    the offer from the compiled sell rule called on the running world."""
    spec = get_behaviour(name)
    sim = simulation(_cfg(name, params, steps=steps), seed)
    kind = sim.kinds.index(name)
    args = [float(dict(spec.defaults, **params)[p]) for p in spec.sell.params]
    for _ in range(steps // every):
        sim.step(every)
        w = sim.world
        for me in np.flatnonzero(w.kind == kind):
            for site in (0, 1):
                offer = spec.sell.func(sim._view, int(me), site, *args)
                own = (bool(w.tab_valid[me, site]), float(w.tab_vec[me, site, 0]), float(w.tab_vec[me, site, 1]),
                       int(w.tab_age[me, site]))
                yield w, int(me), site, offer, own


def test_the_selective_liar_lies_only_with_no_other_seller_in_range():
    lied = truthful = 0
    for w, me, site, offer, own in _offers("selective_liar", {"rotation_angle": 30.0, "max_confirmers": 0.0}):
        if not own[0]:
            continue
        others = sum(bool(w.tab_valid[j, site]) for j in w.nbr[me, :w.nbr_count[me]])
        want = own[1:3] if others else rotate(own[1], own[2], 30.0)
        assert np.allclose(offer[1:3], want, rtol=0, atol=1e-12), (me, site, others)
        lied += others == 0
        truthful += others > 0
    assert lied > 0 and truthful > 0  # both branches were exercised


def test_the_newcomer_withdraws_once_its_record_is_spent():
    spent = fresh = 0
    for w, me, _site, offer, own in _offers("newcomer", {"rotation_angle": 30.0, "fresh_record": 3.0}, steps=4000):
        if w.rep_settled[me] >= 3:
            assert not offer[0]
            spent += 1
        elif own[0]:
            assert np.allclose(offer[1:3], rotate(own[1], own[2], 30.0), rtol=0, atol=1e-12)
            fresh += 1
    assert spent > 0 and fresh > 0


def _buy_from_partner(name, params):
    """Robot a (Byzantine) offered partner b's offers for both sites, older than a's own entries (no
    sceptic or naive robot would buy them): a's open transactions after its buy rule, before and after,
    and whether a's new table changed."""
    spec = get_behaviour(name)
    sim = simulation(_cfg(name, params, steps=500), 4)
    sim.step(300)
    w = sim.world
    a, b = np.flatnonzero(w.kind == sim.kinds.index(name))[:2]
    for site in (0, 1):
        w.off_valid[b, site] = True
        w.off_vec[b, site] = (50.0, 20.0)
        w.off_age[b, site] = int(w.new_age[a, site]) + 10
    w.cool_timer[[a, b]] = 0
    before, table = int(w.tx_count[a]), w.new_vec[a].copy()
    args = [float(dict(spec.defaults, **params)[p]) for p in spec.buy.params]
    spec.buy.func(sim._view, int(a), np.array([b], np.int64), *args)
    once = int(w.tx_count[a])
    spec.buy.func(sim._view, int(a), np.array([b], np.int64), *args)  # the same round trip: not again
    return before, once, int(w.tx_count[a]), np.array_equal(w.new_vec[a], table)


def test_colluders_buy_each_partners_offer_once_per_round_trip_without_using_it():
    before, once, twice, unchanged = _buy_from_partner("colluder", {"rotation_angle": 20.0})
    assert (once - before, twice - once, unchanged) == (2, 0, True)
    before, once, twice, unchanged = _buy_from_partner("attacker", {"rot_base": 20.0})  # no collusion
    assert (once - before, twice - once, unchanged) == (0, 0, True)


def test_colluders_share_one_rotation_whatever_their_records():
    base = {"rot_base": 30.0, "collude": 1.0}
    assert _same(_run("attacker", {**base, "rot_rep": 90.0, "rot_buyer_rep": 90.0}), _run("attacker", base))
    assert not _same(_run("attacker", {"rot_base": 30.0, "rot_rep": 90.0}), _run("attacker", {"rot_base": 30.0}))


def test_reputation_weighted_averaging_with_power_zero_is_naive():
    assert _same(_run("reputation_weighted", {"power": 0.0}, byz=5), _run("naive", byz=5))
    assert not _same(_run("reputation_weighted", {"power": 2.0}, byz=5), _run("naive", byz=5))
