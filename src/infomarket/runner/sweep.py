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

import json
import time
from collections.abc import Callable, Iterable
from concurrent.futures import Executor
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .._version import __version__
from ..config import sizes
from ..config.schema import Experiment
from ..errors import UsageError
from ..store import Store, StoreError
from ..store.results import FAILED, OK
from .execute import TOGETHER, RunOutput, Task, execute, local_executor, make_tasks, preflight
from .plan import Condition, conditions

__all__ = ["SweepReport", "Task", "check_compatible", "make_tasks", "plan", "run_sweep", "sweep_locked"]


@dataclass
class SweepReport:
    """What a sweep did: runs planned, skipped (already in the store), done and failed, the env-steps run and the
    time taken."""
    planned: int
    skipped: int
    done: int
    env_steps: int
    wall_seconds: float
    failed: int = 0
    first_error: str = ""
    #: failed runs whose error is a user's rule's (RuleRunError: the rule, its file and line, the step)
    rule_errors: int = 0
    retried: int = 0
    #: seconds spent compiling or loading kernels: the warm-up, or the longest a run spent on it
    compile_seconds: float = 0.0
    #: seconds the runs made now spent running (summed over workers: per-core speed is env_steps / this)
    run_seconds: float = 0.0

    @property
    def env_steps_per_second(self) -> float:
        """Environment steps (runs x steps) per wall-clock second of the sweep (0 when nothing ran)."""
        return self.env_steps / self.wall_seconds if self.wall_seconds > 0 else 0.0


def plan(experiments: Iterable[Experiment], *, runs: int | None = None, seed: int | None = None,
         scale: float = 1.0) -> list[Condition]:
    """The conditions of every experiment, in order, with the runs, seed and scale overrides applied
    (``runner.plan.conditions``)."""
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
    if not existing.empty:  # the first run of each of these conditions (a search's store holds thousands)
        existing = existing[existing.condition.isin({c.id for c in conds})]
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


def _concat(frames: list[pd.DataFrame]) -> pd.DataFrame | None:
    frames = [f for f in frames if len(f)]
    return pd.concat(frames, ignore_index=True) if frames else None


#: The part's tables that hold one frame per run (``_frames``), and whether they take the condition's keys.
_PER_RUN = {"robots": True, "history": False, "events": True, "payments": True, "sites": True, "chain": True}


def _frames(task: Task, outputs: list[RunOutput]) -> dict[str, pd.DataFrame | None]:
    """The part's tables (None when empty): robots, history, events, payments, sites, the configurations
    the runs used (one row per condition: ``Store.config`` rebuilds them) and the runs record.  The runs'
    frames of each table are concatenated once and labelled with their conditions' columns by repetition
    (labelling each run's frame, or each condition's, cost more than a short run itself)."""
    members = task.members
    if not _alike(members):  # conditions with other keys or key types: each labelled alone, as pandas types it
        parts, k = [], 0
        for c, runs in members:
            parts.append(_frames(Task(c, runs), outputs[k:k + len(runs)]))
            k += len(runs)
        return {t: _concat([p[t] for p in parts if p[t] is not None]) for t in parts[0]}
    # table -> (the runs' frames, the condition of each)
    frames: dict[str, tuple[list, list]] = {t: ([], []) for t in _PER_RUN}
    rows, configs, k = [], [], 0
    for c, runs in members:
        for o, run in zip(outputs[k:k + len(runs)], runs):
            if o.error is None:
                history = o.history
                if len(history):
                    history = history.merge(o.robots[["robot", "honest", "behaviour"]], on="robot", how="left")
                for t, df in (("robots", o.robots), ("history", history), ("events", o.events),
                              ("payments", o.payments), ("sites", o.sites), ("chain", o.chain)):
                    if len(df):
                        frames[t][0].append(df)
                        frames[t][1].append(c)
            rows.append({"experiment": c.experiment, "condition": c.id, "run": np.int64(run),
                         "seed": np.uint64(c.seed(run)), "master_seed": np.int64(c.master_seed),
                         "config_hash": c.config.config_hash(), "package_version": __version__,
                         "duration_s": o.run_seconds, "steps": o.steps, "transitory": c.config.transitory,
                         "status": OK if o.error is None else FAILED, "error": o.error or "", **c.keys})
        configs.append({"experiment": c.experiment, "condition": c.id, "config_hash": c.config.config_hash(),
                        "config": config_json(c.config)})
        k += len(runs)
    out = {t: _labelled(*frames[t], keys) for t, keys in _PER_RUN.items()}
    return {**out, "configs": pd.DataFrame(configs), "runs": pd.DataFrame(rows)}


