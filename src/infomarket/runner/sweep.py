"""Sweeps: every run of every condition, spread over an executor, appended to a results store.

Runs are batched into tasks (several runs of one condition) so scheduling overhead stays small; the
parent process writes each finished task to the store as one part, so the store has a single writer
whichever executor computed the runs (a local process pool, or ``dask.distributed``).  Resuming is the
default: runs already committed in the store are skipped, orphan parts of a crash are removed first.

Before anything runs, the sweep takes the store's lock (one writer at a time), checks every committed part
against its checksum (a damaged store is refused until ``infomarket store repair``), and checks that the
store holds nothing made with another configuration or another master seed.  A run that raises is
committed as ``failed`` with its error text; the others go on (``retry_failed`` reruns those).
"""
from __future__ import annotations

import hashlib
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
from ..store.results import FAILED, OK
from .batch import RunOutput, _chunk, process_pool, warm
from .plan import Condition, conditions


@dataclass(frozen=True)
class Task:
    condition: Condition
    runs: tuple[int, ...]
    #: further (condition, runs) committed in the same part: the points of a sampled design, which have
    #: a run or two each, are grouped so that a study of thousands of points is not thousands of parts
    more: tuple[tuple[Condition, tuple[int, ...]], ...] = ()

    @property
    def members(self) -> list[tuple[Condition, tuple[int, ...]]]:
        return [(self.condition, self.runs), *self.more]

    @property
    def size(self) -> int:
        return sum(len(r) for _, r in self.members)

    @property
    def part_id(self) -> str:
        c = self.condition
        if self.more:  # named by its members, so a resumed sweep's regrouped parts never collide
            ids = ";".join(f"{m.id}:{','.join(map(str, r))}" for m, r in self.members)
            return f"{c.experiment}-set-{hashlib.sha256(ids.encode()).hexdigest()[:16]}"
        tag = "base" if c.id == "base" else format(c.number, "x")[:12]
        return f"{c.experiment}-{tag}-{self.runs[0]:05d}-{self.runs[-1]:05d}"


@dataclass
class SweepReport:
    planned: int
    skipped: int
    done: int
    env_steps: int
    wall_seconds: float
    failed: int = 0
    first_error: str = ""
    retried: int = 0

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
    """Refuse to mix runs of different configurations or master seeds under one experiment and condition."""
    seeds: dict[str, int] = {}
    for c in conds:
        if seeds.setdefault(c.experiment, c.master_seed) != c.master_seed:
            raise StoreError(f"{c.experiment}: conditions with two master seeds in one sweep")
    store.claim_seeds(seeds, record=False)  # the recorded seeds first: the clearest message
    existing = store.runs()
    if not existing.empty:
        first = existing.groupby(["experiment", "condition"]).first()
        for c in conds:
            if (c.experiment, c.id) not in first.index:
                continue
            row = first.loc[(c.experiment, c.id)]
            if row.config_hash != c.config.config_hash():
                raise StoreError(f"{store.root}: holds runs of {c.experiment} [{c.id}] made with another "
                                 f"configuration (hash {row.config_hash}, now {c.config.config_hash()}); "
                                 f"use another --out")
            if int(row.seed) != c.seed(int(row.run)):  # also stores made before seeds were recorded
                raise StoreError(f"{store.root}: holds runs of {c.experiment} [{c.id}] made with another master "
                                 f"seed than {c.master_seed}; runs of two seeds would mix in one condition: start "
                                 f"a new store (another --out), or leave --seed out to resume this one")
    store.claim_seeds(seeds)


def make_tasks(conds: list[Condition], done: set, workers: int) -> list[Task]:
    """Missing runs, grouped per condition into tasks of a few runs each."""
    todo = [(c, [r for r in range(c.runs) if (c.experiment, c.id, r) not in done]) for c in conds]
    total = sum(len(r) for _, r in todo)
    size = max(1, min(16, math.ceil(total / max(1, workers * 8))))
    tasks = []
    group: list[tuple[Condition, tuple[int, ...]]] = []  # points of a sampled design, filled up to ``size``

    def flush() -> None:
        if group:
            tasks.append(Task(group[0][0], group[0][1], tuple(group[1:])))
            group.clear()

    for c, runs in todo:
        if c.design is not None and 0 < len(runs) < size:
            if group and (group[0][0].experiment != c.experiment
                          or sum(len(r) for _, r in group) + len(runs) > size):
                flush()
            group.append((c, tuple(runs)))
            continue
        for k in range(0, len(runs), size):
            tasks.append(Task(c, tuple(runs[k:k + size])))
    flush()
    # longest first, so the long runs (Figs. 5-6) do not finish alone at the end on one worker
    tasks.sort(key=lambda t: -t.condition.config.steps * t.size)
    return tasks


def _chunks(calls: list[tuple]) -> list[RunOutput]:
    """``batch._chunk`` for each (configuration, runs, ...) of one task, outputs in order."""
    return [o for call in calls for o in _chunk(*call)]


def _concat(frames: list[pd.DataFrame]) -> pd.DataFrame | None:
    frames = [f for f in frames if len(f)]
    return pd.concat(frames, ignore_index=True) if frames else None


