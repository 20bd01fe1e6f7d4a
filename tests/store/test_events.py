"""--events stores each run's event log (purchases, refusals, deposits) as the store's events table, and
what each seller was paid at each deposit as its payments table."""
import pandas as pd

import infomarket as im
from infomarket.cli import main
from infomarket.runner.plan import conditions
from infomarket.store import Store


def test_sweep_events_equal_the_engines_log_of_each_run(tiny, tmp_path):
    exp = tiny(runs=2, steps=2000)
    out = tmp_path / "s"
    assert main(["sweep", str(exp), "--out", str(out), "--workers", "1", "--quiet", "--events"]) == 0
    events = Store(out).events()
    assert {"experiment", "condition", "run", "seed", "kind", "buyer", "seller", "information_share"} <= set(events)
    c = conditions(im.load_experiment(exp))[1]
    alone = im.simulate(c.config, seed=c.seed(1), record_events=True).events
    assert len(alone) > 0 and (alone.kind == "purchase").any()
    mine = events[(events.condition == c.id) & (events.run == 1)].reset_index(drop=True)
    pd.testing.assert_frame_equal(mine[list(alone.columns)], alone, check_exact=True, check_categorical=False)


#: Close sites in a small arena: deposits within a few hundred steps; staking with outliers weighed out.  The
#: paper's Fig. 4 mix, whose step kernel other tests compile too.
BUSY = """
name = "busy"
steps = 1500
runs = 2
seed = 3
[arena]
width = 300
height = 200
[food]
x = 60
y = 100
radius = 30
[nest]
x = 240
y = 100
radius = 30
[swarm]
robots = 9
[[swarm.groups]]
behaviour = "sceptical"
count = 7
[[swarm.groups]]
behaviour = "scaboteur"
count = 2
[payment]
scheme = "outlier"
stake = 0.04
[sweep.grid]
"payment.information_share" = [0.25, 0.5]
"""


def test_sweep_payments_say_which_seller_was_paid_what(tmp_path):
    exp = tmp_path / "busy.toml"
    exp.write_text(BUSY)
    out = tmp_path / "s"
    assert main(["sweep", str(exp), "--out", str(out), "--workers", "1", "--quiet", "--events"]) == 0
    store = Store(out)
    pays, events = store.payments(), store.events()
    assert {"experiment", "condition", "run", "seed", "step", "buyer", "seller", "site", "weight",
            "amount"} <= set(pays)
    c = conditions(im.load_experiment(exp))[1]
    alone = im.simulate(c.config, seed=c.seed(1), record_events=True)
    assert len(alone.payments) > 0
    mine = pays[(pays.condition == c.id) & (pays.run == 1)].reset_index(drop=True)
    pd.testing.assert_frame_equal(mine[list(alone.payments.columns)], alone.payments, check_exact=True)
    # every deposit pays exactly the purchases its buyer made since its previous deposit
    for (cond, run), ev in events.groupby(["condition", "run"]):
        paid = pays[(pays.condition == cond) & (pays.run == run)]
        for buyer, mine_ev in ev.groupby("buyer"):
            bought = mine_ev[mine_ev.kind == "purchase"]
            deposits = mine_ev[mine_ev.kind == "deposit"].step.tolist()
            settled = bought[bought.step <= max(deposits, default=-1)]
            assert len(paid[paid.buyer == buyer]) == len(settled)


def test_without_events_there_is_no_events_table(tiny, tmp_path):
    out = tmp_path / "s"
    assert main(["sweep", str(tiny()), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    assert Store(out).events().empty and not list((out / "events").glob("*.parquet"))
    assert Store(out).payments().empty and not list((out / "payments").glob("*.parquet"))
