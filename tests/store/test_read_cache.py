"""A caching store (``Store(root, cache=True)``, the searches' store) extends each table by the parts added
since its last read, and gives exactly what a fresh read of the store gives: the same rows in the same
order, the same dtypes, also when two parts hold rows of one run (a store no sweep writes, read whole)."""
import pandas as pd
import pytest

from infomarket.cli import main
from infomarket.store import Store
from infomarket.store import read_cache

TABLES = ("runs", "robots", "events", "payments", "configs")

OTHER = """
name = "other"
steps = 200
runs = 2
seed = 4

[swarm]
robots = 5

[[swarm.groups]]
behaviour = "sceptical"
count = 4

[[swarm.groups]]
behaviour = "scaboteur"
count = 1

[payment]
scheme = "outlier"

[sweep.grid]
"payment.stake" = [0.0, 1.0]
"""


def sweep(exp, out, *extra):
    assert main(["sweep", str(exp), "--out", str(out), "--workers", "1", "--quiet", *extra]) == 0


def same_as_fresh(cached: Store) -> None:
    fresh = Store(cached.root)
    for table in TABLES:
        pd.testing.assert_frame_equal(getattr(cached, table)(), getattr(fresh, table)(), check_exact=True)


@pytest.fixture
def concats(monkeypatch):
    """How many frames each concatenation of the read cache joined."""
    seen = []
    concat = read_cache.pd.concat

    def counting(frames, **kw):
        frames = list(frames)
        seen.append(len(frames))
        return concat(frames, **kw)

    monkeypatch.setattr(read_cache.pd, "concat", counting)
    return seen


def test_a_growing_store_is_read_by_its_new_parts_and_reads_as_a_fresh_read(tiny, tmp_path, concats):
    root = tmp_path / "s"
    sweep(tiny(runs=2), root)
    cached = Store(root, cache=True)
    same_as_fresh(cached)
    parts = len(cached.committed())
    for runs in (4, 5):  # more runs of the same conditions
        sweep(tiny(runs=runs), root)
        concats.clear()
        cached.robots()
        new = len(cached.committed()) - parts
        assert concats == [1 + new], "the robots table was not extended by the new parts alone"
        parts += new
        same_as_fresh(cached)
    other = tmp_path / "other.toml"  # another experiment, other behaviours, with events and payments
    other.write_text(OTHER)
    sweep(other, root, "--events")
    same_as_fresh(cached)
    concats.clear()
    again = cached.robots()
    assert concats == [] and again.equals(Store(root).robots())  # nothing new: the last rows, copied


def test_two_parts_holding_one_run_read_as_the_whole_store_reads(tiny, tmp_path):
    root = tmp_path / "s"
    sweep(tiny(runs=2), root)
    cached = Store(root, cache=True)
    cached.robots(), cached.runs()
    # a second part holding run 0 of the first part's condition, with other values, under an id that sorts
    # first: a fresh read puts its rows before the first part's, equal keys kept in part order
    first = cached.committed()[0]
    record = pd.read_parquet(cached.part_path("runs", first))
    robots = pd.read_parquet(cached.part_path("robots", first))
    run0 = record[record.run == 0].drop(columns=[c for c in record.columns if c.endswith(("_sha256", "_rows"))])
    twin = robots[robots.run == 0].assign(items_collected=lambda d: d.items_collected + 100)
    keys = ["information_share"]  # the condition's key column
    with cached.writing():
        cached.write_part("0000-twin", robots=twin, runs=run0, keys=keys)
    assert "0000-twin" < first
    same_as_fresh(cached)
    both = cached.robots()
    rows = both[(both.condition == run0.condition.iloc[0]) & (both.run == 0)]
    items = rows.items_collected.to_numpy()  # robot by robot: the twin's row first, then the first part's
    assert len(rows) == 2 * len(twin) and (items[::2] >= 100).all() and (items[1::2] < 100).all()


def test_what_a_caching_store_writes_is_read_back_without_opening_it(tiny, tmp_path, monkeypatch):
    """The searches sweep into their own caching store: a commit record it has just written, and the checksum
    of a data part it has just hashed, are not read from the disk again, and read as a fresh read reads."""
    from infomarket.config import load_experiment
    from infomarket.runner.sweep import plan, run_sweep
    from infomarket.store import integrity, results

    cached = Store(tmp_path / "s", cache=True)
    opened = []
    read_record, sha = results.Store._read_runs_part_now, integrity.sha256_file
    monkeypatch.setattr(results.Store, "_read_runs_part_now", lambda self, path: opened.append(path) or
                        read_record(self, path))
    monkeypatch.setattr(integrity, "sha256_file", lambda path: opened.append(path) or sha(path))
    for runs in (2, 3):
        run_sweep(plan([load_experiment(tiny(runs=runs))]), cached)  # the second one checks the first's parts
        cached.check()
        tables = {t: getattr(cached, t)() for t in TABLES}
        assert opened == []
        for t, frame in tables.items():
            pd.testing.assert_frame_equal(frame, getattr(Store(cached.root), t)(), check_exact=True)
        opened.clear()  # the fresh store's reads


def test_a_commit_record_of_every_kind_of_key_reads_back_verified(tmp_path):
    """The record's digest is taken of the table written, before it is written: a fresh reader recomputes it
    from what it reads back, so keys of every kind (a flag, a rate with NaN, a label) and a failed run's
    error text must come back exactly."""
    import numpy as np

    runs = pd.DataFrame({"experiment": ["e"] * 4, "condition": [f"k={i}" for i in range(4)], "run": [0, 1, 2, 3],
                         "seed": np.array([1, 2**63, 3, 2**64 - 1], dtype=np.uint64), "status": ["ok"] * 3 + ["failed"],
                         "error": ["", "", "", "Traceback: a rule raised ✓"], "flag": [True, False, True, False],
                         "rate": [np.nan, 0.25, 1e-300, -0.0], "label": ["a", "b", "", "é"]})
    writer = Store(tmp_path / "s", cache=True)
    with writer.writing():
        writer.write_part("p", robots=None, runs=runs, keys=["flag", "rate", "label"])
    back = Store(tmp_path / "s").runs()  # a fresh reader: the digest checked against what it read
    pd.testing.assert_frame_equal(back[runs.columns], runs, check_exact=True, check_dtype=False)
    pd.testing.assert_frame_equal(back, writer.runs(), check_exact=True)
