"""The defence search (min-max): an outer search over defences, each judged by the worst attack an inner
attack search finds against it, then the frontier confirmed on seeds no other phase touched.

1. **Outer search** (search seeds).  Per family, its first candidates (``families.candidates``: the
   default and a Sobol design), then ``refine`` points around the family's best trade.  Every candidate
   is judged by
   - its **cost**: ``cost_runs`` runs with no Byzantines beside the undefended swarm on the same seeds,
     ``1 - mean(items) / mean(items of the undefended)``;
   - its **worst-case loss** at each Byzantine count: the inner attack search (``search.driver.search_cell``
     with the declared ``[inner]`` settings and seeds keyed by the study's), whose chosen worst attack and
     truthful reference give the mean per-seed loss on the inner search's own confirmation runs.
   The trade ``J = loss(target) + max(0, cost - max_cost)`` ranks candidates.
2. **Confirmation** (one shared seed set no other phase uses).  Every existing defence and at most
   ``frontier`` new candidates (the Pareto set of cost and loss at the target count, best J first): the
   candidate with no Byzantines beside the undefended swarm, and at each count its worst attack found and
   the truthful reference, every one on runs 0 .. confirmation_runs - 1.  Every answer comes from these.

Everything is a condition of a results store run on the sweep machinery, and every choice is a pure
function of the settings and of runs already made, so a study started again (after SIGKILL) replays the
same choices and runs only what is missing, inline, on the process pool or on Dask.
"""
from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..errors import InternalError
from ..runner.plan import condition_number
from ..search import driver as attack
from ..search.objective import per_run
from ..search.restarts import stream
from ..search.study import Cell
from ..store import Store
from .families import Candidate, candidates as first_candidates, refine
from .study import Study

NAME = "defence_search"
KEYS = ("phase", "seed_set", "searcher", "restart", "gen", "cand", "attack")


@dataclass
class Judged:
    """One candidate as the outer search judged it (search seeds only)."""

    candidate: Candidate
    cost: float                                   # 1 - mean items / mean items of the undefended swarm
    losses: dict[int, float]                      # Byzantine count -> mean per-seed loss to the worst found
    attacks: dict[int, dict[str, dict]]           # count -> {"worst": params, "reference": params}
    chosen: dict[int, dict[str, str]] = field(default_factory=dict)  # count -> the inner search's roles
    runs: int = 0                                 # runs this judgement stands on

    def trade(self, target: int, max_cost: float) -> float:
        """``loss(target) + max(0, cost - max_cost)``; infinite where either is undefined (no items)."""
        if not (np.isfinite(self.cost) and np.isfinite(self.losses[target])):
            return float("inf")
        return self.losses[target] + max(0.0, self.cost - max_cost)


@dataclass
class Result:
    """What a defence search found: every judged candidate, the confirmed ones and their runs."""

    judged: list[Judged]
    confirmed: list[str]                 # labels, existing defences first
    cost_runs: pd.DataFrame              # label, run, items, undefended: the confirmation runs with no Byzantines
    attack_runs: pd.DataFrame            # label, byzantines, run, worst, reference: items per honest robot
    made: int = 0
    found: int = 0


def ratio_loss(x, reference) -> float:
    """``1 - mean(x) / mean(reference)``: the search phase's estimate (a ratio of means, defined when single
    runs collect nothing); NaN when the reference collected nothing at all."""
    ref = float(np.mean(reference))
    return 1.0 - float(np.mean(x)) / ref if ref > 0 else float("nan")


def cell(study: Study, c: Candidate, byzantines: int) -> Cell:
    """The attack-search cell of a defence candidate with ``byzantines`` attackers, so the inner search runs
    against it."""
    cfg = study.config(c, byzantines).model_copy(update={"name": NAME})
    return Cell(c.label, byzantines, cfg)


def _condition(experiment: str, cfg, phase: str, seed_set: str, attack_label: str, runs: int, crn: int):
    keys = {"phase": phase, "seed_set": seed_set, "searcher": "defence", "restart": -1, "gen": -1, "cand": -1,
            "attack": attack_label}
    cid = ",".join(f"{k}={keys[k]}" for k in sorted(keys))
    return attack.CRNCondition(experiment, cid, keys, cfg, runs, cfg.seed, condition_number(cid), crn=crn)


