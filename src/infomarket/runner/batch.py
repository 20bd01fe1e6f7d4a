"""One experiment run many times, its tables kept in memory: a sweep of one condition without a store.

``run_batch`` plans the condition, makes the tasks and runs them with ``execute.execute`` exactly as a
sweep does (same tasks, same warm-up, same seeds: run ``i`` uses ``seeds.run_seed(master, i, condition)``);
only what happens to a finished task differs.  ``infomarket run`` uses ``runner.run`` (a results store).
"""
from __future__ import annotations

from concurrent.futures import Executor
from dataclasses import dataclass, field

import pandas as pd

from ..config.schema import Experiment
from .execute import (RunFailed, RunOutput, Task, default_workers, execute, local_executor, make_tasks,
                      process_pool, warm)
from .plan import BASE, Condition

__all__ = ["BatchInterrupted", "BatchResult", "RunFailed", "RunOutput", "default_workers", "process_pool", "run_batch",
           "run_conditions", "warm"]


@dataclass
class BatchResult:
    """The tables of a batch of runs stepped in one process, with the compile and run times and the steps per run."""
    robots: pd.DataFrame
    history: pd.DataFrame
    compile_seconds: float
    run_seconds: float
    steps: int
    #: Items per site per run (terrain setups only: ``Simulation.site_counts``), else empty.
    sites: pd.DataFrame = field(default_factory=pd.DataFrame)

    @property
    def env_steps_per_second(self) -> float:
        """Environment steps (runs x steps) per second of running, compilation excluded."""
        runs = self.robots["run"].nunique() if len(self.robots) else 0
        return runs * self.steps / self.run_seconds if self.run_seconds > 0 else float("inf")


class BatchInterrupted(KeyboardInterrupt):
    """Ctrl-C during ``run_batch``: ``result`` holds the runs that had finished (None if none had)."""

    def __init__(self, result: BatchResult | None, planned: int):
        super().__init__()
        self.result, self.planned = result, planned


def run_batch(cfg: Experiment, runs: int, master_seed: int, *, steps: int | None = None,
              history_every: int | None = None, workers: int = 1, condition: int = 0,
              on_done=None, executor: Executor | None = None) -> BatchResult:
    """Run ``runs`` independent runs of ``cfg`` (``steps``/``history_every`` replace the file's); returns
    their tables.  ``on_done(k)`` is called as runs complete (for progress).  ``executor`` (any
    concurrent.futures Executor) is used if given, else inline for one worker, else a local pool.
    A run that raises stops the batch with ``RunFailed`` (holding the run's traceback text)."""
    changes = {k: v for k, v in (("steps", steps), ("history_every", history_every)) if v is not None}
    if changes:
        cfg = cfg.model_copy(update=changes)
    cond = Condition(cfg.name, BASE, {}, cfg, runs, master_seed, condition)
    return run_conditions([cond], workers=workers if runs > 1 else 1, on_done=on_done, executor=executor)[0]


def run_conditions(conds: list[Condition], *, workers: int = 1, on_done=None,
                   executor: Executor | None = None) -> list[BatchResult]:
    """Every run of each condition, on one executor with one warm-up; a BatchResult per condition, in
    order.  Ctrl-C raises ``BatchInterrupted`` holding the first condition's finished runs."""
    tasks = make_tasks(conds, set(), workers if executor is None else max(workers, 2))
    outputs: dict[tuple[str, str], list[RunOutput]] = {(c.experiment, c.id): [] for c in conds}
    warm_seconds = 0.0

    def finished(task: Task, out: list[RunOutput]) -> None:
        k = 0
        for c, runs in task.members:
            mine = out[k:k + len(runs)]
            k += len(runs)
            for o in mine:
                if o.error is not None:
                    raise RunFailed(f"{c.experiment} [{c.id}]: run {o.run} (seed {o.seed}) failed:\n{o.error}")
            outputs[(c.experiment, c.id)].extend(mine)
        if on_done:
            on_done(len(out))

    try:
        if executor is not None:
            warm_seconds = execute(tasks, finished, executor=executor)
        else:
            with local_executor(max(1, min(workers, len(tasks)))) as pool:  # never more processes than tasks
                warm_seconds = execute(tasks, finished, executor=pool)
    except KeyboardInterrupt:
        first = outputs[(conds[0].experiment, conds[0].id)]
        raise BatchInterrupted(_collect(first, warm_seconds) if first else None, conds[0].runs) from None
    return [_collect(outputs[(c.experiment, c.id)], warm_seconds) for c in conds]


def _collect(outputs: list[RunOutput], warm_seconds: float) -> BatchResult:
    outputs = sorted(outputs, key=lambda o: o.run)  # tasks finish in any order; rows are by run
    robots = pd.concat([o.robots for o in outputs], ignore_index=True)
    hists = [o.history for o in outputs if len(o.history)]
    history = pd.concat(hists, ignore_index=True) if hists else pd.DataFrame()
    compile_seconds = max([warm_seconds] + [o.compile_seconds for o in outputs])
    sites = [o.sites for o in outputs if len(o.sites)]
    return BatchResult(robots, history, compile_seconds, sum(o.run_seconds for o in outputs), outputs[0].steps,
                       pd.concat(sites, ignore_index=True) if sites else pd.DataFrame())
