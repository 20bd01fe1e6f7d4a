"""Several jobs' sweeps on one executor at once, so that no worker waits while one job waits for its slowest run.

A study is many searches (a cell of the attack search, a family of the defence search), and each search is
a sequence of sweeps: a generation, a race's stage, a confirmation.  Run one after another, every sweep
ends with workers idle while its slowest task finishes, and again while the parent writes the store and
the optimiser asks its next points.  ``Feed.map(jobs)`` runs each job (a search) in a thread of its own;
a job's sweep (``Feed.sweep``, called where ``run_sweep`` was) hands its conditions to this process's
main thread and waits.  The main thread alone plans, compiles, submits and writes the store, keeping the
workers fed from the sweeps of every job waiting, the largest task first.

Jobs take turns (a baton): a job's code runs only while no other job's does and never while the main
thread plans or writes, so each job sees what it would see alone (the optimisers reseed NumPy's global
generator before each ask), and a job gives up its turn only where it waits for runs.  Each sweep's tasks
are made as ``run_sweep`` makes them (``make_tasks`` over that sweep's conditions and the runs committed
when it is planned), so the parts hold the runs, with their rows, that the jobs run one after another would
have written; a run that another job's sweep already has in flight is waited for, not made twice.  No run's
seed or configuration depends on the order the jobs' sweeps run in.

Outside ``map`` (in the main thread), ``Feed.sweep`` is ``run_sweep`` on the feed's executor.
"""
from __future__ import annotations

import concurrent.futures as cf
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from .. import interrupts
from ..errors import InternalError
from ..store import Store
from .execute import InlineExecutor, RunOutput, Task, _calls, make_tasks, preflight, run_calls, warm_up
from .sweep import SweepReport, _frames, _save_designs, check_compatible, refuse_too_big, run_sweep

#: Tasks handed to the executor ahead of those running, per worker: enough that the workers do not run dry
#: while a job's turn (its optimiser's work) keeps the main thread from submitting more.
AHEAD = 2
#: The worker count a sweep's tasks are cut for (``make_tasks``): the one the studies' sweeps always used
#: (up to four tasks a sweep), so that a store's parts are the same whatever executor or workers made them.
CUT_FOR = 1
#: How long the main thread waits for a task or a job before looking again (seconds).
POLL = 0.02


@dataclass
class _Sweep:
    """One job's sweep: its conditions, what it waits for, what it made."""

    conds: list
    on_plan: Callable[[int], None] | None
    on_part: Callable[[dict], None] | None
    done: threading.Event = field(default_factory=threading.Event)
    waiting: set = field(default_factory=set)   # (experiment, condition, run) not yet committed
    report: SweepReport | None = None
    error: BaseException | None = None
    failed: list = field(default_factory=list)
    env_steps: int = 0
    run_seconds: float = 0.0
    compile_seconds: float = 0.0
    t0: float = 0.0


@dataclass
class Busy:
    """How busy a study kept its workers: its wall time, the seconds its runs ran (summed over workers),
    the seconds spent compiling or loading kernels before runs, and the worker count."""

    wall_seconds: float = 0.0
    run_seconds: float = 0.0
    compile_seconds: float = 0.0
    workers: int = 1
    runs: int = 0
    env_steps: int = 0
    #: the main thread's own work: checking the store and making a sweep's tasks (``plan``), writing the
    #: finished tasks' parts and handing their rows to the searches (``write``); and the searches' own work
    #: between their sweeps (``searches``: the optimisers, reading their runs' values), each in seconds
    plan_seconds: float = 0.0
    write_seconds: float = 0.0
    search_seconds: float = 0.0

    @property
    def share(self) -> float:
        """The share of the workers' wall time spent in runs (``run_seconds / (wall x workers)``)."""
        return self.run_seconds / (self.wall_seconds * self.workers) if self.wall_seconds > 0 else 0.0

    def as_dict(self) -> dict:
        return {"wall_seconds": self.wall_seconds, "run_seconds": self.run_seconds,
                "compile_seconds": self.compile_seconds, "workers": self.workers, "runs": self.runs,
                "env_steps": self.env_steps, "share_in_runs": self.share, "plan_seconds": self.plan_seconds,
                "write_seconds": self.write_seconds, "search_seconds": self.search_seconds}