class _Runner:
    """Runs conditions into the store and reads back each one's per-run items."""

    def __init__(self, run: Callable, store: Store):
        self.run, self.store = run, store
        self.made = self.found = 0

    def items(self, conds: list) -> list[np.ndarray]:
        if not conds:
            return []
        made, found = self.run(conds)
        self.made, self.found = self.made + made, self.found + found
        robots = self.run.robots(conds) if hasattr(self.run, "robots") else self.store.robots()
        per = per_run(robots)
        out = []
        for c in conds:
            mine = per[(per.experiment == c.experiment) & (per.condition == c.id)].sort_values("run")
            if list(mine.run) != list(range(c.runs)):
                raise InternalError(f"{c.experiment} [{c.id}]: runs missing after the run: "
                                    f"{sorted(set(range(c.runs)) - set(mine.run))[:5]}")
            out.append(mine["items"].to_numpy(float))
        return out


def _cost_conditions(study: Study, labelled: list[tuple[str, object]], seed_set: str, runs: int, crn: int) -> list:
    return [_condition(f"{NAME}.{label}.b0", cfg.model_copy(update={"name": NAME}), "cost", seed_set, "none", runs, crn)
            for label, cfg in labelled]


def _undefended(study: Study):
    return ("undefended", study.undefended_config())


def outer_counts(study: Study) -> tuple[int, ...]:
    """The Byzantine counts the outer search judges every candidate at (``Settings.every_count``)."""
    return study.byzantines if study.settings.every_count else (study.settings.target,)


def _judge_count(study: Study, c: Candidate, b: int, store: Store, run: Callable) -> tuple[float, dict, dict, int]:
    """The inner attack search against ``c`` with ``b`` Byzantines: the mean per-seed loss to the worst attack
    it chose, that attack and the reference, the search's roles, and the runs it stands on."""
    r = attack.search_cell(study.inner, cell(study, c, b), store, run=run)
    conf = r.confirmation
    worst, ref = r.chosen["worst"], r.chosen["reference"]
    w = conf[conf.attack == worst].sort_values("run")["items"].to_numpy(float)
    t = conf[conf.attack == ref].sort_values("run")["items"].to_numpy(float)
    attacks = {"worst": dict(r.params[worst]), "reference": dict(r.params[ref])}
    return ratio_loss(w, t), attacks, dict(r.chosen), r.done + r.skipped


def judge(study: Study, c: Candidate, store: Store, run: Callable, *, runner: _Runner | None = None) -> Judged:
    """The candidate's cost and its worst case at the outer search's counts, on search seeds (module
    docstring, 1)."""
    s = study.settings
    runner = runner or _Runner(run, store)
    before = runner.made + runner.found
    crn = stream(s.seed, "cost", "search")
    mine, undef = runner.items(_cost_conditions(study, [(c.label, study.config(c, 0)), _undefended(study)],
                                                "search", s.cost_runs, crn))
    j = Judged(c, ratio_loss(mine, undef), {}, {}, {})
    complete(study, j, store, run, outer_counts(study))
    j.runs += runner.made + runner.found - before
    return j


def complete(study: Study, j: Judged, store: Store, run: Callable, counts: tuple[int, ...] | None = None) -> None:
    """Judge ``j`` at the ``counts`` (default: every count of the study) it was not judged at yet.  The inner
    search's seeds depend on the candidate and the count alone, so a candidate completed before its
    confirmation has the numbers it would have had from the outer search."""
    for b in counts or study.byzantines:
        if b not in j.losses:
            j.losses[b], j.attacks[b], j.chosen[b], runs = _judge_count(study, j.candidate, b, store, run)
            j.runs += runs
    order = [b for b in study.byzantines if b in j.losses]
    j.losses, j.attacks, j.chosen = ({b: d[b] for b in order} for d in (j.losses, j.attacks, j.chosen))


def pareto(judged: list[Judged], target: int) -> list[Judged]:
    """The candidates no other candidate beats on both cost and loss at ``target`` (ties kept; a candidate
    whose cost or loss is undefined is on no frontier)."""
    judged = [j for j in judged if np.isfinite(j.cost) and np.isfinite(j.losses[target])]
    out = []
    for j in judged:
        if not any(o is not j and o.cost <= j.cost and o.losses[target] <= j.losses[target]
                   and (o.cost < j.cost or o.losses[target] < j.losses[target]) for o in judged):
            out.append(j)
    return out


def frontier(study: Study, judged: list[Judged]) -> list[Judged]:
    """The new candidates to confirm: the Pareto set, best trade first, at most ``frontier``."""
    s = study.settings
    new = [j for j in judged if j.candidate.origin != "existing"]
    return sorted(pareto(new, s.target), key=lambda j: (j.trade(s.target, s.max_cost), j.candidate.label))[:s.frontier]