def _frames(task: Task, outputs: list[RunOutput]) -> dict[str, pd.DataFrame | None]:
    """The part's tables: robots, history, events, payments (None when empty) and the runs record."""
    if task.more:
        parts, k = [], 0
        for c, runs in task.members:
            parts.append(_frames(Task(c, runs), outputs[k:k + len(runs)]))
            k += len(runs)
        return {t: _concat([p[t] for p in parts if p[t] is not None])
                for t in ("robots", "history", "events", "payments", "runs")}
    c = task.condition

    def label(df: pd.DataFrame, keys: bool) -> pd.DataFrame:
        df.insert(0, "experiment", c.experiment)
        df.insert(1, "condition", c.id)
        if keys:
            for k, v in c.keys.items():
                df[k] = v
        return df

    robots, hists, events, payments, rows = [], [], [], [], []
    for o, run in zip(outputs, task.runs):
        if o.error is None:
            robots.append(label(o.robots, True))
            if len(o.history):
                meta = o.robots[["robot", "honest", "behaviour"]]
                hists.append(label(o.history.merge(meta, on="robot", how="left"), False))
            if len(o.events):
                events.append(label(o.events, True))
            if len(o.payments):
                payments.append(label(o.payments, True))
        rows.append({"experiment": c.experiment, "condition": c.id, "run": np.int64(run),
                     "seed": np.uint64(c.seed(run)), "master_seed": np.int64(c.master_seed),
                     "config_hash": c.config.config_hash(), "package_version": __version__,
                     "duration_s": o.run_seconds, "steps": o.steps, "transitory": c.config.transitory,
                     "status": OK if o.error is None else FAILED, "error": o.error or "", **c.keys})
    return {"robots": _concat(robots), "history": _concat(hists), "events": _concat(events),
            "payments": _concat(payments), "runs": pd.DataFrame(rows)}


def run_sweep(conds: list[Condition], store: Store, *, workers: int = 1, client=None,
              on_done: Callable[[int], None] | None = None, on_plan: Callable[[int], None] | None = None,
              record_events: bool = False, retry_failed: bool = False) -> SweepReport:
    """Run every missing run of ``conds`` into ``store``.  ``client``: a dask.distributed Client
    (never created here); otherwise a local pool of ``workers`` processes (inline when 1).
    ``record_events``: also store each run's event log; ``retry_failed``: rerun the failed runs."""
    store.create()
    with store.lock():
        store.check()  # a damaged store is refused until repaired
        check_compatible(store, conds)  # first: a refused store is left exactly as it was
        _save_designs(store, conds)  # refuses a store holding another design of the same experiment
        retried = store.uncommit_failed() if retry_failed else 0
        store.remove_orphans()
        report = _run(conds, store, workers, client, on_done, on_plan, record_events)
    report.retried = retried
    return report


def _save_designs(store: Store, conds: list[Condition]) -> None:
    """Keep each sampled design in the store before its points run (``runner.design``)."""
    from .design import save

    for design in {id(c.design): c.design for c in conds if c.design is not None}.values():
        save(store, design)


def _run(conds, store, workers, client, on_done, on_plan, record_events) -> SweepReport:
    done = store.completed_runs()
    tasks = make_tasks(conds, done, workers)
    planned = sum(c.runs for c in conds)
    todo = sum(t.size for t in tasks)
    if on_plan:
        on_plan(todo)
    t0 = time.perf_counter()
    env_steps = 0
    failed: list[RunOutput] = []

    def finished(task: Task, outputs: list[RunOutput]) -> None:
        nonlocal env_steps
        tables = _frames(task, outputs)
        store.write_part(task.part_id, **tables)
        env_steps += int(tables["runs"].steps.sum())
        failed.extend(o for o in outputs if o.error is not None)
        if on_done:
            on_done(task.size)

    def args(t: Task):
        return ([(c.config, [(r, c.seed(r)) for r in runs], None, None, record_events, True)
                 for c, runs in t.members],)

    if tasks and client is None and workers > 1:
        seen = set()
        for c in (c for t in tasks for c, _ in t.members):  # every kernel loaded once here: forked workers
            key = (behaviour_kinds(c.config), c.config.payment.scheme)  # inherit them compiled
            if key not in seen:
                seen.add(key)
                warm(c.config)
    if not tasks:
        pass
    elif client is not None:
        from distributed import as_completed as dask_completed

        for cfg in {(behaviour_kinds(c.config), c.config.payment.scheme): c.config
                    for t in tasks for c, _ in t.members}.values():
            warm(cfg)  # fills the disk cache once instead of in every worker at once
        futures = {client.submit(_chunks, *args(t), pure=False): t for t in tasks}
        for fut in dask_completed(futures):
            finished(futures[fut], fut.result())
    elif workers <= 1:
        for t in tasks:
            finished(t, _chunks(*args(t)))
    else:
        with process_pool(workers) as pool:
            futures = {pool.submit(_chunks, *args(t)): t for t in tasks}
            try:
                for fut in futures_completed(futures):
                    finished(futures[fut], fut.result())
            except BaseException:
                for f in futures:
                    f.cancel()
                raise
    first = failed[0].error.strip().splitlines()[-1] if failed else ""
    return SweepReport(planned, planned - todo, todo, env_steps, time.perf_counter() - t0, len(failed), first)
