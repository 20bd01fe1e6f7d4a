"""engine.batch.Simulations: B runs stepped together in one compiled call are the runs Simulation
makes one at a time, and fresh worlds start with the room earlier runs of the same kernel grew to."""
import json
import sys

import numpy as np
import pandas as pd
import pytest

from infomarket.config import load_experiment
from infomarket.engine import build, simulation
from infomarket.engine.batch import Simulations
from infomarket.engine.simulation import Simulation
from infomarket.errors import ConfigError

SEEDS = [3, 41, 977]


@pytest.fixture(scope="module")
def cfg():
    return load_experiment("fig4C").with_overrides(steps=1500, transitory=500, history_every=250)


def test_runs_stepped_together_are_the_runs_made_alone(cfg):
    simulation._ROOM.clear()  # every run starts from the built capacities: the batch must grow its worlds
    together = Simulations(cfg, SEEDS).run()
    for r, seed in zip(together, SEEDS):
        simulation._ROOM.clear()
        alone = Simulation(cfg, seed).run()
        assert r.seed == seed and r.steps == cfg.steps
        pd.testing.assert_frame_equal(r.robots, alone.robots, check_exact=True)
        pd.testing.assert_frame_equal(r.history, alone.history, check_exact=True)


def test_runs_advanced_in_steps_of_their_own_and_reset_are_the_runs_made_alone(cfg):
    sims = Simulations(cfg, SEEDS)
    sims.advance([100, 700, 1500])
    assert sims.clocks.tolist() == [100, 700, 1500]
    sims.reset(2, 5)  # a new run in slot 2, started from step 0
    sims.advance(cfg.steps)
    for sim, seed in zip(sims.sims, [3, 41, 5]):
        np.testing.assert_array_equal(sim.world.balance, Simulation(cfg, seed).run().robots.wealth.to_numpy())
    assert sims.sims[2].seed == 5


def test_a_fresh_world_starts_with_the_room_earlier_runs_grew_to(cfg, monkeypatch):
    grown = []
    real = simulation.make_room
    monkeypatch.setattr(simulation, "make_room", lambda w, *a: grown.append(1) or real(w, *a))
    simulation._ROOM.clear()
    first = Simulation(cfg, SEEDS[0])
    built = first.world.nbr.shape[1], first.world.pend_seller.shape[2], first.world.tx_cap.copy()
    first.run()
    assert grown, "the first run of a kernel grows its arrays"
    grown.clear()
    second = Simulation(cfg, SEEDS[0])
    assert second.world.nbr.shape[1] >= first.world.nbr.shape[1] >= built[0]
    assert (second.world.tx_cap >= built[2]).all() and (second.world.tx_cap > built[2]).any()
    r = second.run()
    assert not grown, "the same run again starts with the room it needs"
    pd.testing.assert_frame_equal(r.robots, first.result().robots, check_exact=True)


def test_a_bad_seed_in_a_batch_is_refused(cfg):
    with pytest.raises(ConfigError, match="seed must be an integer"):
        Simulations(cfg, [1, -2])


def test_room_of_keeps_the_largest_capacities():
    cfg = load_experiment("fig2A").with_overrides(steps=10)
    w, _ = build.build_world(cfg, np.random.default_rng(0))
    small = build.room_of(w, None)
    assert (small["tx"] == 16).all()
    big = {**small, "nbr": small["nbr"] + 5, "tx": small["tx"] + 20}
    room = build.room_of(w, big)
    assert room["nbr"] == small["nbr"] + 5 and (room["tx"] == 36).all()
    wide = build.with_room(w, room)
    assert wide.nbr.shape == (w.nbr.shape[0], small["nbr"] + 5) and not wide.nbr.any()
    # a block of 16 asked for 36: grow_ledger gives max(2 x 16, 36) = 36, blocks laid end to end, empty
    assert (wide.tx_cap == 36).all() and (wide.tx_off == 36 * np.arange(25)).all() and wide.tx_count.sum() == 0


class _Counted:
    """A kernel module whose ``step_all`` records each call's robot-steps."""

    def __init__(self, module, robots: int):
        self.module, self.robots, self.work = module, robots, []

    def step_all(self, views, rngs, t_end, status, clocks):
        before = clocks.copy()
        short = self.module.step_all(views, rngs, t_end, status, clocks)
        self.work.append(int((clocks - before).sum()) * self.robots)
        return short