def _alike(members) -> bool:
    """Do these conditions have the same keys, each with values of one type (so one column types them all
    as pandas typed each condition's)?"""
    names = [tuple(c.keys) for c, _ in members]
    return all(n == names[0] for n in names) and all(
        len({type(c.keys[k]) for c, _ in members}) == 1 for k in names[0])


def _labelled(frames: list[pd.DataFrame], conditions: list, keys: bool) -> pd.DataFrame | None:
    """``frames`` as one, with the experiment, condition and (``keys``) key columns of each frame's condition."""
    if not frames:
        return None
    df = pd.concat(frames, ignore_index=True)
    counts = [len(f) for f in frames]
    df.insert(0, "experiment", np.repeat(np.array([c.experiment for c in conditions], dtype=object), counts))
    df.insert(1, "condition", np.repeat(np.array([c.id for c in conditions], dtype=object), counts))
    if keys:
        for k in conditions[0].keys:
            df[k] = np.repeat(np.array([c.keys[k] for c in conditions]), counts)
    return df


def config_json(cfg: Experiment) -> str:
    """The configuration as JSON text, as ``Store.config`` reads it back (``config.load.validate``)."""
    return json.dumps(cfg.model_dump(mode="json"), sort_keys=True)


def run_sweep(conds: list[Condition], store: Store, *, workers: int = 1, executor: Executor | None = None,
              on_done: Callable[[int], None] | None = None, on_plan: Callable[[int], None] | None = None,
              record_events: bool = False, retry_failed: bool = False,
              on_part: Callable[[dict], None] | None = None) -> SweepReport:
    """Run every missing run of ``conds`` into ``store``: on ``executor`` (any ``concurrent.futures``
    Executor, e.g. ``process_pool(n)`` or a Dask ``client.get_executor(pure=False)``; never shut down
    here), else inline when ``workers`` is 1, else on a local pool of ``workers`` processes made here.
    ``record_events``: also store each run's event log; ``retry_failed``: rerun the failed runs.
    The store is locked throughout (a second writer gets StoreError at once, before writing anything).
    A kernel that a user's rule keeps from compiling is refused first (RuleRunError), nothing written.
    ``on_part(tables)``: called with each part's tables once it is committed (what a caller that reads the
    runs back at once would otherwise read from the store)."""
    refuse_too_big(conds, workers, executor, record_events)
    preflight(c.config for c in remaining(conds, store))
    with store.writing():
        return sweep_locked(conds, store, workers=workers, executor=executor, on_done=on_done, on_plan=on_plan,
                            record_events=record_events, retry_failed=retry_failed, on_part=on_part)


def remaining(conds: list[Condition], store: Store) -> list[Condition]:
    """The conditions of ``conds`` with a run not yet committed in ``store`` (read without the lock: a guess
    that only decides which kernels are compiled ahead; the sweep decides what to run under the lock).  A
    command over a finished store then loads and compiles no kernel at all: a study's rerun rewrites its
    report from the store (a defence study's rerun compiled every family's kernels again: 1 458 s)."""
    if not store.exists():
        return list(conds)
    try:
        done = store.completed_runs()
    except Exception:  # noqa: BLE001 - a damaged store: the sweep's own checks say so, under the lock
        return list(conds)
    return [c for c in conds if any((c.experiment, c.id, r) not in done for r in range(c.runs))]