def search(study: Study, store: Store, run: Callable, *, on_judged: Callable[[Judged], None] | None = None
           ) -> list[Judged]:
    """The outer search over every family of the study, then the existing defences (module docstring, 1)."""
    s = study.settings
    attack.record_provenance(store, study.declaration.path, key=NAME)

    def family(fam) -> list[Judged]:
        runner = _Runner(run, store)
        first = [judge(study, c, store, run, runner=runner) for c in first_candidates(fam, s.candidates, s.seed)]
        best = min(first, key=lambda j: (j.trade(s.target, s.max_cost), j.candidate.label))
        return first + [judge(study, c, store, run, runner=runner)
                        for c in refine(fam, best.candidate, s.refine, len(first), s.seed, s.refine_sigma)]

    # each family, and each existing defence, is a job of its own: ``run.map`` may run them side by side
    # (runner.feed), and every choice in one depends on its own runs alone
    jobs = [functools.partial(family, fam) for fam in study.families.values()]
    jobs += [functools.partial(lambda c: [judge(study, c, store, run)], c) for c in study.existing_candidates()]
    judged = [j for part in _map(run, jobs) for j in part]
    for j in judged if on_judged else ():
        on_judged(j)
    return judged


def _map(run: Callable, jobs: list) -> list:
    """``run.map(jobs)`` where the runner has one (``search.driver.store_runner``), else the jobs in turn."""
    return run.map(jobs) if hasattr(run, "map") else [job() for job in jobs]


def confirm(study: Study, judged: list[Judged], store: Store, run: Callable) -> Result:
    """The existing defences and the frontier on the confirmation seeds (module docstring, 2)."""
    s = study.settings
    chosen = [j for j in judged if j.candidate.origin == "existing"] + frontier(study, judged)
    # the counts the outer search left out (Settings.every_count), each candidate a job of its own
    _map(run, [functools.partial(complete, study, j, store, run) for j in chosen])
    runner = _Runner(run, store)
    crn = stream(s.seed, "confirmation")
    n = s.confirmation_runs
    labelled = [(j.candidate.label, study.config(j.candidate, 0)) for j in chosen] + [_undefended(study)]
    values = runner.items(_cost_conditions(study, labelled, "confirmation", n, crn))
    undef = values[-1]
    cost_rows = [pd.DataFrame({"label": j.candidate.label, "run": np.arange(n), "items": v, "undefended": undef})
                 for j, v in zip(chosen, values[:-1])]
    conds, where = [], []
    for j in chosen:
        for b in study.byzantines:
            ce = cell(study, j.candidate, b)
            for role in ("worst", "reference"):
                conds.append(_condition(ce.experiment, ce.with_attack(j.attacks[b][role]), "defence_confirmation",
                                        "confirmation", role, n, crn))
                where.append((j.candidate.label, b, role))
    values = runner.items(conds)
    per: dict[tuple[str, int], dict[str, np.ndarray]] = {}
    for (label, b, role), v in zip(where, values):
        per.setdefault((label, b), {})[role] = v
    attack_rows = [pd.DataFrame({"label": label, "byzantines": b, "run": np.arange(n), "worst": r["worst"],
                                 "reference": r["reference"]}) for (label, b), r in per.items()]
    cols_c = ["label", "run", "items", "undefended"]
    cols_a = ["label", "byzantines", "run", "worst", "reference"]
    return Result(judged, [j.candidate.label for j in chosen],
                  pd.concat(cost_rows, ignore_index=True) if cost_rows else pd.DataFrame(columns=cols_c),
                  pd.concat(attack_rows, ignore_index=True) if attack_rows else pd.DataFrame(columns=cols_a),
                  runner.made, runner.found)


def planned_runs(study: Study) -> int:
    """The runs of the whole study (at most: the inner searches often choose fewer distinct attacks)."""
    s = study.settings
    per_family = {n: (s.candidates + s.refine if f.params else 1) for n, f in study.families.items()}
    n_candidates = sum(per_family.values()) + len(study.existing)
    inner = attack.planned_runs(study.inner)
    outer = len(outer_counts(study))
    confirmed = len(study.existing) + min(s.frontier, sum(per_family.values()))
    return (n_candidates * (s.cost_runs + inner * outer) + s.cost_runs
            + confirmed * inner * (len(study.byzantines) - outer)
            + (confirmed + 1) * s.confirmation_runs + confirmed * len(study.byzantines) * 2 * s.confirmation_runs)
