"""The paper's setups in one process after compilation: medians of several runs per setup, each set
beside this machine's floor (``bench.floor``) measured in the same run."""
from __future__ import annotations

import statistics
import time

from .._version import __version__
from ..config import load_experiment
from ..seeds import run_seed
from ..engine.simulation import Simulation
from .floor import floor_seconds, floor_summary


#: A setup named ``NAME+chain`` is the shipped setup NAME with every robot a blockchain node
#: (docs/chain-model.md): Proof-of-Authority blocks every 10 steps, out-of-turn signers 5 steps later,
#: transactions and blocks spreading over the robots' own links only.  Its ``ratio_to_instant`` is its
#: env-steps/s over NAME's when NAME is benched in the same run.
CHAIN_SUFFIX = "+chain"
CHAIN_BENCH = {"consensus": "poa", "period": 10, "out_of_turn_delay": 5}


#: Signers of the swarm-size benchmark with the chain on (``chain_at``): a Clique-like authority set of the
#: paper's swarm size, whatever the number of robots (every robot is still a node with its own view).
CHAIN_SCALING_SIGNERS = 25


def chain_at(robots: int) -> dict:
    """The ``[chain]`` section of ``bench --robots N --chain``: ``CHAIN_BENCH`` with the first
    ``CHAIN_SCALING_SIGNERS`` robots as the signers (all of them up to 25 robots)."""
    return {**CHAIN_BENCH, "signers": list(range(min(robots, CHAIN_SCALING_SIGNERS)))}


def bench_config(name: str, steps: int):
    """The configuration a bench setup runs: a shipped experiment, or one with the chain model on."""
    if name.endswith(CHAIN_SUFFIX):
        return load_experiment(name[:-len(CHAIN_SUFFIX)]).with_overrides(steps=steps, chain=CHAIN_BENCH)
    return load_experiment(name).with_overrides(steps=steps)


def run_bench(setups, *, steps: int = 15000, repeats: int = 7) -> dict:
    """Per setup: env-steps per second (median over ``repeats`` runs) and the time to get the compiled
    kernel ready in this process: a compilation, or a load from numba's disk cache (then
    ``kernel_from_disk_cache`` is true; a kernel already loaded in this process counts as cached).

    The runs go in rounds: each round times the floor once, then one run of every setup.  A change in the
    machine's speed during the bench (another process starting, a clock stepping down) then moves the
    floor and the setups alike, and the ratios stay comparable; timed one after the other, the floor
    after all the setups, a load change between them moved a run's ratios by up to 20 %."""
    out, cfgs = {}, {}
    for name in setups:
        cfg = bench_config(name, steps)
        t0 = time.perf_counter()
        first = Simulation(cfg, run_seed(cfg.seed, 0))
        compile_seconds = time.perf_counter() - t0
        loaded_from_disk = bool(sum(first._kernel.step_all.stats.cache_hits.values()))
        del first
        cfgs[name] = cfg
        out[name] = {"compile_seconds": compile_seconds, "kernel_from_disk_cache": loaded_from_disk,
                     "robots": cfg.swarm.robots, "steps": steps, "repeats": repeats}
    floor_seconds(0, 1)  # compiles or loads the floor kernel; not timed
    floor_times: list[float] = []
    times: dict[str, list[float]] = {name: [] for name in setups}
    for i in range(repeats):
        floor_times.append(floor_seconds(i + 1, steps))
        for name, cfg in cfgs.items():
            sim = Simulation(cfg, run_seed(cfg.seed, i))
            sim.run()
            times[name].append(sim.run_seconds)
    for name, r in out.items():
        med = statistics.median(times[name])
        r.update({"steps_per_second": steps / med, "seconds_per_run": med,
                  "min_seconds": min(times[name]), "max_seconds": max(times[name])})
    floor = floor_summary(floor_times, 25, steps)
    for r in out.values():
        r["ratio_to_floor"] = floor["steps_per_second"] / r["steps_per_second"]
    for name, r in out.items():
        base = name[:-len(CHAIN_SUFFIX)]
        if name.endswith(CHAIN_SUFFIX) and base in out:
            r["ratio_to_instant"] = r["steps_per_second"] / out[base]["steps_per_second"]
    return {"version": __version__, "setups": out, "floor": floor}
