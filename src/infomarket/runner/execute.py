"""The one way infomarket runs many simulations: tasks of runs handed to any ``concurrent.futures.Executor``.

A task is some runs of one condition (or of a few points of a sampled design); ``execute`` submits every
task to the executor, hands each finished task's outputs to ``finished`` in this process (which writes
them to a results store, or keeps them in memory for ``run_batch``), and stops cleanly on Ctrl-C.  The
executor may be ``InlineExecutor`` (this process, one task at a time), a local ``process_pool``, or a
Dask client's ``client.get_executor(pure=False)``.

Before any task is submitted to another process, ``warm_up`` compiles (or loads from the disk cache)
each distinct kernel once, keyed on ``engine.specialise.kernel_id``: forked pool workers inherit the
loaded kernels, and Dask workers find them in the disk cache instead of all compiling at once.

Run ``r`` of a condition uses ``seeds.run_seed(master, r, condition_number)``: rerunning it alone with
that seed gives exactly its rows, whichever executor ran it.
"""
from __future__ import annotations

import math
import multiprocessing
import os
import shutil
import sys
import tempfile
import time
import traceback
from collections.abc import Callable, Iterable
from concurrent.futures import Executor, Future, ProcessPoolExecutor, as_completed
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from .. import interrupts, plugins
from ..config.schema import Experiment
from ..engine.batch import Simulations
from ..engine.compiling import kernel_marker
from ..engine.simulation import Simulation
from ..engine.specialise import kernel_id
from ..checks import explain, explain_compile_failure
from ..errors import InfomarketError, RuleRunError
from .partial import Keep
from .plan import Condition

MAX_ERROR_CHARS = 4000
#: Runs of one configuration stepped together in one compiled call (their worlds are alive at once; a
#: run that records events keeps its whole log, so those go one at a time).
TOGETHER = 16


class RunFailed(InfomarketError, RuntimeError):
    """A run raised where its caller cannot go on without it (``run_batch``); the message holds its
    traceback's text."""


# ---------------------------------------------------------------------------------------- one run
@dataclass
class RunOutput:
    """What one run produced; ``error`` (a traceback's text) when it raised instead."""

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
    #: the chain model's measures, one row (runs with ``[chain]`` only), else empty
    chain: pd.DataFrame = field(default_factory=pd.DataFrame)
    #: the error is a user's rule's (RuleRunError): the message names the rule, its file and line, the step
    rule_error: bool = False


def run_one(cfg: Experiment, run: int, seed: int, record_events: bool = False) -> RunOutput:
    """Run ``cfg`` once with ``seed`` (its own ``steps`` and ``history_every``); tables get ``run``/``seed``.
    An error raised inside the compiled step (a rule's) becomes a RuleRunError naming the rule, its file
    and line, and the step (``checks.explain_run_failure``) when one rule reproduces it alone."""
    sim = None
    try:
        sim = Simulation(cfg, seed, record_events=record_events)
        r = sim.run()
    except Exception as exc:  # a rule's error (or an error bit a rule set): named, else as it is
        raise explain(cfg, seed, exc, sim, record_events=record_events) from exc
    return output(r, run)


def run_together(cfg: Experiment, items: list[tuple[int, int]], record_events: bool = False) -> list[RunOutput]:
    """Runs ``items`` (run, seed) of ``cfg`` stepped back to back in one compiled call
    (``engine.batch.Simulations``: one kernel load, worlds that start with the room earlier runs
    grew to); the same rows as ``run_one`` for each.  Raises the first run's error, named."""
    sims = Simulations(cfg, [seed for _, seed in items], record_events=record_events)
    return [output(r, run) for r, (run, _) in zip(sims.run(), items)]


def output(r, run: int) -> RunOutput:
    """A run's ``Result`` as the store keeps it: every table labelled with ``run`` (and ``seed``)."""
    seed = r.seed
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
    chain = pd.DataFrame()
    if "chain" in r.totals:  # the chain model's measures (docs/chain-model.md): per robot and per run
        robots["gas_paid"], robots["mean_lag"], chain = chain_tables(r.totals["chain"], run, seed)
    return RunOutput(run, seed, robots, hist, events, payments, r.compile_seconds, r.run_seconds, r.steps,
                     sites=sites, chain=chain)  # events and payments are empty unless recorded


