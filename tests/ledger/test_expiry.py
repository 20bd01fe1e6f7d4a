"""The stake-expiry rule in the engine's step loop (the replay and the contract are checked against an
exact ledger in tests/evm/test_conformance.py)."""
import numpy as np
import pytest

import infomarket as im
from infomarket.engine.world import open_transactions


def _run(expiry: int, steps: int = 3000):
    cfg = im.load_experiment("fig4C").model_dump(exclude={"sweep"})
    cfg["payment"]["stake_expiry"] = expiry
    sim = im.Simulation(im.Experiment.model_validate(cfg), seed=3, record_events=True)
    return sim, steps


def test_no_stake_stays_locked_longer_than_the_bound():
    T = 200
    sim, steps = _run(T)
    oldest_seen = 0
    for _ in range(steps // 100):
        sim.step(100)
        w = sim.world
        for i in range(25):
            a, k = int(w.tx_off[i]), int(w.tx_count[i])
            locked = w.tx_stake[a:a + k] > 0.0
            if locked.any():
                age = int(w.clock[0]) - int(w.tx_step[a:a + k][locked].min())
                oldest_seen = max(oldest_seen, age)
                assert age < T  # opened at t, its stake back at the start of step t + T
            # a pot holds exactly the stakes of the buyer's open transactions
            assert w.pot[i] == pytest.approx(float(w.tx_stake[a:a + k].sum()), abs=1e-12)
    assert oldest_seen > T // 2  # purchases did stay open long enough for the rule to matter
    r = sim.result()
    deposits = int((r.events.kind == "deposit").sum())
    assert r.totals["wealth"] + r.totals["pots"] == pytest.approx(25 + deposits, abs=1e-9)


def test_expiry_changes_nothing_until_a_stake_would_expire():
    a, steps = _run(0)
    b, _ = _run(10**9)
    a.step(steps)
    b.step(steps)
    assert np.array_equal(a.world.balance, b.world.balance) and np.array_equal(a.world.pos, b.world.pos)
    c, _ = _run(50)
    c.step(steps)
    assert not np.array_equal(a.world.balance, c.world.balance)  # with a short bound, stakes came back


def test_expired_transactions_stay_in_the_round_trip_in_order_without_their_stakes():
    """They are paid an equal part of the share at the deposit (tests/evm/test_conformance.py)."""
    sim, _ = _run(30)
    sim.step(1500)
    w = sim.world
    expired = 0
    for i in range(25):
        sellers, sites, directions = open_transactions(w, i)
        a, k = int(w.tx_off[i]), int(w.tx_count[i])
        steps, stakes = w.tx_step[a:a + k], w.tx_stake[a:a + k]
        old = steps <= int(w.clock[0]) - 30
        assert (np.diff(steps) >= 0).all() and len(sellers) == k
        assert (stakes[old] == 0.0).all() and (stakes[~old] > 0.0).all()
        expired += int(old.sum())
    assert expired > 0  # the rule was exercised
