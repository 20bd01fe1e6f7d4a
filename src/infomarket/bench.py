"""Benchmark: single-process runs after compilation; medians of several runs per setup.

Performance is measured here (``infomarket bench``, ``make bench``), never asserted in tests.
"""
from __future__ import annotations

import statistics
import time

from . import __version__
from .config import load_experiment
from .engine.seeds import run_seed
from .engine.simulation import Simulation


def run_bench(setups, *, steps: int = 15000, repeats: int = 7) -> dict:
    """Per setup: env-steps per second (median over ``repeats`` runs) and the time to get the compiled
    kernel ready in this process: a compilation, or a load from numba's disk cache (then
    ``kernel_from_disk_cache`` is true; a kernel already loaded in this process counts as cached)."""
    out = {}
    for name in setups:
        cfg = load_experiment(name).with_overrides(steps=steps)
        t0 = time.perf_counter()
        first = Simulation(cfg, run_seed(cfg.seed, 0))
        compile_seconds = time.perf_counter() - t0
        loaded_from_disk = bool(sum(first._kernel.run_steps.stats.cache_hits.values()))
        del first
        times = []
        for i in range(repeats):
            sim = Simulation(cfg, run_seed(cfg.seed, i))
            sim.run()
            times.append(sim.run_seconds)
        med = statistics.median(times)
        out[name] = {"steps_per_second": steps / med, "seconds_per_run": med,
                     "compile_seconds": compile_seconds, "kernel_from_disk_cache": loaded_from_disk,
                     "robots": cfg.swarm.robots, "steps": steps,
                     "repeats": repeats, "min_seconds": min(times), "max_seconds": max(times)}
    return {"version": __version__, "setups": out}


def run_scaling(experiment: str = "fig2A", runs: int = 32, steps: int = 15000) -> dict:
    """Steady-state sweep throughput (env-steps/s) with 1 and 2 local workers and a local Dask cluster
    of 2: each executor's workers are started and have the kernel loaded before the clock starts (the
    local pool's forked workers inherit it from the parent; Dask workers load it from the disk cache)."""
    import tempfile

    from .runner.batch import warm
    from .runner.sweep import plan, run_sweep
    from .store import Store

    cfg = load_experiment(experiment).with_overrides(steps=steps)
    conds = plan([cfg], runs=runs)
    out = {}
    setups = [("local_1", {"workers": 1}), ("local_2", {"workers": 2}), ("dask_local_2", None)]
    for name, kw in setups:
        with tempfile.TemporaryDirectory() as tmp:
            if kw is None:
                from distributed import Client, LocalCluster

                with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, Client(cluster) as client:
                    client.run(warm, cfg)  # workers up, kernel loaded, before the clock starts
                    t0 = time.perf_counter()
                    run_sweep(conds, Store(tmp), client=client)
                    wall = time.perf_counter() - t0
            else:
                t0 = time.perf_counter()
                run_sweep(conds, Store(tmp), **kw)
                wall = time.perf_counter() - t0
        out[name] = {"env_steps_per_second": runs * steps / wall, "wall_seconds": wall}
    out["speedup_2_vs_1"] = out["local_2"]["env_steps_per_second"] / out["local_1"]["env_steps_per_second"]
    out["dask_vs_local_2"] = out["dask_local_2"]["env_steps_per_second"] / out["local_2"]["env_steps_per_second"]
    return {"experiment": experiment, "runs": runs, "steps": steps, **out}