def chain_tables(m: dict, run: int, seed: int) -> tuple[np.ndarray, np.ndarray, pd.DataFrame]:
    """A chain run's measures (``Simulation.chain_measures``) as the store keeps them: each robot's gas paid
    and mean view lag (robots table), and the run's row of the chain table."""
    gas, lag = np.asarray(m["gas_paid"], np.float64), np.asarray(m["mean_lag"], np.float64)
    row = {"run": np.int64(run), "seed": np.uint64(seed),
           **{k: np.int64(m[k]) for k in ("blocks", "height", "forks", "reorgs", "reorganised_tx", "view_reorgs",
                                          "failed_tx", "pending_tx", "deposits_paid")},
           "mean_payment_delay": float(m["mean_payment_delay"]), "gas_paid": float(gas.sum()),
           "mean_lag": float(lag.mean()) if len(lag) else float("nan")}
    return gas, lag, pd.DataFrame([row])


def _failed(run: int, seed: int, exc: BaseException) -> RunOutput:
    if isinstance(exc, RuleRunError):  # one clear message: the rule, its file and line, the step
        text = str(exc)
    else:
        text = "".join(traceback.format_exception(exc))[-MAX_ERROR_CHARS:]
    empty = pd.DataFrame()
    return RunOutput(run, seed, empty, empty, empty, empty, error=text, rule_error=isinstance(exc, RuleRunError))


def run_chunk(cfg: Experiment, items: list[tuple[int, int]], record_events: bool = False,
              keep: Callable[[list[RunOutput]], None] | None = None) -> list[RunOutput]:
    """Run ``items`` (run, seed) of ``cfg`` in this process, up to ``TOGETHER`` at a time in one compiled
    call (``run_together``); a run that raises becomes a RunOutput with its error text and the others
    still run (its group is run again one run at a time).  Ctrl-C (KeyboardInterrupt) is not caught.
    ``keep(outputs)`` gets each group's outputs as it finishes (``partial.Keep``)."""
    try:
        for entry in cfg.plugins:  # rules registered by plugins must exist in this worker too
            plugins.load(entry)
    except Exception as exc:  # noqa: BLE001 - a plugin that fails to load fails these runs, each recorded
        return [_failed(run, seed, exc) for run, seed in items]
    out: list[RunOutput] = []
    size = 1 if record_events else TOGETHER
    for k in range(0, len(items), size):
        group = items[k:k + size]
        if len(group) > 1:
            try:
                done = run_together(cfg, group, record_events)
            except Exception:  # noqa: BLE001 - run alone, so each run's error is its own and the others go on
                done = _alone(cfg, group, record_events)
        else:
            done = _alone(cfg, group, record_events)
        out += done
        if keep is not None:
            keep(done)
    return out


def _alone(cfg: Experiment, items: list[tuple[int, int]], record_events: bool) -> list[RunOutput]:
    out = []
    for run, seed in items:
        try:
            out.append(run_one(cfg, run, seed, record_events))
        except Exception as exc:  # noqa: BLE001 - a run's error is recorded with it, the others go on
            out.append(_failed(run, seed, exc))
    return out


def run_calls(calls: list[tuple], keep: Callable[[list[RunOutput]], None] | None = None) -> list[RunOutput]:
    """``run_chunk`` for each (configuration, items, record_events) of one task, outputs in order; ``keep``
    gets each finished group of runs (``partial.Keep``)."""
    return [o for cfg, items, record_events in calls for o in run_chunk(cfg, items, record_events, keep)]


