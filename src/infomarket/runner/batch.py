"""Run one experiment many times, in this process or a local process pool.

Run ``i`` uses ``seeds.run_seed(master, i, condition)``: rerunning any single run alone with that seed
gives exactly its rows here, whichever executor ran it.
"""
from __future__ import annotations

import multiprocessing
import os
import sys
import time
from concurrent.futures import Executor, ProcessPoolExecutor
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .. import plugins
from ..config.schema import Experiment
from ..engine.seeds import run_seed
from ..engine.simulation import Simulation, simulate


@dataclass
class BatchResult:
    robots: pd.DataFrame
    history: pd.DataFrame
    compile_seconds: float
    run_seconds: float
    steps: int

    @property
    def env_steps_per_second(self) -> float:
        runs = self.robots["run"].nunique() if len(self.robots) else 0
        return runs * self.steps / self.run_seconds if self.run_seconds > 0 else float("inf")


def _one(cfg: Experiment, run: int, seed: int, steps: int | None, history_every: int | None):
    r = simulate(cfg, seed, steps=steps, history_every=history_every)
    robots = r.robots
    robots.insert(0, "run", np.int64(run))
    hist = r.history
    if len(hist):
        hist.insert(0, "run", np.int64(run))
        hist.insert(1, "seed", np.uint64(seed))
    return robots, hist, r.compile_seconds, r.run_seconds, r.steps


def _chunk(cfg: Experiment, items: list[tuple[int, int]], steps, history_every):
    for entry in cfg.plugins:  # rules registered by plugins must exist in this worker too
        plugins.load(entry)
    return [_one(cfg, run, seed, steps, history_every) for run, seed in items]


def default_workers() -> int:
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1)


def warm(cfg: Experiment) -> None:
    """Compile (or load) the configuration's kernel in this process, so forked workers inherit it."""
    Simulation(cfg, 0)  # loads every compiled entry point (view constructor, step loop)


def process_pool(workers: int) -> ProcessPoolExecutor:
    """A local pool.  On Linux workers are forked, so kernels already loaded here cost them nothing."""
    ctx = multiprocessing.get_context("fork") if sys.platform.startswith("linux") else None
    return ProcessPoolExecutor(max_workers=workers, mp_context=ctx)


def run_batch(cfg: Experiment, runs: int, master_seed: int, *, steps: int | None = None,
              history_every: int | None = None, workers: int = 1, condition: int = 0,
              on_done=None, executor: Executor | None = None) -> BatchResult:
    """Run ``runs`` independent runs; ``on_done(k)`` is called as runs complete (for progress).
    ``executor`` (any concurrent.futures Executor) is used if given, else a local pool of ``workers``."""
    items = [(i, run_seed(master_seed, i, condition)) for i in range(runs)]
    outputs = []
    warm_seconds = 0.0
    if executor is None and (workers <= 1 or runs == 1):
        for it in items:
            outputs.append(_one(cfg, *it, steps, history_every))
            if on_done:
                on_done(1)
    else:
        t0 = time.perf_counter()
        warm(cfg)
        warm_seconds = time.perf_counter() - t0
        n_workers = workers if executor is None else max(workers, 1)
        size = max(1, min(8, runs // (n_workers * 4) or 1))  # batch runs per task: little overhead
        chunks = [items[k:k + size] for k in range(0, runs, size)]
        pool = executor or process_pool(workers)
        try:
            futures = [pool.submit(_chunk, cfg, c, steps, history_every) for c in chunks]
            for f in futures:
                res = f.result()
                outputs.extend(res)
                if on_done:
                    on_done(len(res))
        finally:
            if executor is None:
                pool.shutdown(cancel_futures=True)
    robots = pd.concat([o[0] for o in outputs], ignore_index=True)
    hists = [o[1] for o in outputs if len(o[1])]
    history = pd.concat(hists, ignore_index=True) if hists else pd.DataFrame()
    compile_seconds = max([warm_seconds] + [o[2] for o in outputs])
    return BatchResult(robots, history, compile_seconds, sum(o[3] for o in outputs), outputs[0][4])
