"""Run one experiment many times, in this process or a local process pool.

Run ``i`` uses ``seeds.run_seed(master, i, condition)``: rerunning any single run alone with that seed
gives exactly its rows here, whichever executor ran it.
"""
from __future__ import annotations

import multiprocessing
import os
import sys
import time
import traceback
from concurrent.futures import Executor, ProcessPoolExecutor
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .. import plugins
from ..config.schema import Experiment
from ..seeds import run_seed
from ..engine.simulation import Simulation, simulate


@dataclass
class BatchResult:
    robots: pd.DataFrame
    history: pd.DataFrame
    compile_seconds: float
    run_seconds: float
    steps: int
    #: Items per site per run (terrain setups only: ``Simulation.site_counts``), else empty.
    sites: pd.DataFrame = field(default_factory=pd.DataFrame)

    @property
    def env_steps_per_second(self) -> float:
        runs = self.robots["run"].nunique() if len(self.robots) else 0
        return runs * self.steps / self.run_seconds if self.run_seconds > 0 else float("inf")


class BatchInterrupted(KeyboardInterrupt):
    """Ctrl-C during ``run_batch``: ``result`` holds the runs that had finished (None if none had)."""

    def __init__(self, result: "BatchResult | None", planned: int):
        super().__init__()
        self.result, self.planned = result, planned


@dataclass
class RunOutput:
    """What one run of a batch produced; ``error`` (a traceback's text) when it raised instead."""

    run: int
    seed: int
    robots: pd.DataFrame
    history: pd.DataFrame
    events: pd.DataFrame
    payments: pd.DataFrame = field(default_factory=pd.DataFrame)
    compile_seconds: float = 0.0
    run_seconds: float = 0.0
    steps: int = 0
    error: str | None = None
    sites: pd.DataFrame = field(default_factory=pd.DataFrame)


MAX_ERROR_CHARS = 4000


def _one(cfg: Experiment, run: int, seed: int, steps: int | None, history_every: int | None,
         record_events: bool = False) -> RunOutput:
    r = simulate(cfg, seed, steps=steps, history_every=history_every, record_events=record_events)
    robots = r.robots
    robots.insert(0, "run", np.int64(run))
    hist, events, payments = r.history, r.events, r.payments
    for table in (hist, events, payments):
        if len(table):
            table.insert(0, "run", np.int64(run))
            table.insert(1, "seed", np.uint64(seed))
    sites = pd.DataFrame(r.totals.get("sites", []))
    if len(sites):
        sites.insert(0, "run", np.int64(run))
        sites.insert(1, "seed", np.uint64(seed))
        sites.insert(2, "site", np.arange(len(sites), dtype=np.int64))
    return RunOutput(run, seed, robots, hist, events, payments, r.compile_seconds, r.run_seconds, r.steps,
                     sites=sites)  # events and payments are empty unless recorded


def _failed(run: int, seed: int, exc: BaseException) -> RunOutput:
    text = "".join(traceback.format_exception(exc))[-MAX_ERROR_CHARS:]
    empty = pd.DataFrame()
    return RunOutput(run, seed, empty, empty, empty, empty, error=text)


def _chunk(cfg: Experiment, items: list[tuple[int, int]], steps, history_every, record_events=False,
           isolate=False) -> list[RunOutput]:
    """Run ``items`` (run, seed) in this process.  ``isolate``: a run that raises becomes a RunOutput
    with its error text, and the others still run (sweeps); otherwise the exception propagates."""
    try:
        for entry in cfg.plugins:  # rules registered by plugins must exist in this worker too
            plugins.load(entry)
    except Exception as exc:
        if not isolate:
            raise
        return [_failed(run, seed, exc) for run, seed in items]
    out = []
    for run, seed in items:
        try:
            out.append(_one(cfg, run, seed, steps, history_every, record_events))
        except Exception as exc:
            if not isolate:
                raise
            out.append(_failed(run, seed, exc))
    return out


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
    outputs: list[RunOutput] = []
    warm_seconds = 0.0
    try:
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
    except KeyboardInterrupt:
        raise BatchInterrupted(_collect(outputs, warm_seconds) if outputs else None, runs) from None
    return _collect(outputs, warm_seconds)


def _collect(outputs: list[RunOutput], warm_seconds: float) -> BatchResult:
    robots = pd.concat([o.robots for o in outputs], ignore_index=True)
    hists = [o.history for o in outputs if len(o.history)]
    history = pd.concat(hists, ignore_index=True) if hists else pd.DataFrame()
    compile_seconds = max([warm_seconds] + [o.compile_seconds for o in outputs])
    sites = [o.sites for o in outputs if len(o.sites)]
    return BatchResult(robots, history, compile_seconds, sum(o.run_seconds for o in outputs), outputs[0].steps,
                       pd.concat(sites, ignore_index=True) if sites else pd.DataFrame())