# ------------------------------------------------------------------------------------------ tasks
@dataclass(frozen=True)
class Task:
    """One unit of work for a worker, written as one store part: runs of a condition, and more (condition, runs)
    pairs grouped with it."""
    condition: Condition
    runs: tuple[int, ...]
    #: further (condition, runs) in the same task: conditions of a few runs each (the points of a sampled
    #: design, an attack search's candidates) are grouped so that thousands of them are not thousands of
    #: tasks (and store parts)
    more: tuple[tuple[Condition, tuple[int, ...]], ...] = ()

    @property
    def members(self) -> list[tuple[Condition, tuple[int, ...]]]:
        """Every (condition, runs) pair of the task, the first one included."""
        return [(self.condition, self.runs), *self.more]

    @property
    def size(self) -> int:
        """The number of runs in the task, over all its members."""
        return sum(len(r) for _, r in self.members)

    def first(self, count: int) -> Task | None:
        """The task of this one's first ``count`` runs (in its members' order), or None when ``count`` is 0:
        what a stop left finished of it (``partial``)."""
        members, left = [], count
        for c, runs in self.members:
            if left <= 0:
                break
            members.append((c, runs[:left]))
            left -= len(runs)
        if not members:
            return None
        (c, runs), *more = members
        return Task(c, runs, tuple(more))

    @property
    def part_id(self) -> str:
        """The id of the store part this task writes: the experiment, condition and runs, or for a grouped task a
        hash of its members, so a resumed sweep's parts never collide."""
        import hashlib

        c = self.condition
        if self.more:  # named by its members, so a resumed sweep's regrouped parts never collide
            ids = ";".join(f"{m.id}:{','.join(map(str, r))}" for m, r in self.members)
            return f"{c.experiment}-set-{hashlib.sha256(ids.encode()).hexdigest()[:16]}"
        tag = "base" if c.id == "base" else format(c.number, "x")[:12]
        return f"{c.experiment}-{tag}-{self.runs[0]:05d}-{self.runs[-1]:05d}"


#: Tasks per worker a sweep aims at (enough to balance the workers' loads), and the most runs in one task
#: (one store part: its tables are written, checksummed and read back once, whatever the runs in it).
TASKS_PER_WORKER = 4
MAX_TASK = 64


def make_tasks(conds: list[Condition], done: set, workers: int) -> list[Task]:
    """The runs of ``conds`` not in ``done`` ((experiment, condition, run) keys), grouped into tasks of
    up to ``total / (workers x TASKS_PER_WORKER)`` runs (at most ``MAX_TASK``): a condition's runs are
    split into tasks of that size, conditions with fewer runs (the points of a sampled design, the
    candidates of an attack search) share tasks with the next ones of the same experiment.  Longest first."""
    todo = [(c, [r for r in range(c.runs) if (c.experiment, c.id, r) not in done]) for c in conds]
    total = sum(len(r) for _, r in todo)
    size = max(1, min(MAX_TASK, math.ceil(total / max(1, workers * TASKS_PER_WORKER))))
    tasks = []
    group: list[tuple[Condition, tuple[int, ...]]] = []  # conditions of a few runs each, filled up to ``size``

    def flush() -> None:
        if group:
            tasks.append(Task(group[0][0], group[0][1], tuple(group[1:])))
            group.clear()

    for c, runs in todo:
        if 0 < len(runs) < size:
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


# -------------------------------------------------------------------------------------- executors
class InlineExecutor(Executor):
    """Runs each submitted call at once, in this process (``workers = 1``): no pickling, no warm-up."""

    def submit(self, fn, /, *args, **kwargs) -> Future:
        """Run ``fn(*args, **kwargs)`` now and return a finished future holding its result or its exception."""
        future: Future = Future()
        future.set_running_or_notify_cancel()
        try:
            future.set_result(fn(*args, **kwargs))
        except Exception as exc:  # noqa: BLE001 - held by the future; Ctrl-C (KeyboardInterrupt) propagates at once
            future.set_exception(exc)
        return future


def default_workers() -> int:
    """The worker processes to use by default: the CPUs this process may run on (its affinity), at least 1."""
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1)


def process_pool(workers: int) -> ProcessPoolExecutor:
    """A local pool.  On Linux workers are forked, so kernels already loaded here cost them nothing.  Each
    worker is detached (``interrupts.detach``: its own process group, default signal dispositions, dies
    with this process), so Ctrl-C reaches this process alone, which then ends the workers (``stop_pool``)."""
    ctx = multiprocessing.get_context("fork") if sys.platform.startswith("linux") else None
    return ProcessPoolExecutor(max_workers=workers, mp_context=ctx, initializer=interrupts.detach,
                               initargs=(os.getpid(),))


