"""The resumable CMA-ES loop: candidates are conditions of a results store, evaluated on the sweep machinery.

Generation g of a cell asks CMA-ES (``cma``) for ``popsize`` points; each becomes the condition
``phase=search,gen=g,cand=i`` of the cell's experiment in the store, whose runs all use the seeds of
generation g (**common random numbers**: candidates of one generation differ only by their parameters;
each generation draws a new set).  The runs go to ``runner.sweep.run_sweep`` (inline, a local process
pool, or Dask), which skips runs already committed.  The optimiser keeps no state of its own: a search
that starts again (after a crash or a SIGKILL) replays the generations from the optimiser's seed, asks
the same points (NumPy's global generator, which ``cma`` samples from, is reseeded per generation from the
study's seed, the cell and g), finds their runs committed and tells CMA-ES the same values, so no
evaluation is lost or repeated.  A replay that asked another point would need another configuration, and
the store refuses that (``runner.sweep.check_compatible``), so a divergence cannot pass unnoticed.

Before the first generation, every hand-written attack runs on a seed set of its own (``phase=start``);
CMA-ES starts at the point of the best of them (the search space contains every hand-written attack), so
the search refines the strongest known attack instead of starting from the middle of the cube.

After the search, the ``best`` candidates and every hand-written attack run on **held-out seeds** (one
set shared by all of them, never used by the search): conditions ``phase=heldout,attack=NAME``.
"""
from __future__ import annotations

import hashlib
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..runner.plan import Condition, condition_number
from ..runner.sweep import run_sweep
from ..seeds import run_seed
from ..store import Store
from . import space
from .objective import loss, per_run
from .study import Cell, Settings, Study


@dataclass(frozen=True)
class CRNCondition(Condition):
    """A condition whose runs use a seed stream of their own choosing (``crn``), shared with other
    conditions: the common random numbers of one generation, or the held-out set."""

    crn: int = 0

    def seed(self, run: int) -> int:
        return run_seed(self.master_seed, run, self.crn)


@dataclass
class CellSearch:
    """What the search of one cell found: every evaluated candidate, and the held-out runs."""

    cell: Cell
    candidates: pd.DataFrame   # gen, cand, label, fitness, the parameters
    heldout: pd.DataFrame      # attack, run, items, liar_wealth
    searched: list[str] = field(default_factory=list)  # labels of the re-evaluated candidates, best first
    done: int = 0              # runs made now
    skipped: int = 0           # runs found in the store
    start_from: str = ""       # the hand-written attack CMA-ES started at (the best on the start seeds)


def _stream(*parts) -> int:
    text = "/".join(map(str, parts))
    return int(hashlib.sha256(text.encode()).hexdigest()[:15], 16)


def _keys(phase: str, gen: int, cand: int, attack: str) -> dict:
    return {"phase": phase, "gen": gen, "cand": cand, "attack": attack}


def _condition(cell: Cell, params: dict, keys: dict, runs: int, crn: int, steps, transitory) -> CRNCondition:
    cid = ",".join(f"{k}={keys[k]}" for k in sorted(keys))
    cfg = cell.with_attack(params, steps=steps, transitory=transitory)
    return CRNCondition(cell.experiment, cid, keys, cfg, runs, cfg.seed, condition_number(cid), crn=crn)


