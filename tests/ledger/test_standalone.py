"""The ledger runs on its own state: a replay builds no swarm and runs no engine code."""
import numpy as np
import pytest

from infomarket.engine import build, swarm
from infomarket.ledger import state
from infomarket.ledger.replay import Ledger, LedgerEvent, replay_events


def test_a_replay_builds_no_swarm(monkeypatch):
    def forbidden(*a, **k):
        raise AssertionError("the ledger built a swarm")

    monkeypatch.setattr(swarm, "build_swarm", forbidden)
    monkeypatch.setattr(build, "build_world", forbidden)
    monkeypatch.setattr(build, "build_swarm", forbidden)
    events = [LedgerEvent("purchase", 0, 1, 0, 10.0), LedgerEvent("purchase", 0, 2, 0, 12.0),
              LedgerEvent("deposit", 0)]
    out = replay_events(events, 3, stake=0.04)
    # by hand: reward 1 to the buyer, pot 0.08 back to it, then 0.5 + 0.08 split equally (delayed)
    np.testing.assert_allclose(out.balances, [1.0 + 1.0 + 0.08 - 0.58, 0.96 + 0.29, 0.96 + 0.29])
    assert out.accepted == [True, True]
    assert out.record["rep_settled"].tolist() == [0, 1, 1]


def test_the_book_holds_no_swarm_field():
    book = state.new_book(4, initial_wealth=1.0, reward=1.0, information_share=0.5, stake=0.0,
                          stake_expiry=0, pparams=[])
    assert not set(book._fields) & set(swarm.SPEC.names)
    assert {"balance", "tx_seller", "clock", "ev_step"} <= set(book._fields)


def test_a_seller_short_of_the_stake_is_refused_and_pays_nothing():
    ledger = Ledger(2, stake=0.6)
    assert ledger.purchase(0, 1, 0, 0.0)
    assert not ledger.purchase(0, 1, 1, 0.0)  # 0.4 left, below the stake
    assert ledger.book.balance.tolist() == pytest.approx([1.0, 0.4])
    assert ledger.book.pot.tolist() == pytest.approx([0.6, 0.0])