@contextmanager
def local_executor(workers: int):
    """``InlineExecutor`` for one worker, else a local ``process_pool``, shut down on leaving; on Ctrl-C or
    an error the pool's workers are stopped at once instead of first finishing the tasks already queued
    to them (their results could no longer be kept)."""
    if workers <= 1:
        yield InlineExecutor()
        return
    pool = process_pool(workers)
    try:
        yield pool
    except BaseException:
        stop_pool(pool)
        raise
    pool.shutdown(wait=True)


def stop_pool(pool: ProcessPoolExecutor) -> None:
    """Cancel what has not started and end the workers now: SIGKILL to each worker's process group, which
    no worker can delay (a worker inside a kernel runs no Python), then reap them."""
    processes = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for proc in processes:
        interrupts.kill_group(proc.pid)
    for proc in processes:
        proc.join()  # SIGKILL cannot be caught or ignored: each ends


# ---------------------------------------------------------------------------------------- warm-up
def warm(cfg: Experiment) -> None:
    """Compile (or load) the configuration's kernel in this process, so forked workers inherit it: the
    view constructor, the step loop, and the batch driver with its list of views (``run_together``)."""
    Simulations(cfg, [0, 1]).advance(0)


def _distinct_kernels(configs: Iterable[Experiment]) -> dict[str, Experiment]:
    """Kernel id (``kernel_id``) -> the first configuration that runs on it; a configuration whose id fails
    is left out (the runs themselves report it)."""
    seen: dict[str, Experiment] = {}
    for cfg in configs:
        try:
            seen.setdefault(kernel_id(cfg), cfg)
        except Exception:  # noqa: BLE001 - the runs themselves report it
            continue
    return seen


def _try_warm(cfg: Experiment) -> None:
    """``warm`` with the configuration's plugins loaded; an error is left to where it is reported (the runs,
    or the calls after ``compiled_together``'s child)."""
    try:
        for entry in cfg.plugins:
            plugins.load(entry)
        warm(cfg)
    except Exception:  # noqa: BLE001 - met again where it is reported
        pass


def _compile_together(configs: list[Experiment]) -> None:
    """In a command, the kernels of ``configs`` not yet in the cache and their batch drivers compiled in
    one child (``interrupts.compiled_together``), which types the step's helpers once for all of them;
    the calls here then load them."""
    if not configs:  # nothing left to run: no child
        return

    def warm_all() -> None:
        for cfg in configs:
            _try_warm(cfg)

    interrupts.compiled_together(warm_all, [kernel_marker(cfg) for cfg in configs])


def preflight(configs: Iterable[Experiment]) -> None:
    """Compile (or load) each distinct kernel in this process before anything is written or run: a kernel
    that cannot compile because of a user's rule is a RuleRunError naming the rule and what is wrong with
    it (numba's own error points into the generated kernel).  Other errors are left to the runs.  New
    kernels are compiled together first (``_compile_together``)."""
    distinct = list(_distinct_kernels(configs).values())
    _compile_together(distinct)
    for cfg in distinct:
        try:
            Simulation(cfg, 0)  # compiles or loads the kernel (what a warm-up then finds done)
        except InfomarketError:
            raise
        except Exception as exc:  # noqa: BLE001 - a compile error: the rule is named where it can be, else the runs report it
            why = explain_compile_failure(cfg, exc)
            if why:
                raise RuleRunError(f"{cfg.name}: {why}; the step kernel cannot be compiled, nothing was run") from None


def warm_up(configs: Iterable[Experiment]) -> dict[str, float]:
    """Load the kernel of each configuration in this process, once per distinct
    ``engine.specialise.kernel_id`` (behaviours, scheme and terrain: the kernel's real key); returns the
    seconds spent per kernel id.  A configuration whose warm-up raises is left to its runs, which record
    the error as failed runs.  New kernels are compiled together first (``_compile_together``; its seconds
    shared equally among the kernels)."""
    t0 = time.perf_counter()
    distinct = _distinct_kernels(configs)
    _compile_together(list(distinct.values()))
    shared = (time.perf_counter() - t0) / max(len(distinct), 1)
    seconds: dict[str, float] = {}
    for key, cfg in distinct.items():
        t0 = time.perf_counter()
        _try_warm(cfg)
        seconds[key] = shared + time.perf_counter() - t0
    return seconds


