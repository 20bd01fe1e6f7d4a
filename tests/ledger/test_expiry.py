"""The stake-expiry rule in the engine's step loop (the replay and the contract are checked against an
exact ledger in tests/evm/test_conformance.py)."""
import numpy as np
import pytest

import infomarket as im


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


def test_an_expired_round_trip_is_settled_whole_by_weight_before_the_step():
    """Once its first transaction is stake_expiry steps old, a buyer's whole round trip is paid as a
    deposit pays it, with no reward (the amounts are checked by hand and against the exact ledger in
    tests/evm/test_conformance.py): no open transaction is that old, and settlements without a deposit
    appear in the payments log, weighed (an outlier among them)."""
    T = 30
    sim, _ = _run(T)
    sim.step(1500)
    w = sim.world
    for i in range(25):
        a, k = int(w.tx_off[i]), int(w.tx_count[i])
        steps = w.tx_step[a:a + k]
        assert (np.diff(steps) >= 0).all() and (steps > int(w.clock[0]) - T).all()
    r = sim.result()
    deposits = set(zip(r.events.step[r.events.kind == "deposit"], r.events.buyer[r.events.kind == "deposit"]))
    expired = r.payments[[(s, b) not in deposits for s, b in zip(r.payments.step, r.payments.buyer)]]
    assert len(expired) > 0  # the rule was exercised
    assert (expired.amount > 0).all() and expired.weight.nunique() > 1  # paid, and by weight, not equally
    assert r.totals["wealth"] + r.totals["pots"] == pytest.approx(25 + len(deposits), abs=1e-9)  # no reward minted
