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
    """Per setup: env-steps per second (median over ``repeats`` runs) and kernel compile/load time."""
    out = {}
    for name in setups:
        cfg = load_experiment(name).with_overrides(steps=steps)
        t0 = time.perf_counter()
        first = Simulation(cfg, run_seed(cfg.seed, 0))
        compile_seconds = time.perf_counter() - t0
        del first
        times = []
        for i in range(repeats):
            sim = Simulation(cfg, run_seed(cfg.seed, i))
            sim.run()
            times.append(sim.run_seconds)
        med = statistics.median(times)
        out[name] = {"steps_per_second": steps / med, "seconds_per_run": med,
                     "compile_seconds": compile_seconds, "robots": cfg.swarm.robots, "steps": steps,
                     "repeats": repeats, "min_seconds": min(times), "max_seconds": max(times)}
    return {"version": __version__, "setups": out}