# ---------------------------------------------------------------------------------------- execute
def execute(tasks: list[Task], finished: Callable[[Task, list[RunOutput]], None], *,
            executor: Executor | None = None, record_events: bool = False, keep_partial: bool = False) -> float:
    """Run every task on ``executor`` (None: inline, in this process), calling ``finished(task, outputs)``
    here as each completes (in completion order).  Kernels are warmed up once per kernel id before the
    first task goes to another process.  On any exception, Ctrl-C included, tasks not yet started are
    cancelled and the exception propagates; tasks already finished have been handed to ``finished``.
    ``keep_partial``: on a stop, the finished runs of the tasks in progress are handed to ``finished`` too,
    as tasks of those runs (``partial``; inline or on a local pool: a Dask worker's disk is not this one's),
    and a task whose ``finished`` the stop cut short is handed again (``finished`` must allow it).
    Returns the seconds spent warming up."""
    if not tasks:
        return 0.0
    if executor is None or isinstance(executor, InlineExecutor):  # no other process: nothing to warm
        for t in tasks:
            keep, out = (Keep(None, t.size) if keep_partial else None), None
            try:
                out = run_calls(_calls(t, record_events), keep)
                finished(t, out)
            except KeyboardInterrupt:
                if keep is not None:  # the runs finished, or the whole task if the stop cut its commit short
                    _hand_partial(t, keep.kept() if out is None else out, finished)
                raise
            interrupts.check()
        return 0.0
    warm_seconds = sum(warm_up(c.config for t in tasks for c, _ in t.members).values())
    folder = (Path(tempfile.mkdtemp(prefix="infomarket-runs-")) if keep_partial and
              isinstance(executor, ProcessPoolExecutor) else None)
    futures: dict[Future, tuple[Task, Keep | None]] = {}
    handed: set[Future] = set()  # ``finished`` returned for these
    try:
        for k, t in enumerate(tasks):
            keep = Keep(folder / str(k), t.size) if folder is not None else None
            futures[executor.submit(run_calls, _calls(t, record_events), keep)] = (t, keep)
        for fut in as_completed(futures):  # the wait is interrupted by a signal at once
            finished(futures[fut][0], fut.result())
            handed.add(fut)
            interrupts.check()
    except BaseException as exc:  # noqa: BLE001 - the pending runs are cancelled, then it is raised again as a stop
        for f in futures:
            f.cancel()
        if folder is not None and (isinstance(exc, KeyboardInterrupt) or interrupts.requested()):
            _keep_finished(futures, handed, finished)
        interrupts.raise_stopped(exc)
    finally:
        if folder is not None:
            shutil.rmtree(folder, ignore_errors=True)
    return warm_seconds


def _keep_finished(futures: dict, handed: set, finished: Callable[[Task, list[RunOutput]], None]) -> None:
    """After a stop: every task done but not yet handed over, and the finished runs of the others, to
    ``finished``.  A task whose ``finished`` the stop cut short is handed over again: ``finished`` must then
    leave a part it had committed as it is (the sweep's does)."""
    for fut, (task, keep) in futures.items():
        if fut in handed:
            continue
        if fut.done() and not fut.cancelled() and fut.exception() is None:
            finished(task, fut.result())
        elif keep is not None:
            _hand_partial(task, keep.kept(), finished)


def _hand_partial(task: Task, outputs: list[RunOutput], finished: Callable[[Task, list[RunOutput]], None]) -> None:
    part = task.first(len(outputs))
    if part is not None:
        finished(part, outputs)


def _calls(task: Task, record_events: bool) -> list[tuple]:
    return [(c.config, [(r, c.seed(r)) for r in runs], record_events) for c, runs in task.members]
