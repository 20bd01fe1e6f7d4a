"""``infomarket run``: one experiment run N times into a results store — a sweep of its one condition.

The store is the sweeps' (``store.results``): ``figures``, ``store verify`` and DuckDB read it; its runs
table records each run's seed, master seed, steps and configuration hash, and its configs table the
configuration itself, so ``simulate(store.config(name), seed=run_seed)`` repeats any run bit for bit.

What a folder may already hold, decided under the store's lock (a second writer is refused at once):

* nothing, or a store without this experiment: the runs are added;
* this experiment's runs with the same configuration and master seed: the missing runs are added
  (an interrupted ``run`` resumes; a larger ``--runs`` extends it);
* this experiment's runs made otherwise (another configuration, seed, or a sweep's conditions), or the
  flat files an earlier version of ``run`` wrote: refused, unless ``force``, which removes this
  experiment's earlier runs (other experiments in the store are kept) or those files, then runs.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from ..config import load_experiment, sizes
from ..config.load import validate
from ..errors import ConfigError, UsageError
from ..store import Store
from .plan import BASE, Condition
from .sweep import SweepReport, refuse_too_big, sweep_locked
from .execute import preflight

#: What ``infomarket run`` wrote before it wrote a results store (``--force`` replaces these).
LEGACY_FILES = ("robots.parquet", "wealth_history.parquet", "sites.parquet")


@dataclass
class RunReport:
    """What ``infomarket run`` did: the condition, the store, the sweep's report and the robots table of the
    requested runs."""
    condition: Condition
    store: Store
    sweep: SweepReport
    #: rows of this request's runs (run < runs) that completed: one per robot per run
    robots: pd.DataFrame
    #: this experiment's earlier parts (or flat files) that ``force`` removed
    replaced: int = 0

    @property
    def runs_done(self) -> int:
        """How many of the requested runs completed (distinct runs in the robots table)."""
        return int(self.robots["run"].nunique()) if len(self.robots) else 0


class RunInterrupted(KeyboardInterrupt):
    """Ctrl-C during a ``run``: ``kept`` of the ``planned`` runs are committed in the store."""

    def __init__(self, kept: int, planned: int, store: Store):
        super().__init__()
        self.kept, self.planned, self.store = kept, planned, store


def prepare(experiment: str, *, runs: int | None = None, seed: int | None = None, steps: int | None = None,
            history_every: int | None = None) -> Condition:
    """The one condition ``run`` makes: the experiment (a file or a shipped name) with ``steps`` and
    ``history_every`` replaced where given, without its sweep (``run`` runs the base configuration), and
    the runs and master seed recorded in it.  Bad input raises ConfigError or UsageError (exit 2)."""
    cfg = load_experiment(experiment)
    changes = {k: v for k, v in (("steps", steps), ("history_every", history_every)) if v is not None}
    runs = runs or cfg.runs
    seed = cfg.seed if seed is None else seed
    data = cfg.model_dump()
    data.update(changes, sweep=None, runs=runs, seed=seed)
    options = " ".join(f"--{'history' if k == 'history_every' else k} {v}" for k, v in changes.items())
    try:
        cfg = validate(data, options or "configuration")
    except ConfigError as exc:  # e.g. --steps below the file's transitory or history_every
        raise UsageError(str(exc).replace(" invalid experiment\n  ", " ").replace("\n  ", "; ")) from None
    too_big = sizes.runs_too_big(cfg, runs)
    if too_big:  # named with the options that make the results this big
        raise UsageError(f"{' '.join(filter(None, (f'--runs {runs}', options)))}: {too_big}")
    return Condition(cfg.name, BASE, {}, cfg, runs, seed, 0)


def run_experiment(cond: Condition, out: str | Path, *, workers: int = 1, force: bool = False,
                   on_done: Callable[[int], None] | None = None,
                   on_plan: Callable[[int], None] | None = None) -> RunReport:
    """Run the missing runs of ``cond`` into the store at ``out`` (see the module's text for what an
    existing folder may hold).  Ctrl-C raises ``RunInterrupted``: the runs already finished are kept in
    the store, and the same call again runs only the others."""
    out = Path(out)
    refuse_too_big([cond], workers, None, False)
    store = Store(out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {out}: exists and is not a directory")

    preflight([cond.config])  # a rule that keeps the kernel from compiling: refused, nothing written
    replaced = _legacy_files(store, force)
    try:
        with store.writing():
            replaced += _make_room(store, cond, force)
            report = sweep_locked([cond], store, workers=workers, on_done=on_done, on_plan=on_plan,
                                  retry_failed=True)
    except KeyboardInterrupt:
        raise RunInterrupted(_committed(store, cond), cond.runs, store) from None
    robots = store.robots()
    if len(robots):
        robots = robots[(robots.experiment == cond.experiment) & (robots.condition == cond.id)
                        & (robots.run < cond.runs)].reset_index(drop=True)
    return RunReport(cond, store, report, robots, replaced)


def _legacy_files(store: Store, force: bool) -> int:
    """Refuse (or, with ``force``, remove) the flat files of an earlier version's ``run``; any other
    foreign content is refused by ``store.writing`` and never removed."""
    foreign = store.foreign()
    if not foreign or any(p.name not in LEGACY_FILES or not p.is_file() for p in foreign):
        return 0
    if not force:
        raise UsageError(f"--out {store.root}: {foreign[0].name} exists (an earlier run's results); --force "
                         f"replaces it, or choose another --out")
    for p in foreign:
        p.unlink()
    return len(foreign)


def _make_room(store: Store, cond: Condition, force: bool) -> int:
    """With the lock held: keep this experiment's earlier runs if they are the same request's, else
    refuse, or with ``force`` remove them (returns how many parts)."""
    runs = store.runs()
    mine = runs[runs.experiment == cond.experiment] if len(runs) else runs
    recorded = store.seeds().get(cond.experiment)
    if mine.empty and recorded is None:
        return 0
    if force:
        return store.drop_experiment(cond.experiment)
    why = None
    if recorded is not None and recorded != cond.master_seed:
        why = f"master seed {recorded} (now {cond.master_seed})"
    elif set(mine.condition) - {cond.id}:
        why = f"the conditions of a sweep ({', '.join(sorted(set(mine.condition))[:3])}, ...)"
    elif (mine.config_hash != cond.config.config_hash()).any():
        why = f"another configuration (hash {mine.config_hash.iloc[0]}, now {cond.config.config_hash()})"
    if why is None:
        return 0  # the same runs: resume (add the missing ones)
    raise UsageError(f"--out {store.root}: holds runs of {cond.experiment} made with {why}; --force replaces "
                     f"them, or choose another --out")


def _committed(store: Store, cond: Condition) -> int:
    try:
        runs = store.runs()
    except Exception:  # noqa: BLE001 - reporting what was kept must not hide the interruption
        return 0
    if runs.empty:
        return 0
    mine = runs[(runs.experiment == cond.experiment) & (runs.condition == cond.id) & (runs.run < cond.runs)]
    return int((mine.status == "ok").sum()) if "status" in mine else len(mine)