def refuse_too_big(conds: list[Condition], workers: int, executor: Executor | None, record_events: bool) -> None:
    """Refuse (UsageError, before anything is written) runs whose worlds would not fit in memory at once:
    each local worker process (one: an executor's own processes are counted one by one) steps up to
    ``TOGETHER`` runs of a condition at once (one at a time when events are recorded)."""
    processes = 1 if executor is not None else max(1, min(workers, sum(c.runs for c in conds)))
    for c in conds:
        worlds = 1 if record_events else min(TOGETHER, c.runs)
        why = sizes.held_too_big(c.config, worlds, processes, record_events=record_events)
        if why:
            raise UsageError(f"{c.experiment} [{c.id}]: {why}")


def sweep_locked(conds: list[Condition], store: Store, *, workers: int = 1, executor: Executor | None = None,
                 on_done: Callable[[int], None] | None = None, on_plan: Callable[[int], None] | None = None,
                 record_events: bool = False, retry_failed: bool = False,
                 on_part: Callable[[dict], None] | None = None) -> SweepReport:
    """``run_sweep`` for a caller already inside ``store.writing()`` (``runner.run`` decides what to keep
    under the same lock)."""
    store.check()  # a damaged store is refused until repaired
    check_compatible(store, conds)  # first: a refused store is left exactly as it was
    _save_designs(store, conds)  # refuses a store holding another design of the same experiment
    retried = store.uncommit_failed() if retry_failed else 0
    store.remove_orphans()
    report = _run(conds, store, workers, executor, on_done, on_plan, record_events, on_part)
    report.retried = retried
    return report


def _save_designs(store: Store, conds: list[Condition]) -> None:
    """Keep each sampled design in the store before its points run (``runner.design``)."""
    from .design import save  # sampled designs only: design imports SALib, which is slow to import

    for design in {id(c.design): c.design for c in conds if c.design is not None}.values():
        save(store, design)


def _run(conds, store, workers, executor, on_done, on_plan, record_events, on_part=None) -> SweepReport:
    tasks = make_tasks(conds, store.completed_runs(), workers)
    planned = sum(c.runs for c in conds)
    todo = sum(t.size for t in tasks)
    if on_plan:
        on_plan(todo)
    t0 = time.perf_counter()
    env_steps, compile_seconds, run_seconds = 0, 0.0, 0.0
    failed: list[RunOutput] = []

    def finished(task: Task, outputs: list[RunOutput]) -> None:
        nonlocal env_steps, compile_seconds, run_seconds
        if store.part_path("runs", task.part_id).exists():  # handed again after a stop cut its commit short
            return
        tables = _frames(task, outputs)
        keys = dict.fromkeys(k for c, _ in task.members for k in c.keys)
        store.write_part(task.part_id, **tables, keys=keys)
        if on_part:
            on_part(tables)
        runs = tables["runs"]
        assert runs is not None  # a part always has its runs record
        env_steps += int(runs.steps.sum())
        run_seconds += float(runs.duration_s.sum())
        compile_seconds = max([compile_seconds] + [o.compile_seconds for o in outputs])
        failed.extend(o for o in outputs if o.error is not None)
        if on_done:
            on_done(task.size)

    # keep_partial: a stop commits the finished runs of the parts in progress too (runner.partial)
    if executor is not None:
        warm = execute(tasks, finished, executor=executor, record_events=record_events, keep_partial=True)
    else:
        with local_executor(max(1, min(workers, len(tasks)))) as pool:  # never more processes than tasks
            warm = execute(tasks, finished, executor=pool, record_events=record_events, keep_partial=True)
    first = (failed[0].error or "").strip().splitlines()[-1] if failed else ""
    rule_errors = [o for o in failed if o.rule_error]
    if rule_errors:  # the clearest message: a rule's, named with its file, line and step
        first = (rule_errors[0].error or "").strip()
    return SweepReport(planned, planned - todo, todo, env_steps, time.perf_counter() - t0, len(failed), first,
                       compile_seconds=max(warm, compile_seconds), run_seconds=run_seconds,
                       rule_errors=len(rule_errors))


