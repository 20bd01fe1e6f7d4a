"""One warm-up, keyed on the real kernel: ``engine.specialise.kernel_id`` (behaviours, scheme and terrain).

Two conditions that differ only in terrain (collisions on or off) run on two kernels, so a sweep must
load both before handing runs to other processes; the key it used to use, (behaviours, scheme), took
them for one.  The same configuration under another seed or stake shares its kernel: loaded once."""
from __future__ import annotations

from concurrent.futures import Executor, Future

import infomarket as im
from infomarket.engine.build import behaviour_kinds
from infomarket.engine.specialise import kernel_id
from infomarket.runner import execute
from infomarket.runner.plan import conditions
from infomarket.runner.sweep import plan, run_sweep
from infomarket.store import Store

#: The paper's Fig. 4 mix (sceptical robots, scaboteurs, outlier payment): the suite compiles its step kernels
#: for other tests too, on the plane and with terrain (tests/store/test_dictionary.py).
TERRAIN_SWEEP = """
name = "collide"
steps = 200
runs = 2
seed = 4

[swarm]
robots = 6

[[swarm.groups]]
behaviour = "sceptical"
count = 5

[[swarm.groups]]
behaviour = "scaboteur"
count = 1

[payment]
scheme = "outlier"

[sweep.grid]
"robot.collisions" = [false, true]
"payment.stake" = [0.0, 0.04]
"""


class Direct(Executor):
    """Runs each call when submitted, but is not the InlineExecutor: stands for a pool or a cluster."""

    def __init__(self):
        self.calls = 0

    def submit(self, fn, /, *args, **kwargs) -> Future:
        self.calls += 1
        f: Future = Future()
        f.set_result(fn(*args, **kwargs))
        return f


def _experiment(tmp_path):
    path = tmp_path / "collide.toml"
    path.write_text(TERRAIN_SWEEP)
    return im.load_experiment(path)


def test_configs_differing_only_in_terrain_are_warmed_separately(tmp_path, monkeypatch):
    conds = conditions(_experiment(tmp_path))
    assert len(conds) == 4
    plane = [c.config for c in conds if not c.config.robot.collisions]
    walls = [c.config for c in conds if c.config.robot.collisions]
    # the old key could not tell them apart; the kernel's own digest does
    assert {(behaviour_kinds(c), c.payment.scheme) for c in plane + walls} == {(("sceptical", "scaboteur"), "outlier")}
    assert len({kernel_id(c) for c in plane}) == len({kernel_id(c) for c in walls}) == 1
    assert kernel_id(plane[0]) != kernel_id(walls[0])

    warmed = []
    monkeypatch.setattr(execute, "warm", lambda cfg: warmed.append(cfg))
    seconds = execute.warm_up([*plane, *walls, *plane])
    assert [c.robot.collisions for c in warmed] == [False, True]  # once per kernel, in first-seen order
    assert set(seconds) == {kernel_id(plane[0]), kernel_id(walls[0])}


def test_a_sweep_on_another_executor_warms_each_kernel_once_before_submitting(tmp_path, monkeypatch):
    warmed, pool = [], Direct()
    real = execute.warm

    def record(cfg):
        warmed.append((pool.calls, cfg.robot.collisions))  # how many tasks were submitted before it
        real(cfg)

    monkeypatch.setattr(execute, "warm", record)
    store = Store(tmp_path / "s")
    report = run_sweep(plan([_experiment(tmp_path)]), store, executor=pool)
    assert sorted(warmed) == [(0, False), (0, True)]  # two kernels, both before the first task
    assert report.done == 8 and report.failed == 0 and pool.calls >= 1
    assert len(store.robots()) == 8 * 6
    # inline (one worker, this process) needs no warm-up: each run loads its kernel itself
    warmed.clear()
    run_sweep(plan([_experiment(tmp_path)]), Store(tmp_path / "inline"), workers=1)
    assert warmed == []
    pd_equal = store.robots().equals(Store(tmp_path / "inline").robots())
    assert pd_equal  # same seeds, same numbers, whichever executor
