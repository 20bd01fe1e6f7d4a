"""Sweeps: every run of every condition, spread over an executor, appended to a results store.

Runs are batched into tasks (several runs of one condition) so scheduling overhead stays small; the
parent process writes each finished task to the store as one part, so the store has a single writer
whichever executor computed the runs (a local process pool, or ``dask.distributed``).  Resuming is the
default: runs already committed in the store are skipped, orphan parts of a crash are removed first.
"""
from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable
from concurrent.futures import as_completed as futures_completed
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .. import __version__
from ..config.schema import Experiment
from ..engine.build import behaviour_kinds
from ..store import Store, StoreError
from .batch import _chunk, process_pool, warm
from .plan import Condition, conditions


@dataclass(frozen=True)
class Task:
    condition: Condition
    runs: tuple[int, ...]

    @property
    def part_id(self) -> str:
        c = self.condition
        tag = "base" if c.id == "base" else format(c.number, "x")[:12]
        return f"{c.experiment}-{tag}-{self.runs[0]:05d}-{self.runs[-1]:05d}"


@dataclass
class SweepReport:
    planned: int
    skipped: int
    done: int
    env_steps: int
    wall_seconds: float

    @property
    def env_steps_per_second(self) -> float:
        return self.env_steps / self.wall_seconds if self.wall_seconds > 0 else 0.0


def plan(experiments: Iterable[Experiment], *, runs: int | None = None, seed: int | None = None,
         scale: float = 1.0) -> list[Condition]:
    out: list[Condition] = []
    for exp in experiments:
        out += conditions(exp, runs=runs, seed=seed, scale=scale)
    return out


def check_compatible(store: Store, conds: list[Condition]) -> None:
    """Refuse to mix runs of different configurations under the same experiment and condition."""
    existing = store.runs()
    if existing.empty:
        return
    known = existing.groupby(["experiment", "condition"]).config_hash.first().to_dict()
    for c in conds:
        h = known.get((c.experiment, c.id))
        if h is not None and h != c.config.config_hash():
            raise StoreError(f"{store.root}: holds runs of {c.experiment} [{c.id}] made with another "
                             f"configuration (hash {h}, now {c.config.config_hash()}); use another --out")


def make_tasks(conds: list[Condition], done: set, workers: int) -> list[Task]:
    """Missing runs, grouped per condition into tasks of a few runs each."""
    todo = [(c, [r for r in range(c.runs) if (c.experiment, c.id, r) not in done]) for c in conds]
    total = sum(len(r) for _, r in todo)
    size = max(1, min(16, math.ceil(total / max(1, workers * 8))))
    tasks = []
    for c, runs in todo:
        for k in range(0, len(runs), size):
            tasks.append(Task(c, tuple(runs[k:k + size])))
    # longest first, so the long runs (Figs. 5-6) do not finish alone at the end on one worker
    tasks.sort(key=lambda t: -t.condition.config.steps * len(t.runs))
    return tasks


def _frames(task: Task, outputs) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
    c = task.condition
    robots, hists, rows = [], [], []
    for (rob, hist, _compile, run_s, steps), run in zip(outputs, task.runs):
        rob.insert(0, "experiment", c.experiment)
        rob.insert(1, "condition", c.id)
        for k, v in c.keys.items():
            rob[k] = v
        robots.append(rob)
        if len(hist):
            meta = rob[["robot", "honest", "behaviour"]]
            hist = hist.merge(meta, on="robot", how="left")
            hist.insert(0, "experiment", c.experiment)
            hist.insert(1, "condition", c.id)
            hists.append(hist)
        rows.append({"experiment": c.experiment, "condition": c.id, "run": np.int64(run),
                     "seed": np.uint64(c.seed(run)), "config_hash": c.config.config_hash(),
                     "package_version": __version__, "duration_s": run_s, "steps": steps,
                     "transitory": c.config.transitory, "status": "ok", **c.keys})
    history = pd.concat(hists, ignore_index=True) if hists else pd.DataFrame()
    return pd.concat(robots, ignore_index=True), pd.DataFrame(rows), history


def run_sweep(conds: list[Condition], store: Store, *, workers: int = 1, client=None,
              on_done: Callable[[int], None] | None = None, on_plan: Callable[[int], None] | None = None
              ) -> SweepReport:
    """Run every missing run of ``conds`` into ``store``.  ``client``: a dask.distributed Client
    (never created here); otherwise a local pool of ``workers`` processes (inline when 1)."""
    store.create()
    check_compatible(store, conds)  # first: a refused store is left exactly as it was
    store.remove_orphans()
    done = store.completed_runs()
    tasks = make_tasks(conds, done, workers)
    planned = sum(c.runs for c in conds)
    todo = sum(len(t.runs) for t in tasks)
    if on_plan:
        on_plan(todo)
    t0 = time.perf_counter()
    env_steps = 0

    def finished(task: Task, outputs) -> None:
        nonlocal env_steps
        robots, runs, history = _frames(task, outputs)
        store.write_part(task.part_id, robots, runs, history)
        env_steps += int(runs.steps.sum())
        if on_done:
            on_done(len(task.runs))

    def args(t: Task):
        return (t.condition.config, [(r, t.condition.seed(r)) for r in t.runs], None, None)

    if tasks and client is None and workers > 1:
        seen = set()
        for t in tasks:  # load every kernel once here, so forked workers inherit them compiled
            key = (behaviour_kinds(t.condition.config), t.condition.config.payment.scheme)
            if key not in seen:
                seen.add(key)
                warm(t.condition.config)
    if not tasks:
        pass
    elif client is not None:
        from distributed import as_completed as dask_completed

        for t in {(behaviour_kinds(t.condition.config), t.condition.config.payment.scheme): t
                  for t in tasks}.values():
            warm(t.condition.config)  # fills the disk cache once instead of in every worker at once
        futures = {client.submit(_chunk, *args(t), pure=False): t for t in tasks}
        for fut in dask_completed(futures):
            finished(futures[fut], fut.result())
    elif workers <= 1:
        for t in tasks:
            finished(t, _chunk(*args(t)))
    else:
        with process_pool(workers) as pool:
            futures = {pool.submit(_chunk, *args(t)): t for t in tasks}
            try:
                for fut in futures_completed(futures):
                    finished(futures[fut], fut.result())
            except BaseException:
                for f in futures:
                    f.cancel()
                raise
    return SweepReport(planned, planned - todo, todo, env_steps, time.perf_counter() - t0)
