"""--events stores each run's event log (purchases, refusals, deposits) as the store's events table."""
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


def test_without_events_there_is_no_events_table(tiny, tmp_path):
    out = tmp_path / "s"
    assert main(["sweep", str(tiny()), "--out", str(out), "--workers", "1", "--quiet"]) == 0
    assert Store(out).events().empty and not list((out / "events").glob("*.parquet"))