def search_cell(study: Study, cell: Cell, store: Store, *, run: Callable[[list[Condition]], tuple[int, int]],
                steps: int | None = None, transitory: int | None = None) -> CellSearch:
    """Search one cell: CMA-ES generations, then the held-out re-evaluation.  ``run(conds)`` runs the
    missing runs of ``conds`` into ``store`` and returns (runs made, runs skipped)."""
    import cma

    s: Settings = study.settings
    dim = space.dimension()
    opts = {"bounds": [0.0, 1.0], "popsize": s.popsize, "seed": _stream(s.seed, cell.experiment) % (2**31 - 2) + 1,
            "verbose": -9, "verb_log": 0, "verb_disp": 0, "verb_filenameprefix": "", "tolfun": 0.0,
            "tolx": 0.0, "tolfunhist": 0.0, "tolstagnation": 10**9, "tolflatfitness": 10**9}
    # the start: every hand-written attack on one shared seed set of its own; CMA-ES starts at the best
    hand = [(n, p) for n, p in study.baselines.items() if n != study.reference]
    start = [_condition(cell, p, _keys("start", -1, k, n), s.runs, _stream("start"), steps, transitory)
             for k, (n, p) in enumerate(hand)]
    done, skipped = run(start) if start else (0, 0)
    x0, start_from = np.full(dim, 0.5), ""
    robots = getattr(run, "robots", None) or (lambda conds: _robots(store, cell))
    if start:
        values = _values(robots(start), start, s.objective)
        scores = [float(loss(values.loc[c.id].mean(), s.objective)) for c in start]
        k = int(np.argmin(scores))  # ties: the first declared
        x0, start_from = np.clip(space.to_unit(hand[k][1]), 0.0, 1.0), hand[k][0]
    es = cma.CMAEvolutionStrategy(x0, s.sigma0, opts)
    rows = []
    for g in range(s.generations):
        np.random.seed(_stream(s.seed, cell.experiment, "gen", g) % (2**32))  # what cma samples from
        X = es.ask()
        crn = _stream("search", g)
        conds = [_condition(cell, space.to_params(x), _keys("search", g, i, f"g{g}c{i}"), s.runs, crn, steps,
                            transitory) for i, x in enumerate(X)]
        made, found = run(conds)
        done, skipped = done + made, skipped + found
        values = _values(robots(conds), conds, s.objective)
        fitness = [float(loss(values.loc[c.id].mean(), s.objective)) for c in conds]
        es.tell(X, fitness)
        for i, (c, f) in enumerate(zip(conds, fitness)):
            rows.append({"gen": g, "cand": i, "label": c.keys["attack"], "fitness": f,
                         **space.to_params(X[i])})
    candidates = pd.DataFrame(rows)
    best = candidates.sort_values(["fitness", "gen", "cand"], kind="stable").head(s.best)
    crn = _stream("heldout")
    held = []
    for rank, row in enumerate(best.itertuples(index=False)):
        params = {n: getattr(row, n) for n in space.NAMES}
        held.append(_condition(cell, params, _keys("heldout", row.gen, row.cand, f"search{rank + 1}"),
                               s.heldout_runs, crn, steps, transitory))
    for name, params in study.baselines.items():
        held.append(_condition(cell, params, _keys("heldout", -1, -1, name), s.heldout_runs, crn, steps,
                               transitory))
    made, found = run(held)
    per = per_run(_robots(store, cell))
    per = per[per.condition.isin({c.id for c in held})]
    label = {c.id: c.keys["attack"] for c in held}
    heldout = per.assign(attack=per.condition.map(label))[["attack", "run", "items", "liar_wealth"]]
    return CellSearch(cell, candidates, heldout.reset_index(drop=True), [f"search{k + 1}" for k in range(len(best))],
                      done + made, skipped + found, start_from)


def _robots(store: Store, cell: Cell) -> pd.DataFrame:
    r = store.robots()
    return r[r.experiment == cell.experiment]


def _values(robots: pd.DataFrame, conds: list[Condition], objective: str) -> pd.Series:
    """The objective's per-run values of ``conds`` (from ``robots``, which holds their rows), indexed by
    condition id."""
    per = per_run(robots)
    per = per[per.condition.isin({c.id for c in conds})]
    return per.set_index("condition")[objective]


def store_runner(store: Store, *, workers: int = 1, executor=None,
                 on_done: Callable[[int], None] | None = None,
                 on_skip: Callable[[int], None] | None = None) -> Callable[[list[Condition]], tuple[int, int]]:
    """``run(conds)`` for ``search_cell``: their missing runs into ``store`` on the sweep machinery.
    ``run.robots(conds)``: the robots rows of ``conds``, kept from the parts just written when every run of
    theirs was made by this runner (the store is read back only for a search that resumes): reading the
    whole store after every generation cost the parent more the larger the store grew, while the
    workers waited."""
    kept: dict[tuple[str, str], list[pd.DataFrame]] = {}
    made: dict[tuple[str, str], set[int]] = {}

    def keep(tables: dict) -> None:
        ok = tables["runs"][tables["runs"].status == "ok"]
        for (exp, cid), g in ok.groupby(["experiment", "condition"], sort=False):
            made.setdefault((exp, cid), set()).update(int(r) for r in g.run)
        if tables["robots"] is not None:
            for (exp, cid), g in tables["robots"].groupby(["experiment", "condition"], sort=False):
                kept.setdefault((exp, cid), []).append(g)

    def robots(conds: list[Condition]) -> pd.DataFrame:
        if all(made.get((c.experiment, c.id)) == set(range(c.runs)) and (c.experiment, c.id) in kept for c in conds):
            frames = [f for c in conds for f in kept.pop((c.experiment, c.id), [])]
            return pd.concat(frames, ignore_index=True).sort_values(["experiment", "condition", "run", "robot"],
                                                                    kind="stable")
        r = store.robots()
        return r[r.experiment.isin({c.experiment for c in conds})]

    def run(conds: list[Condition]) -> tuple[int, int]:
        planned = sum(c.runs for c in conds)
        rep = run_sweep(conds, store, workers=workers, executor=executor, on_done=on_done,
                        on_plan=(lambda todo: on_skip(planned - todo)) if on_skip else None, on_part=keep)
        if rep.failed:
            from ..errors import SimulationError  # only when a run failed

            raise SimulationError(f"{rep.failed} of {rep.done} runs failed (the first: {rep.first_error}); "
                                  f"`infomarket store failed {store.root}` lists them")
        return rep.done, rep.skipped

    run.robots = robots
    return run