class Feed:
    """The sweeps of several jobs on one executor (module docstring).  ``workers``: how many tasks the
    executor runs at once (a local pool's processes, a Dask cluster's threads); ``on_done(k)``: ``k`` runs
    made (called in the main thread, e.g. a progress bar's)."""

    def __init__(self, store: Store, *, workers: int = 1, executor: cf.Executor | None = None,
                 on_done: Callable[[int], None] | None = None):
        self.store, self.workers, self.on_done = store, max(1, workers), on_done
        self.executor = executor if executor is not None else InlineExecutor()
        self.busy = Busy(workers=self.workers)
        self._baton = threading.Lock()
        self._asked: list[_Sweep] = []
        self._open: list[_Sweep] = []
        self._queue: list[tuple[Task, _Sweep]] = []
        self._running: dict[cf.Future, tuple[Task, _Sweep]] = {}
        self._inflight: set = set()
        self._wake = threading.Event()
        self._main: threading.Thread | None = None
        self._since = 0.0
        self._jobs: set[threading.Thread] = set()
        self._ended: BaseException | None = None

    # ------------------------------------------------------------------------------- a job's side
    def sweep(self, conds: list, store: Store | None = None, *, on_plan=None, on_part=None, **_) -> SweepReport:
        """``run_sweep(conds, store, ...)`` for a job of ``map``: its missing runs, made on the feed's executor
        among the other jobs' (the job's turn given up meanwhile); in the main thread, ``run_sweep`` itself."""
        if store is not None and store is not self.store:
            raise InternalError("a feed sweeps into its own store only")
        if self._ended is not None and threading.current_thread() in self._jobs:
            # a job of a map that an error or a stop ended: its thread lives on, but it must not sweep alone
            raise _stopped(self._ended)
        if self._main is None or threading.current_thread() is self._main:
            t0 = time.perf_counter()
            rep = run_sweep(conds, self.store, workers=CUT_FOR, executor=self.executor, on_done=self.on_done,
                            on_plan=on_plan, on_part=on_part)
            self._count(rep.done, rep.env_steps, rep.run_seconds, rep.compile_seconds)
            self.busy.wall_seconds += time.perf_counter() - t0
            return rep
        s = _Sweep(list(conds), on_plan, on_part)
        self._asked.append(s)
        self._wake.set()
        self._turn(False)
        try:
            s.done.wait()
        finally:
            self._turn(True)
        if s.error is not None:
            raise s.error
        assert s.report is not None  # planned before the sweep's first task, settled before done
        return s.report

    # ------------------------------------------------------------------------------ the main side
    def map(self, jobs: list[Callable[[], object]]) -> list:
        """Run ``jobs`` (each a function of no argument), each in a thread of its own taking turns; their
        results in order.  The first job's error (or a stop) ends the others at their next sweep and is raised
        here once the runs in flight are cancelled."""
        if len(jobs) <= 1 or self._main is not None:
            return [job() for job in jobs]
        results: list = [None] * len(jobs)
        errors: list[tuple[float, BaseException]] = []

        def body(k: int) -> None:
            self._turn(True)
            try:
                results[k] = jobs[k]()
            except BaseException as exc:  # noqa: BLE001 - raised in the main thread
                errors.append((time.perf_counter(), exc))
            finally:
                self._wake.set()
                self._turn(False)

        self._main = threading.current_thread()
        t0 = time.perf_counter()
        self._baton.acquire()
        threads = [threading.Thread(target=body, args=(k,), daemon=True, name=f"infomarket-job-{k}")
                   for k in range(len(jobs))]
        self._jobs, self._ended = set(threads), None
        try:
            for t in threads:
                t.start()
            while True:
                if errors:
                    raise min(errors, key=lambda e: e[0])[1]
                self._wake.clear()
                self._plan()
                self._fill()
                if not self._running and not self._queue and not any(t.is_alive() for t in threads):
                    break
                self._baton.release()
                try:
                    self._wait()
                finally:
                    self._baton.acquire()
                self._collect()
                interrupts.check()
        except BaseException as exc:  # noqa: BLE001 - any end, Ctrl-C included, stops every job, then goes on up
            self._ended = exc
            self._stop(exc)
            interrupts.raise_stopped(exc)
        finally:
            self._main = None
            self._baton.release()
            self.busy.wall_seconds += time.perf_counter() - t0
        if errors:
            raise min(errors, key=lambda e: e[0])[1]
        return results

    def _turn(self, take: bool) -> None:
        """A search takes its turn (the baton) or gives it up; the seconds it held it are its own work."""
        if take:
            self._baton.acquire()
            self._since = time.perf_counter()
        else:
            self.busy.search_seconds += time.perf_counter() - self._since
            self._baton.release()

    def _wait(self) -> None:
        if self._wake.is_set():
            return
        if self._running:
            cf.wait(list(self._running), timeout=POLL, return_when=cf.FIRST_COMPLETED)
        else:
            self._wake.wait(POLL)

    def _plan(self) -> None:
        """Plan every sweep asked since the last look: check the store as ``run_sweep`` does, make its tasks,
        compile ahead what they need, queue them."""
        asked, self._asked = self._asked, []
        t0 = time.perf_counter()
        for s in asked:
            try:
                self._plan_one(s)
            except BaseException as exc:  # the job's error (a refused store, a rule that cannot compile)
                if not isinstance(exc, Exception):
                    raise
                s.error = exc
                s.done.set()
        self.busy.plan_seconds += time.perf_counter() - t0 - sum(s.compile_seconds for s in asked)

    def _plan_one(self, s: _Sweep) -> None:
        s.t0 = time.perf_counter()
        conds, store = s.conds, self.store
        refuse_too_big(conds, CUT_FOR, self.executor, False)
        with store.writing():
            store.check()
            check_compatible(store, conds)
            _save_designs(store, conds)
            store.remove_orphans()
            done = store.completed_runs()
        missing = {(c.experiment, c.id, r) for c in conds for r in range(c.runs)} - done
        tasks = make_tasks(conds, done | self._inflight, CUT_FOR)
        t0 = time.perf_counter()
        configs = [c.config for t in tasks for c, _ in t.members]
        preflight(configs)
        if tasks and not isinstance(self.executor, InlineExecutor):
            warm_up(configs)
        s.compile_seconds = time.perf_counter() - t0
        self.busy.compile_seconds += s.compile_seconds
        todo = sum(t.size for t in tasks)
        if s.on_plan:
            s.on_plan(todo)
        s.waiting = missing
        s.report = SweepReport(sum(c.runs for c in conds), sum(c.runs for c in conds) - todo, todo, 0, 0.0)
        for t in tasks:
            self._inflight.update((c.experiment, c.id, r) for c, runs in t.members for r in runs)
            self._queue.append((t, s))
        self._queue.sort(key=lambda ts: -ts[0].condition.config.steps * ts[0].size)  # the largest first
        self._open.append(s)
        self._settle()

    def _fill(self) -> None:
        """Hand queued tasks to the executor, the largest first, up to ``AHEAD`` per worker beyond those
        running (an inline executor runs each as it is handed, here)."""
        while self._queue and len(self._running) < self.workers * (1 + AHEAD):
            task, s = self._queue.pop(0)
            fut = self.executor.submit(run_calls, _calls(task, False))
            self._running[fut] = (task, s)
            if isinstance(self.executor, InlineExecutor):
                self._collect()

    def _collect(self) -> None:
        """Write every finished task to the store as ``run_sweep`` does, and hand each sweep whose runs are all
        committed its report."""
        for fut in [f for f in self._running if f.done()]:
            task, s = self._running.pop(fut)
            self._finished(task, s, fut.result())
        self._settle()

    def _finished(self, task: Task, s: _Sweep, outputs: list[RunOutput]) -> None:
        t0 = time.perf_counter()
        tables = _frames(task, outputs)
        keys = dict.fromkeys(k for c, _ in task.members for k in c.keys)
        with self.store.writing():
            self.store.write_part(task.part_id, **tables, keys=keys)
        if s.on_part:
            s.on_part(tables)
        runs = tables["runs"]
        assert runs is not None  # every part records its runs
        steps, seconds = int(runs.steps.sum()), float(runs.duration_s.sum())
        s.env_steps += steps
        s.run_seconds += seconds
        s.compile_seconds = max([s.compile_seconds] + [o.compile_seconds for o in outputs])
        s.failed.extend(o for o in outputs if o.error is not None)
        self._count(task.size, steps, seconds, 0.0)
        committed = {(c.experiment, c.id, r) for c, runs in task.members for r in runs}
        self._inflight -= committed
        for other in self._open:
            other.waiting -= committed
        if self.on_done:
            self.on_done(task.size)
        self.busy.write_seconds += time.perf_counter() - t0

    def _count(self, runs: int, steps: int, seconds: float, compile_seconds: float) -> None:
        self.busy.runs += runs
        self.busy.env_steps += steps
        self.busy.run_seconds += seconds
        self.busy.compile_seconds += compile_seconds

    def _settle(self) -> None:
        for s in [s for s in self._open if not s.waiting]:
            self._open.remove(s)
            rep = s.report
            assert rep is not None  # a sweep is open only once planned
            rep.env_steps, rep.run_seconds = s.env_steps, s.run_seconds
            rep.wall_seconds, rep.compile_seconds = time.perf_counter() - s.t0, s.compile_seconds
            rep.failed = len(s.failed)
            rule_errors = [o for o in s.failed if o.rule_error]
            rep.rule_errors = len(rule_errors)
            rep.first_error = (rule_errors[0].error.strip() if rule_errors
                               else s.failed[0].error.strip().splitlines()[-1] if s.failed else "")
            s.done.set()

    def _stop(self, exc: BaseException) -> None:
        """Cancel what has not started, and end every waiting job at its sweep with ``exc``'s stop."""
        for fut in self._running:
            fut.cancel()
        self._running.clear()
        self._queue.clear()
        stop = _stopped(exc)
        for s in self._asked + self._open:
            s.error = stop
            s.done.set()
        self._asked.clear()
        self._open.clear()


def _stopped(exc: BaseException) -> InternalError:
    """The error a job's sweep ends with once ``exc`` (another job's error, or a stop) ended the map."""
    return InternalError(f"stopped: {type(exc).__name__}: {exc}")


def dask_threads(client) -> int:
    """How many tasks a Dask cluster runs at once: its workers' threads."""
    return max(1, sum(client.nthreads().values()))
