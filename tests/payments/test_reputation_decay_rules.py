"""Reputation that decays (``payment.reputation_decay``): the ledger's decayed record and the reputation
rules read, by hand, round trip after round trip; and its configuration."""
import pytest

from infomarket import load_experiment
from infomarket.behaviours.market import seller_reputation
from infomarket.config import validate
from infomarket.errors import ConfigError
from infomarket.ledger.replay import Ledger


def _trips(decay, lies):
    """Buyer 0 buys food from sellers 1, 2, 3 (10, 15, 20 degrees) and 4, then deposits, once per entry
    of ``lies``: seller 4 sells 12 degrees (agrees with all: weight 4 of 4) or, lying, 100 (alone:
    weight 1, below half the best 3, an outlier).  Outlier penalisation, Θ = 30."""
    ledger = Ledger(5, scheme="outlier", reputation_decay=decay)
    reps = []
    for lie in lies:
        for s, d in ((1, 10.0), (2, 15.0), (3, 20.0), (4, 100.0 if lie else 12.0)):
            ledger.purchase(0, s, 0, d)
        ledger.deposit(0)
        reps.append(seller_reputation(ledger.view, 4))
    return ledger, reps


def test_a_decayed_record_forgets_a_good_past_as_lies_come():
    # decay 0.5: seller 4's (good, bad) after each trip: (1, 0), (1.5, 0), (0.75, 1), (0.375, 1.5);
    # reputation (good + 1) / (good + bad + 2)
    ledger, reps = _trips(0.5, [False, False, True, True])
    assert reps == pytest.approx([2 / 3, 2.5 / 3.5, 1.75 / 3.75, 1.375 / 3.875], abs=1e-12)
    book = ledger.book
    assert (book.rep_good[4], book.rep_bad[4]) == (0.375, 1.5)
    # an honest seller's record decays too, but keeps counting good sales: 1 + 0.5 + 0.25 + 0.125
    assert book.rep_good[1] == 1.875 and book.rep_bad[1] == 0.0
    assert seller_reputation(ledger.view, 1) == pytest.approx(2.875 / 3.875, abs=1e-12)
    # the integer record is kept as before: 4 settled, 2 reduced
    assert (book.rep_settled[4], book.rep_reduced[4]) == (4, 2)


def test_without_decay_the_reputation_is_the_whole_record():
    # Laplace on 4 settled sales, 2 outliers: after each trip 2/3, 3/4, 3/5, 3/6; the decayed record is unused
    ledger, reps = _trips(1.0, [False, False, True, True])
    assert reps == pytest.approx([2 / 3, 3 / 4, 3 / 5, 3 / 6], abs=1e-12)
    assert ledger.book.rep_good.sum() == 0.0 and ledger.book.rep_bad.sum() == 0.0


def _cfg(**payment):
    return validate({"swarm": {"robots": 3, "groups": [{"behaviour": "naive", "count": 3}]},
                                         "payment": {"scheme": "outlier", **payment}})


def test_the_decay_is_a_market_setting_that_leaves_other_setups_hashes_alone():
    # fig2A's hash as the code computed it before the setting existed (tests/ledger/test_chain.py)
    assert load_experiment("fig2A").config_hash() == "93b0d0974ae24300"
    assert _cfg().config_hash() == _cfg(reputation_decay=1.0).config_hash()
    assert _cfg(reputation_decay=0.9).config_hash() != _cfg().config_hash()
    for bad in (0.0, 1.5):
        with pytest.raises(ConfigError, match="reputation_decay"):
            _cfg(reputation_decay=bad)
    with pytest.raises(ConfigError, match="reputation_decay"):
        validate({"swarm": {"robots": 3, "groups": [{"behaviour": "naive", "count": 3}]},
                  "payment": {"reputation_decay": 0.9}, "chain": {"consensus": "poa"}})
