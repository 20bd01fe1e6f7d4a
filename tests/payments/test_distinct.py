"""``outlier_distinct`` (one seller, one voice): weights by hand, the attacks it answers, and the
public checker every scheme must pass."""
import numpy as np
import pytest

from infomarket.ledger import LedgerEvent, replay_events
from infomarket.payments.distinct import outlier_distinct_weights
from infomarket.registry import get_payment


def _weights(sellers, sites, directions, theta=30.0):
    w = np.zeros(len(sellers))
    outlier_distinct_weights(0, np.array(sellers, dtype=np.int64), np.array(sites, dtype=np.int64),
                             np.array(directions, dtype=np.float64), w, theta)
    return list(w)


def test_weights_by_hand():
    # food: sellers 1 and 2 agree (10 and 20 degrees), seller 3 twice at 15 (agrees with both), seller 4
    # at 200 (alone); nest: seller 1 at 350 and seller 2 at 5 agree across 0 degrees.
    w = _weights([1, 2, 3, 3, 4, 1, 2], [0, 0, 0, 0, 0, 1, 1], [10.0, 20.0, 15.0, 15.0, 200.0, 350.0, 5.0])
    # 10: sellers 1, 2, 3 -> 3; 20: 3; each 15: sellers 1, 2, 3 = 3, split over seller 3's two sales;
    # 200: itself only; nest: 2 each (a seller's weight is split over its sales for the same site only).
    assert w == [3.0, 3.0, 1.5, 1.5, 1.0, 2.0, 2.0]


def test_a_repeating_saboteur_gets_what_it_would_get_selling_once():
    """The review's attack: one 90-degree-rotated vector sold 5 times against three honest sellers.
    Under eq. 7 it takes 25/34 = 73.5 % of the share; here 1/10, as if it had sold once."""
    honest = [LedgerEvent("purchase", 0, s, 0, d) for s, d in ((1, 10.0), (2, 15.0), (3, 20.0))]
    repeated = [LedgerEvent("purchase", 0, 4, 0, 100.0)] * 5
    events = honest + repeated + [LedgerEvent("deposit", 0)]
    paper = replay_events(events, 5, scheme="outlier", params={"theta": 30.0})
    distinct = replay_events(events, 5, scheme="outlier_distinct", params={"theta": 30.0})
    assert paper.balances[4] - 1.0 == pytest.approx(0.5 * 25 / 34)  # eq. 7 unchanged: 73.5 %
    assert distinct.balances[4] - 1.0 == pytest.approx(0.5 * 1 / 10)
    assert [distinct.balances[s] - 1.0 for s in (1, 2, 3)] == pytest.approx([0.5 * 3 / 10] * 3)


def test_a_copying_seller_gets_no_more_than_one_honest_sellers_share():
    """A seller that copies the honest direction 6 times: each copy counts sellers 1, 2, 3 and itself
    (4) but weighs 4/6, so its six copies earn exactly one honest seller's share (4 of 16)."""
    events = ([LedgerEvent("purchase", 0, s, 0, d) for s, d in ((1, 10.0), (2, 15.0), (3, 20.0))]
              + [LedgerEvent("purchase", 0, 5, 0, 12.0)] * 6 + [LedgerEvent("deposit", 0)])
    out = replay_events(events, 6, scheme="outlier_distinct", stake=0.04, params={"theta": 30.0})
    amount = 0.5 + 9 * 0.04
    assert out.balances[5] == pytest.approx(1.0 - 6 * 0.04 + amount / 4)
    assert out.balances[1] == pytest.approx(1.0 - 0.04 + amount / 4)
    assert out.balances[0] == pytest.approx(1.0 + 1.0 + 9 * 0.04 - amount)


def test_registered_through_the_public_api():
    """Registered like the built-ins (tests/test_checks.py runs the payment checker on every scheme)."""
    spec = get_payment("outlier_distinct")
    assert spec.weights.py_func is outlier_distinct_weights
    assert spec.params == ("theta",) and spec.defaults == {"theta": 30.0}
