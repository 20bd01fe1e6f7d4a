"""The ledger's reputation record (engine.world REPUTATION), against numbers worked out by hand."""
import numpy as np
import pytest

import infomarket as im
from infomarket.behaviours import market
from infomarket.ledger import LedgerEvent, replay_events

from ..shared_kernel import simulation


def _settlement(scheme, stake):
    """Buyer 0 buys food vectors from sellers 1-5 (0, 5, 10, 15, 20 deg: all within 30 of each other)
    and from seller 6 (100 deg: an outlier), then deposits; 8 robots of wealth 1."""
    dirs = [0.0, 5.0, 10.0, 15.0, 20.0, 100.0]
    events = [LedgerEvent("purchase", 0, s, 0, d) for s, d in zip(range(1, 7), dirs)]
    return replay_events(events + [LedgerEvent("deposit", 0)], 8, scheme=scheme, stake=stake)


def test_one_outlier_settlement_by_hand():
    res = _settlement("outlier", 0.04)
    # weights 5,5,5,5,5,1 (total 26); pot 6 x 0.04 = 0.24; the sellers share 0.5 + 0.24 = 0.74
    honest_pay, outlier_pay = 0.74 * 5 / 26, 0.74 / 26
    rec = res.record
    assert rec["rep_settled"].tolist() == [0, 1, 1, 1, 1, 1, 1, 0]
    # best weight of the food site is 5, half of it 2.5: only seller 6 (weight 1) is an outlier
    assert rec["rep_reduced"].tolist() == [0, 0, 0, 0, 0, 0, 1, 0]
    assert rec["rep_earned"] == pytest.approx([0] + [honest_pay] * 5 + [outlier_pay, 0], abs=1e-12)
    # seller 6 locked 0.04 and was paid 0.0285: it lost 0.0115; the others earned more than their stake
    assert rec["rep_stake_lost"] == pytest.approx([0] * 6 + [0.04 - outlier_pay, 0], abs=1e-12)
    assert rec["rep_deposits"].tolist() == [1, 0, 0, 0, 0, 0, 0, 0]
    assert rec["money"][0] == pytest.approx(9.0, abs=1e-12)  # 8 initial + 1 reward, nothing locked
    assert res.balances == pytest.approx([1.5] + [1 - 0.04 + honest_pay] * 5 + [1 - 0.04 + outlier_pay, 1.0])


def test_under_delayed_payment_no_sale_is_an_outlier():
    rec = _settlement("delayed", 0.0).record
    assert rec["rep_settled"][1:7].tolist() == [1] * 6
    assert rec["rep_reduced"].sum() == 0
    assert rec["rep_earned"][1:7] == pytest.approx([0.5 / 6] * 6)
    assert rec["rep_stake_lost"].sum() == 0


def test_an_expired_sale_is_judged_by_weight_and_paid_from_the_buyers_balance():
    events = [LedgerEvent("purchase", 0, 1, 0, 0.0, step=1), LedgerEvent("purchase", 0, 2, 0, 0.0, step=9),
              LedgerEvent("deposit", 0, step=10)]
    res = replay_events(events, 3, scheme="outlier", stake=0.04, stake_expiry=5)
    rec = res.record
    # seller 1's sale expired the buyer's round trip at step 6: settled then by weight (alone, so not an
    # outlier), the share 0.5 from the buyer's balance and its stake back: 0.54. Seller 2's sale opened a
    # new round trip, paid 0.5 + its stake at the deposit; the buyer paid the share twice for one reward.
    assert rec["rep_settled"].tolist() == [0, 1, 1] and rec["rep_reduced"].tolist() == [0, 0, 0]
    assert rec["rep_earned"] == pytest.approx([0.0, 0.54, 0.54], abs=1e-12)
    assert res.balances == pytest.approx([1.0, 1.5, 1.5], abs=1e-12)
    assert rec["money"][0] == pytest.approx(res.balances.sum() + res.pots.sum(), abs=1e-12)
    assert rec["money"][0] == pytest.approx(4.0, abs=1e-12)


def test_readers_compute_from_the_record():
    rec = _settlement("outlier", 0.04).record
    w = type("W", (), {**rec, "balance": np.array([3.0, 1.0]), "money": np.array([4.0]), "rep_decay": 1.0})
    py = {name: getattr(market, name).py_func for name in ("seller_reputation", "wealth_share", "wealth",
                                                          "sales_settled", "sales_reduced", "deposits")}
    assert py["seller_reputation"](w, 1) == pytest.approx(2 / 3)   # 1 good sale of 1, Laplace: 2/3
    assert py["seller_reputation"](w, 6) == pytest.approx(1 / 3)   # 1 outlier of 1: 1/3
    assert py["seller_reputation"](w, 7) == pytest.approx(1 / 2)   # never judged
    assert py["wealth_share"](w, 0) == pytest.approx(0.75)
    assert py["wealth"](w, 1) == 1.0
    assert (py["sales_settled"](w, 6), py["sales_reduced"](w, 6), py["deposits"](w, 0)) == (1, 1, 1)


def test_money_is_the_sum_of_balances_through_a_run_with_fuel_and_staking():
    cfg = im.Experiment.model_validate({
        "steps": 3000, "robot": {"fuel_cost": 0.0001},
        "swarm": {"robots": 25, "groups": [{"behaviour": "naive", "count": 20},
                                           {"behaviour": "scaboteur", "count": 5}]},
        "payment": {"scheme": "outlier", "stake": 0.04, "initial_wealth": 2.0}})
    sim = simulation(cfg, 4, record_events=True)  # on the rule checks' kernel: nothing new to compile
    res = sim.run()
    w = sim.world
    assert w.burned[0] > 0 and w.rep_settled.sum() > 0 and w.rep_reduced.sum() > 0
    assert w.money[0] == pytest.approx(w.balance.sum(), abs=1e-9)
    # one deposit counted per deposit event of the log
    deposits = res.events[res.events.kind == "deposit"].groupby("buyer").size().reindex(range(25), fill_value=0)
    assert deposits.sum() > 0 and w.rep_deposits.tolist() == deposits.tolist()
