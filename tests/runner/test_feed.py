"""Several searches' sweeps on one executor (``runner.feed``): each run made once, even when two searches
ask for it at once, the store the sweeps one after another make, results in the jobs' order, and a job's
error raised with the other jobs ended."""
import threading

import pandas as pd
import pytest

import infomarket as im
from infomarket.errors import InternalError
from infomarket.runner.feed import Feed
from infomarket.runner.sweep import plan, run_sweep
from infomarket.store import Store

from .test_sweep import write


def _sorted(df: pd.DataFrame) -> pd.DataFrame:
    return df.sort_values(["experiment", "condition", "run", "robot"]).reset_index(drop=True)


@pytest.fixture(scope="module")
def conds(tmp_path_factory):
    return plan([im.load_experiment(write(tmp_path_factory.mktemp("feed"), steps=200, runs=2))])


def test_searches_asking_for_the_same_runs_at_once_get_each_run_made_once(conds, tmp_path):
    store = Store(tmp_path / "fed", cache=True)
    feed = Feed(store)
    threads = set()

    def job(first, then):
        def go():
            threads.add(threading.current_thread().name)
            a = feed.sweep(first)
            b = feed.sweep(then)
            return a.done + a.skipped, b.done + b.skipped
        return go

    # by hand: 4 conditions of 2 runs; the jobs overlap on conditions 1 and 2, and each asks again for some
    # the other asked first
    out = feed.map([job(conds[0:3], conds[3:4]), job(conds[1:4], conds[0:1])])
    assert out == [(6, 2), (6, 2)]
    assert len(threads) == 2
    runs = store.runs()
    assert len(runs) == 8 and not runs.duplicated(["experiment", "condition", "run"]).any()
    alone = Store(tmp_path / "alone")
    run_sweep(conds, alone)
    pd.testing.assert_frame_equal(_sorted(store.robots()), _sorted(alone.robots()), check_exact=True)
    assert feed.busy.runs == 8 and feed.busy.run_seconds > 0


def test_a_jobs_error_is_raised_and_ends_the_others(conds, tmp_path):
    feed = Feed(Store(tmp_path / "s", cache=True))
    after = []

    failed = threading.Event()

    def fails():
        failed.set()
        raise ValueError("the optimiser's own error")

    def sweeps():
        # every sweep hands the turn on, so the failing job runs at some point: whichever thread the error
        # reaches first, the sweep asked after it must raise and end this job (no timing decides it)
        while not failed.is_set():
            feed.sweep(conds[:1])
        feed.sweep(conds[1:2])
        after.append("kept going")

    before = set(threading.enumerate())
    with pytest.raises(ValueError, match="the optimiser's own error"):
        feed.map([sweeps, fails])
    for t in set(threading.enumerate()) - before:  # the other job, ended at its sweep
        t.join(timeout=60)
        assert not t.is_alive()
    assert after == []


def test_a_job_that_sweeps_after_the_map_ended_is_stopped_not_run_alone(conds, tmp_path):
    """The interleaving the test above leaves to chance, forced: the other job asks its next sweep only
    after ``map`` has raised (its thread lives on), and must be stopped rather than sweep by itself."""
    feed = Feed(Store(tmp_path / "s", cache=True))
    raised, outcome = threading.Event(), []

    def late():
        feed._turn(False)  # wait without holding the turn, as a job between two sweeps does
        raised.wait(60)
        feed._turn(True)
        try:
            feed.sweep(conds[1:2])
            outcome.append("swept alone")
        except InternalError as exc:
            outcome.append(str(exc))

    def fails():
        raise ValueError("the optimiser's own error")

    with pytest.raises(ValueError, match="the optimiser's own error"):
        feed.map([late, fails])
    raised.set()
    for t in feed._jobs:
        t.join(timeout=60)
    assert outcome == ["stopped: ValueError: the optimiser's own error"]
    assert not Store(tmp_path / "s").exists() or Store(tmp_path / "s").runs().empty