@pytest.mark.parametrize("world_steps", [2, 150])  # per call: one step of two of the four worlds; 37 of each
def test_a_batch_is_stepped_in_calls_of_bounded_work_that_do_not_change_its_runs(cfg, monkeypatch, world_steps):
    from infomarket.engine import batch

    seeds = SEEDS + [7]
    monkeypatch.setattr(batch, "CALL_ROBOT_STEPS", 1 << 62)  # no bound: the reference, one call per advance
    whole = Simulations(cfg, seeds)
    whole.advance([100, 700, 1500, 20])
    whole.advance(cfg.steps)
    robots = whole.sims[0].world.pos.shape[0]
    cap = world_steps * robots
    monkeypatch.setattr(batch, "CALL_ROBOT_STEPS", cap)
    parts = Simulations(cfg, seeds)
    parts._kernel = counted = _Counted(parts._kernel, robots)
    parts.advance([100, 700, 1500, 20])
    parts.advance(cfg.steps)
    assert max(counted.work) <= cap and sum(counted.work) == len(seeds) * cfg.steps * robots
    assert parts.clocks.tolist() == [cfg.steps] * len(seeds)
    for a, b in zip(parts.run(), whole.run()):
        pd.testing.assert_frame_equal(a.robots, b.robots, check_exact=True)
        pd.testing.assert_frame_equal(a.history, b.history, check_exact=True)


def test_the_worlds_of_a_batch_share_the_sampling_tables_and_own_the_rest(cfg):
    sims = Simulations(cfg, SEEDS)
    a, b = sims.sims[0].world, sims.sims[1].world
    for name in build.SHARED_TABLES:
        assert getattr(a, name) is getattr(b, name)  # 16 bytes per step of the run, held once
    assert not np.shares_memory(a.bparams, b.bparams) and not np.shares_memory(a.balance, b.balance)


@pytest.mark.parametrize("alpha", [0.0, 1.0, 1.4, 2.0])  # exponents -1 and -2 take numpy's fast paths
@pytest.mark.parametrize("steps", [1, 15000, 3_000_000])  # the last: the guide table in several chunks
def test_the_step_length_tables_are_the_plain_formula_bit_for_bit(alpha, steps):
    from infomarket.engine import params

    k = np.arange(1, steps + 2, dtype=np.float64)
    p = k ** -(alpha + 1.0)
    cdf = np.cumsum(p / p.sum())
    cdf[-1] = 1.0
    guide = np.searchsorted(cdf, np.arange(len(cdf)) / len(cdf), side="right").astype(np.int64)
    assert params.levy_cdf(alpha, steps).tobytes() == cdf.tobytes()
    assert params.guide_table(cdf).tobytes() == guide.tobytes()


#: A child: steps a small batch of fig4C runs (build, advance, reset one, advance) and prints every
#: function numba compiled meanwhile (``numba:compile`` fires on a compile, not on a load from the cache).
_BATCH_CHILD = r"""
import json
from numba.core import event

compiled = set()


class Compiles(event.Listener):
    def on_start(self, ev):
        pass

    def on_end(self, ev):
        f = ev.data["dispatcher"].py_func
        compiled.add(f"{f.__module__}.{f.__qualname__}")


event.register("numba:compile", Compiles())
from infomarket.config import load_experiment
from infomarket.engine.batch import Simulations

runs = Simulations(load_experiment("fig4C").with_overrides(steps=40, transitory=10), [3, 41])
runs.advance(20)
runs.reset(1, 5)
runs.advance(40)
print(json.dumps(sorted(compiled)))
"""


def test_a_batch_in_a_process_that_finds_its_code_cached_compiles_nothing(procs):
    """Every pool worker and command steps its runs in batches: what a batch needs beyond the kernel (the
    driver, its typed lists of views and generators) must load from the disk cache, not compile again in
    every process (numba compiled a typed list's methods per process and item type, uncached)."""
    first = procs.run([sys.executable, "-c", _BATCH_CHILD])  # compiles what no earlier process cached
    assert first.returncode == 0, first.stderr[-2000:]
    again = procs.run([sys.executable, "-c", _BATCH_CHILD])
    assert again.returncode == 0, again.stderr[-2000:]
    assert json.loads(again.stdout.splitlines()[-1]) == []
