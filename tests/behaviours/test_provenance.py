"""Provenance of resold vectors: ``api.origin_of`` / ``api.origin_set`` and ``outcome_trust`` with
``provenance`` = 1, on a world, by hand.  As in test_outcome_defences.py, buyer and sellers stand on one
spot facing the same way, so a bought vector is the offered one."""
import numpy as np
import pytest

from infomarket.behaviours.api import origin_of, origin_set, trust_add
from infomarket.engine.world import FOOD

from .test_outcome_defences import _buy, _market, _sellers

#: outcome_trust's parameters: prior 1, distrust 0.3, power 1, memory 8, provenance 1.
PROVENANCE = (1.0, 0.3, 1.0, 8.0, 1.0)


def _recorded(h, seller, origin, age, step, now=10):
    """Seller ``seller``'s buy rule recorded at clock ``step`` that its food entry (installed aged ``age``)
    came from ``origin``; the clock is now ``now``."""
    h.world.origin[seller, FOOD] = (origin, age, step)
    h.world.clock[0] = now


@pytest.mark.parametrize("offered_age, step, expected", [
    (5, 9, 3),   # one step after the record, the entry still the recorded one (age 5, not yet aged): its origin
    (6, 9, 3),   # ... aged once
    (4, 9, 1),   # younger than it was installed: the seller sensed the site since, the vector is its own
    (10, 5, 3),  # five steps later, aged 5 (expected 10)
    (8, 5, 1),   # five steps later but aged 3: sensed since (two steps younger than expected, or more)
    (5, 10, 1),  # recorded this step: the record describes the entry bought into, not the one offered
])
def test_the_origin_of_an_offer(offered_age, step, expected):
    h = _market(4, offers=[(1, 10.0, 0.0, offered_age)])
    _recorded(h, 1, 3, 5, step)
    assert origin_of(h.view, 1, FOOD) == expected


def test_a_seller_that_records_nothing_is_its_offers_origin():
    h = _market(3, offers=[(1, 10.0, 0.0, 5)])
    assert origin_of(h.view, 1, FOOD) == 1
    origin_set(h.view, 2, FOOD, 0, 7)
    assert tuple(h.world.origin[2, FOOD]) == (0, 7, h.world.clock[0])


def test_a_distrusted_origin_is_skipped_though_its_reseller_is_unjudged():
    # seller 1 (age 5) resells robot 3's vector; the buyer's record of 3 is 0 good, 3 bad: mean 1/5 < 0.3.
    # Seller 2 (age 6) offers its own.  Without provenance seller 1 (a stranger, 0.5) is bought; with it,
    # seller 2, and the entry's origin becomes 2 (an invalid entry takes the purchase whole).
    for provenance, seller in ((0.0, 1), (1.0, 2)):
        h = _market(4, offers=[(1, 10.0, 0.0, 5), (2, 0.0, 10.0, 6)])
        _recorded(h, 1, 3, 5, 9)
        trust_add(h.view, 0, 3, 0.0, 3.0)
        _, _, _, held = _buy(h, "outcome_trust", *PROVENANCE[:4], provenance)
        assert held == [seller] and _sellers(h) == [seller]
    assert tuple(h.world.origin[0, FOOD]) == (2, 503, 10)  # age (1000 + 6) // 2, recorded now


def test_a_resold_vector_is_remembered_and_recorded_by_its_origin():
    # seller 1 resells robot 3's vector (no record of 3: mean 1/2).  The invalid entry takes it: the user on
    # record is 3 (a failed trip will blame 3, not 1), and the new entry's origin is 3.
    h = _market(4, offers=[(1, 10.0, 0.0, 5)])
    _recorded(h, 1, 3, 5, 9)
    vec, age, valid, held = _buy(h, "outcome_trust", *PROVENANCE)
    assert vec == (10.0, 0.0) and age == 502 and held == [3] and _sellers(h) == [1]
    assert tuple(h.world.origin[0, FOOD]) == (3, 502, 10)


def test_an_average_dominated_by_the_own_entry_keeps_the_own_origin():
    # own (0, 0) age 3; robot 3's (10, 0) resold by seller 1 at age 2; the buyer's record of 3 is 0 good, 1
    # bad: mean 1/3 (not below 0.3).  Bought weight 3/5 * 1/3 = 1/5 against 2/5 -> k = 1/3 < 1/2.  The entry
    # (10/3, 0), aged 5 // 2 = 2, stays the robot's own (it had no origin on record: itself, 0); the user on
    # record is still the origin, 3.
    h = _market(4, own=(0.0, 0.0, 3), offers=[(1, 10.0, 0.0, 2)])
    _recorded(h, 1, 3, 2, 9)
    trust_add(h.view, 0, 3, 0.0, 1.0)
    vec, age, _, held = _buy(h, "outcome_trust", *PROVENANCE)
    assert vec == pytest.approx((10.0 / 3.0, 0.0), abs=1e-12) and age == 2 and held == [3]
    assert tuple(h.world.origin[0, FOOD]) == (0, 2, 10)
    np.testing.assert_array_equal(h.world.origin[1:3, FOOD, 0], [3, -1])  # nobody else's record touched


def test_outcome_trust_with_provenance_passes_the_public_checker():
    """The checker runs a rule with its defaults, so provenance is switched on by a rule that calls
    ``outcome_trust``'s with it, as a user would."""
    import infomarket as im
    from infomarket import checks
    from infomarket.registry import get_behaviour

    trust = get_behaviour("outcome_trust").buy.func

    def provenance_buy(w, me, nbrs):
        trust(w, me, nbrs, *PROVENANCE)

    im.register_behaviour("tmp_outcome_provenance", buy=provenance_buy, sell="naive", honest=True, replace=True)
    checks.check_behaviour("tmp_outcome_provenance", steps=1500)
