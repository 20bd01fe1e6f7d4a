"""A Dask worker killed mid-sweep (SIGKILL, as an out-of-memory killer or a lost node would) loses no
run and duplicates none: the scheduler reruns its task elsewhere and the store ends up exactly like a
store made without the loss."""
import os
import signal

import pandas as pd
import pytest

import infomarket as im
from infomarket.runner.sweep import plan, run_sweep
from infomarket.store import Store


def test_a_worker_killed_mid_sweep_loses_and_duplicates_nothing(tiny, tmp_path):
    distributed = pytest.importorskip("distributed")
    exp = im.load_experiment(tiny(runs=12, steps=6000))
    reference = Store(tmp_path / "reference")
    run_sweep(plan([exp]), reference, workers=1)

    killed = []
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        pids = client.run(os.getpid)

        finished = []

        def kill_one(runs: int) -> None:
            finished.append(runs)
            if not killed:  # after the first results come in, while the other tasks still run
                os.kill(next(iter(pids.values())), signal.SIGKILL)
                killed.append(sum(finished))

        store = Store(tmp_path / "dask")
        report = run_sweep(plan([exp]), store, executor=client.get_executor(pure=False), on_done=kill_one)
        victim = next(iter(pids.values()))
        assert victim not in client.run(os.getpid).values()  # the worker really died (its nanny restarted it)
    assert killed and killed[0] < 2 * 12 and report.failed == 0  # killed with runs still to do
    got, want = store.robots(), reference.robots()
    assert len(got) == len(want) == 2 * 12 * 6  # conditions x runs x robots, each exactly once
    assert not got.duplicated(["condition", "run", "robot"]).any()
    key = ["condition", "run", "robot"]
    pd.testing.assert_frame_equal(got.sort_values(key).reset_index(drop=True),
                                  want.sort_values(key).reset_index(drop=True), check_exact=True)
