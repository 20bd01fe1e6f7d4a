"""One cell's attack search: start points, a global search beside a random one, a race, a confirmation.

Every evaluation is a condition of the cell's experiment in a results store, run on the sweep machinery
(``runner.sweep.run_sweep``: inline, a local pool or Dask), which skips runs already committed.  The
phases, each on its own seed set (``phase`` and ``seed_set`` are condition keys, so the store records
which set every run belongs to):

1. **start** (search seeds): every baseline (the declared hand-written attacks and the rotation grid,
   ``search.baselines``) and the global search's start points, spread over the cube (``restarts.design``,
   a share of its budget), all on one seed set;
   then, with ``gate_rounds``, the structured start (``search.structured``): the best point's rotation
   moved, collusion switched, site changed and each gate opened or closed alone, on the same seeds, the
   leaders re-evaluated on ``leader_runs`` of them before each choice (``leaders``);
2. **search** and **random** (search seeds): CMA-ES restarted from the start points (``restarts``;
   restart 0 from the best point of the start phase, the others from the next best spread points), and
   beside it a random search with as many evaluations as the global search (start points included); all
   candidates of one generation share seeds (common random numbers), stream ("search", searcher,
   restart, generation); then, with ``refine``, the refinement (``search.refine``): the best points on a
   stream of their own, ("search", "refine", 0, 0), and rounds of moves around the best on it;
3. **selection** (one shared seed set): the best distinct points of each searcher (the best point it ever
   evaluated first; with ``pool_baselines`` the baselines among the search's, and the search keeping a
   baseline that raced better than its finalists) and every baseline race by successive halving
   (``racing``); each role of ``CellSearch.chosen`` is decided here, on these seeds only (with
   ``confirm_top`` k, each group's k best: ``search_2`` ...);
4. **confirmation** (one shared seed set no other phase uses): the chosen attacks and the truthful
   reference, every one on every run, paired by run.  The worst case is reported from these runs only.

The streams are keyed by the study's seed, so a study declared with a new seed gets confirmation seeds no
earlier run (pilot or reduced) touched.  Nothing of the optimisers' state is kept: a search that starts
again (after a crash or SIGKILL) replays every phase from the seeds, finds the runs committed and makes
the same decisions; a replay that asked another point would need another configuration under the same
condition, which the store refuses (``runner.sweep.check_compatible``).  The store's metadata records the
questions file's commit and the time of the study's first run (``record_provenance``).
"""
from __future__ import annotations

import datetime
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..behaviours.attacks import POLICY
from ..errors import InternalError
from ..runner.plan import Condition, condition_number
from ..runner.sweep import run_sweep
from ..seeds import run_seed
from ..store import Store
from . import provenance as _prov
from . import space
from .objective import loss, per_run
from .racing import merged, race, survivors
from . import refine, structured
from .restarts import (Restarts, design, evaluations, gate_points, random_batches, refine_points, spread_points,
                       stream)
from .study import QUESTIONS, Cell, Settings, Study

PHASES = ("start", "search", "random", "selection", "confirmation")
SEED_SET = {"start": "search", "search": "search", "random": "search", "selection": "selection",
            "confirmation": "confirmation"}
#: the race's groups: the searcher whose points each holds (the start points belong to the global search)
GROUPS = {"search": ("start", "gates", "cma", "refine"), "random": ("random",)}
POOLED = ("baseline",)  # with ``pool_baselines``, the baselines race in the search's pool too
ROLES = ("search", "random", "baseline")
DEFAULTS = {p[0]: float(p[1]) for p in POLICY}


@dataclass(frozen=True)
class CRNCondition(Condition):
    """A condition whose runs use a seed stream of their own choosing (``crn``), shared with other
    conditions: the common random numbers of one generation, of the race or of the confirmation."""

    crn: int = 0

    def seed(self, run: int) -> int:
        """The seed of run ``run`` from the stream ``crn``, shared by the conditions compared together (common
        random numbers: the same swarms for each)."""
        return run_seed(self.master_seed, run, self.crn)


@dataclass
class CellSearch:
    """What the search of one cell found (docs/attack-search.md describes each frame)."""

    cell: Cell
    candidates: pd.DataFrame    # searcher, restart, gen, cand, label, fitness, then the parameters
    selection: pd.DataFrame     # attack, run, items, liar_wealth: the race on the selection seeds
    confirmation: pd.DataFrame  # attack, run, items, liar_wealth: the chosen attacks, every confirmation run
    chosen: dict[str, str]      # role (search, random, baseline, worst, reference) -> attack label
    params: dict[str, dict]     # attack label -> its attacker parameters
    cost: dict                  # phase -> {"runs", "env_steps", "seconds"}
    done: int = 0               # runs made now
    skipped: int = 0            # runs found in the store
    confirmation_seeds: list[int] = field(default_factory=list)  # the run seeds of confirmation runs 0, 1, ...
    extra: dict[str, pd.DataFrame] = field(default_factory=dict)  # other searchers' confirmation runs


def seed_stream(s: Settings, *parts) -> int:
    """The seed stream of a seed set: ("search", searcher, restart, gen), ("selection",), ("confirmation",)."""
    return stream(s.seed, *parts)


def confirmation_seeds(study: Study, cell: Cell, runs: int | None = None) -> list[int]:
    """The run seeds of the cell's confirmation runs 0..runs-1 (default: the declared count)."""
    s = study.settings
    crn = seed_stream(s, "confirmation")
    return [run_seed(cell.config.seed, k, crn) for k in range(s.confirmation_runs if runs is None else runs)]


def provenance(questions=QUESTIONS) -> dict:
    """The questions file's identity (its last commit, whether it differs from it, its SHA-256) and the
    code's commit with whether the tree was clean (``search.provenance``)."""
    return {**_prov.questions(questions), **_prov.code()}


def record_provenance(store: Store, questions=QUESTIONS, key: str = "attack_search") -> dict:
    """Record in the store's metadata (``store.json``, under ``key``), once, before the study's first run:
    the questions file's commit and hash, the code's commit, and the UTC time of the first run."""
    with store.writing():
        meta = store.meta()
        if key not in meta:
            first = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
            meta[key] = {**provenance(questions), "first_run_utc": first}
            store._write_meta(meta)  # under the store's lock, as Store writes it
        return meta[key]


class _Evaluator:
    """Runs conditions of one cell and remembers each run's values; counts each phase's cost."""

    def __init__(self, study: Study, cell: Cell, store: Store, run, steps, transitory):
        self.s, self.cell, self.store, self.run = study.settings, cell, store, run
        self.steps, self.transitory = steps, transitory
        self.robots = getattr(run, "robots", None) or (lambda conds: _robots(store, cell))
        self.values: dict[str, dict[int, tuple[float, float]]] = {}
        self.counted: dict[str, int] = {}
        self.cost = {p: {"runs": 0, "env_steps": 0, "seconds": 0.0} for p in PHASES}
        self.done = self.skipped = 0
        self.length = cell.with_attack({}, steps=steps, transitory=transitory).steps

    def condition(self, params: dict, phase: str, searcher: str, restart: int, gen: int, cand: int, attack: str,
                  runs: int, crn: int) -> CRNCondition:
        keys = {"phase": phase, "seed_set": SEED_SET[phase], "searcher": searcher, "restart": restart, "gen": gen,
                "cand": cand, "attack": attack}
        cid = ",".join(f"{k}={keys[k]}" for k in sorted(keys))
        cfg = self.cell.with_attack(params, steps=self.steps, transitory=self.transitory)
        return CRNCondition(self.cell.experiment, cid, keys, cfg, runs, cfg.seed, condition_number(cid), crn=crn)

    def evaluate(self, conds: list[CRNCondition]) -> list[pd.DataFrame]:
        """Each condition's runs 0..runs-1 (made where missing): frames of run, items, liar_wealth."""
        t0 = time.perf_counter()
        made, found = self.run(conds)
        self.done, self.skipped = self.done + made, self.skipped + found
        # the runs' own seconds (summed over workers) where the runner says them: the call's wall time also
        # holds other searches' runs when several share the workers (runner.feed)
        ran = getattr(self.run, "seconds", None)
        if any(k not in self.values.get(c.id, {}) for c in conds for k in range(c.runs)):
            per = per_run(self.robots(conds))
            per = per[per.condition.isin({c.id for c in conds})]
            for cid, r, items, lw in zip(per.condition, per.run, per["items"], per.liar_wealth):
                self.values.setdefault(cid, {})[int(r)] = (float(items), float(lw))
        seconds = time.perf_counter() - t0 if ran is None else ran
        new = {c.id: c.runs - self.counted.get(c.id, 0) for c in conds}
        total = max(1, sum(new.values()))
        out = []
        for c in conds:
            have = self.values.get(c.id, {})
            missing = [k for k in range(c.runs) if k not in have]
            if missing:
                raise InternalError(f"{c.experiment} [{c.id}]: runs {missing[:5]} were run but not found")
            cost = self.cost[c.keys["phase"]]
            cost["runs"] += new[c.id]
            cost["env_steps"] += new[c.id] * self.length
            cost["seconds"] += seconds * new[c.id] / total
            self.counted[c.id] = max(self.counted.get(c.id, 0), c.runs)
            out.append(pd.DataFrame({"run": np.arange(c.runs), "items": [have[k][0] for k in range(c.runs)],
                                     "liar_wealth": [have[k][1] for k in range(c.runs)]}))
        return out

    def fitness(self, frame: pd.DataFrame) -> float:
        return float(np.mean(loss(frame[self.s.objective].to_numpy(float), self.s.objective)))


def search_cell(study: Study, cell: Cell, store: Store, *, run: Callable[[list[Condition]], tuple[int, int]],
                steps: int | None = None, transitory: int | None = None, starts: np.ndarray | None = None
                ) -> CellSearch:
    """Search one cell (the module's docstring gives the phases).  ``run(conds)`` runs the missing runs of
    ``conds`` into ``store`` and returns (runs made, runs skipped).  ``starts``: the global search's start
    points (default: ``restarts.design``, spread over the cube)."""
    s: Settings = study.settings
    ev = _Evaluator(study, cell, store, run, steps, transitory)
    record_provenance(store, getattr(study, "declaration_path", QUESTIONS))
    dim, seed = space.dimension(), stream(s.seed, cell.experiment)
    points = design(spread_points(s), dim, stream(seed, "design")) if starts is None else np.asarray(starts, float)
    rows: list[dict] = []

    def add(searcher, restart, gen, frames, conds, points):
        for i, (c, f) in enumerate(zip(conds, frames)):
            p = space.to_params(points[i]) if isinstance(points[i], np.ndarray) else {**DEFAULTS, **points[i]}
            rows.append({"searcher": searcher, "restart": restart, "gen": gen, "cand": i, "label": c.keys["attack"],
                         "fitness": ev.fitness(f), **{n: float(p[n]) for n in space.NAMES}})

    # 1. start: every baseline and every start point, on one seed set
    hand = {n: p for n, p in study.baselines.items() if n != study.reference}
    crn = seed_stream(s, "search", "start", 0, 0)
    base = [ev.condition(p, "start", "baseline", -1, -1, k, n, s.runs, crn) for k, (n, p) in enumerate(hand.items())]
    spread = [ev.condition(space.to_params(x), "start", "start", -1, -1, k, f"start{k}", s.runs, crn)
              for k, x in enumerate(points)]
    frames = ev.evaluate(base + spread)
    add("baseline", -1, -1, frames[:len(base)], base, list(hand.values()))
    add("start", -1, -1, frames[len(base):], spread, list(points))
    scores = [ev.fitness(f) for f in frames]
    firsts = [space.to_unit(p) for p in hand.values()] + list(points)
    every = base + spread  # the start phase's conditions, by index (the openings join them)

    def leaders() -> None:  # the best points so far run again on more of the start seeds (search.structured)
        if s.leaders:
            structured.reevaluate(ev, every, scores, rows, s.leaders, s.leader_runs)

    # the structured start: each gate opened alone on the best point not yet opened from (search.structured)
    opened: list[int] = []
    for g in range(s.gate_rounds):
        leaders()
        left = gate_points(s) - (len(firsts) - len(base) - len(points))
        best = min((k for k in range(len(scores)) if k not in opened), key=lambda k: (scores[k], k), default=None)
        if best is None or left <= 0:
            break
        opened.append(best)
        X = structured.openings(firsts[best])[:left]
        conds = [ev.condition(space.to_params(x), "start", "gates", g, 0, i, f"gate_g{g}c{i}", s.runs, crn)
                 for i, x in enumerate(X)]
        fr = ev.evaluate(conds)
        add("gates", g, 0, fr, conds, X)
        scores += [ev.fitness(f) for f in fr]
        firsts += X
        every += conds
    leaders()
    order = sorted(range(len(scores)), key=lambda k: (scores[k], k))  # ties: baselines first, then in order
    # restart 0 (or the first `local` ones) at the best points so far, the others at the next best spread points
    top = order[:max(1, s.local)]
    origins = top + [k for k in order if k >= len(base) and k not in top]

    def start(r: int) -> np.ndarray:
        return firsts[origins[r % len(origins)]] if origins else np.full(dim, 0.5)

    # 2. the global search and the random search, one generation of each per call (one batch of runs)
    cma = Restarts(s, dim, seed, start)
    batches = random_batches(s, dim, seed)
    j = 0
    while True:
        asked = cma.ask()
        conds, parts = [], []
        if asked is not None:
            r, g, X = asked
            crn = seed_stream(s, "search", "cma", r, g)
            conds += [ev.condition(space.to_params(x), "search", "cma", r, g, i, f"cma_r{r}g{g}c{i}", s.runs, crn)
                      for i, x in enumerate(X)]
            parts.append(("cma", r, g, len(X), list(X)))
        if j < len(batches):
            crn = seed_stream(s, "search", "random", 0, j)
            conds += [ev.condition(space.to_params(x), "random", "random", 0, j, i, f"random_g{j}c{i}", s.runs, crn)
                      for i, x in enumerate(batches[j])]
            parts.append(("random", 0, j, len(batches[j]), list(batches[j])))
            j += 1
        if not conds:
            break
        frames, k = ev.evaluate(conds), 0
        for searcher, r, g, n, X in parts:
            add(searcher, r, g, frames[k:k + n], conds[k:k + n], X)
            if searcher == "cma":
                cma.tell([ev.fitness(f) for f in frames[k:k + n]])
            k += n
    centre = _refine(ev, s, rows, add) if s.refine else None
    candidates = pd.DataFrame(rows)

    # 3. the race on the selection seeds: each searcher's best distinct points, every baseline
    ranked = candidates.assign(order=np.arange(len(candidates))).sort_values(["fitness", "order"], kind="stable")
    row = {r.label: r for r in candidates.itertuples(index=False)}
    groups = {}
    for role, members in GROUPS.items():
        members = members + (POOLED if role == "search" and s.pool_baselines else ())
        mine = ranked[ranked.searcher.isin(members)].drop_duplicates(list(space.NAMES))
        if len(mine):
            groups[role] = list(mine.label.head(s.finalists))
            if role == "search" and centre:  # the refined point (on more runs) first, its twins left out
                twin = {lab for lab in groups[role] if _key(row[lab]) == _key(row[centre])}
                groups[role] = [centre, *[lab for lab in groups[role] if lab not in twin][:s.finalists - 1]]
    if hand:
        groups["baseline"] = list(ranked[ranked.searcher == "baseline"].label)
    if study.reference:
        groups["reference"] = [study.reference]
    params = {lab: {n: float(getattr(row[lab], n)) for n in space.NAMES} for g in groups.values() for lab in g
              if lab in row}
    if study.reference:
        params[study.reference] = {**DEFAULTS, **study.baselines[study.reference]}
    searcher = {lab: g for g, labs in groups.items() for lab in labs}
    crn = seed_stream(s, "selection")
    selected: dict[str, pd.DataFrame] = {}

    def on_selection(labels: list[str], runs: int) -> dict[str, np.ndarray]:
        labels = list(dict.fromkeys(labels))  # a pooled baseline races in two groups, on the same runs
        conds = [_raced(ev, params[a], a, searcher[a], row.get(a), runs, crn) for a in labels]
        for a, f in zip(labels, ev.evaluate(conds)):
            selected[a] = f
        return {a: loss(selected[a][s.objective].to_numpy(float), s.objective) for a in labels}

    result = race(groups, tuple(s.race), s.keep, on_selection)
    if s.pool_baselines:  # the search keeps the best attack it raced beside: a baseline that beat it too
        keys: dict = {}
        for a in merged(result, "search", "baseline"):  # one label per attack (a refined twin of a baseline)
            keys.setdefault(_key(row[a]) if a in row else a, a)
        result.ranking["search"] = list(keys.values())
    chosen = {role: result.ranking[role][0] for role in ROLES if result.ranking.get(role)}
    median = {a: float(np.median(loss(selected[a][s.objective].to_numpy(float), s.objective))) for a in chosen.values()}
    if chosen:
        chosen["worst"] = min((chosen[r] for r in ROLES if r in chosen), key=lambda a: median[a])
    for role in ROLES:  # with confirm_top k, each group's next best attacks are confirmed too: role_2 .. role_k
        for k, a in enumerate(result.ranking.get(role, [])[1:s.confirm_top], start=2):
            chosen[f"{role}_{k}"] = a
    if study.reference:
        chosen["reference"] = study.reference
    selection = _frame(selected)

    # 4. the confirmation: the chosen attacks, every one on every confirmation run
    crn = seed_stream(s, "confirmation")
    labels = list(dict.fromkeys(chosen.values()))
    conds = [ev.condition(params[a], "confirmation", searcher[a], -1, -1, -1, a, s.confirmation_runs, crn)
             for a in labels]
    confirmation = _frame(dict(zip(labels, ev.evaluate(conds))))
    return CellSearch(cell, candidates, selection, confirmation, chosen,
                      {a: params[a] for a in dict.fromkeys([*selected, *labels])}, ev.cost, ev.done, ev.skipped,
                      confirmation_seeds(study, cell))


#: the best points of a refinement round run again on ``leader_runs`` seeds before the centre may move to one
GROW = 3


def _refine(ev: _Evaluator, s: Settings, rows: list[dict], add) -> str:
    """The last phase (``search.refine``): the search's best distinct points (twice ``leaders``) on a seed
    set of their own, ``leader_runs`` each; then rounds of moves around the best until the evaluations kept
    for them (``restarts.refine_points``) are spent, each round's ``GROW`` best grown to ``leader_runs`` runs
    on the same seeds, the centre moved to one only if it beats the centre there, the step halved after a
    round that does not.  Returns the label of the last centre."""
    group = GROUPS["search"] + (POOLED if s.pool_baselines else ())
    lead: list[np.ndarray] = []
    for r in sorted((r for r in rows if r["searcher"] in group), key=lambda r: r["fitness"]):  # stable: ties in order
        z = space.to_unit({n: r[n] for n in space.NAMES})
        if not any(np.allclose(z, y) for y in lead):
            lead.append(z)
        if len(lead) == max(1, 2 * s.leaders):
            break
    crn = seed_stream(s, "search", "refine", 0, 0)
    conds = [ev.condition(space.to_params(z), "search", "refine", -1, 0, i, f"refine_l{i}", s.leader_runs, crn)
             for i, z in enumerate(lead)]
    frames = ev.evaluate(conds)
    add("refine", -1, 0, frames, conds, lead)
    scores = [ev.fitness(f) for f in frames]
    c = int(np.argmin(scores))
    centre, best, step, label = lead[c], scores[c], s.refine_step, conds[c].keys["attack"]
    left, g = refine_points(s), 0
    while True:
        X = refine.moves(centre, step)[:left]
        if not X:
            break
        conds = [ev.condition(space.to_params(x), "search", "refine", g, 0, i, f"refine_r{g}c{i}", s.runs, crn)
                 for i, x in enumerate(X)]
        frames = ev.evaluate(conds)
        add("refine", g, 0, frames, conds, X)
        scores = [ev.fitness(f) for f in frames]
        structured.reevaluate(ev, conds, scores, rows[len(rows) - len(X):], min(GROW, len(X)), s.leader_runs)
        grown = [k for k in range(len(X)) if conds[k].runs >= s.leader_runs]
        k = min(grown, key=lambda k: (scores[k], k), default=None)
        if k is not None and scores[k] < best:
            centre, best, label = X[k], scores[k], conds[k].keys["attack"]
        else:
            step /= 2
        left, g = left - len(X), g + 1
    return label


def planned_runs(study: Study) -> int:
    """The runs of one cell's search (at most: fewer when two roles choose the same attack, or a searcher
    found fewer distinct points than ``finalists``)."""
    s = study.settings
    hand = len([n for n in study.baselines if n != study.reference])
    n_eval = evaluations(s)
    sizes = [min(s.finalists, n_eval + (hand if s.pool_baselines else 0)), min(s.finalists, n_eval), hand,
             int(bool(study.reference))]
    selection = 0
    for n in sizes:
        before = 0
        for i, runs in enumerate(s.race):
            selection += n * (runs - before)
            before = runs
            if i < len(s.race) - 1:
                n = survivors(n, s.keep)
    roles = sum(min(n, s.confirm_top) for n in sizes[:3] if n) + int(bool(study.reference))
    leaders = (s.gate_rounds + 1) * s.leaders * max(0, s.leader_runs - s.runs)  # re-evaluations, at most
    if s.refine:  # the refinement's leaders, and its rounds' best grown (its moves are in n_eval)
        rounds = -(-refine_points(s) // 2)  # a round moves two points at the fewest (the rotation's)
        leaders += max(1, 2 * s.leaders) * s.leader_runs + rounds * GROW * max(0, s.leader_runs - s.runs)
    return (hand + 2 * n_eval) * s.runs + leaders + selection + roles * s.confirmation_runs


def _key(row) -> tuple:
    """An attack's parameters as a key: two labels of one attack (a refined point equal to a baseline) are
    one attack, raced and confirmed once."""
    return tuple(float(getattr(row, n)) for n in space.NAMES)


def _raced(ev: _Evaluator, params: dict, label: str, group: str, row, runs: int, crn: int) -> CRNCondition:
    """The selection condition of one raced attack (the same condition at every stage, its runs grown)."""
    where = (int(row.restart), int(row.gen), int(row.cand)) if row is not None else (-1, -1, -1)
    return ev.condition(params, "selection", group, *where, label, runs, crn)


def _frame(per: dict[str, pd.DataFrame]) -> pd.DataFrame:
    cols = ["attack", "run", "items", "liar_wealth"]
    if not per:
        return pd.DataFrame(columns=cols)
    return pd.concat([f.assign(attack=a) for a, f in per.items()], ignore_index=True)[cols]


def _robots(store: Store, cell: Cell) -> pd.DataFrame:
    r = store.robots()
    return r[r.experiment == cell.experiment]


def store_runner(store: Store, *, workers: int = 1, executor=None,
                 on_done: Callable[[int], None] | None = None,
                 on_skip: Callable[[int], None] | None = None,
                 feed=None) -> Callable[[list[Condition]], tuple[int, int]]:
    """``run(conds)`` for ``search_cell``: their missing runs into ``store`` on the sweep machinery.
    A condition run again with more runs (a race's next stage) counts only its new runs as made or found.
    ``run.robots(conds)``: the robots rows of ``conds``, kept from the parts just written when every run of
    theirs was made by this runner (the store is read back only for a search that resumes): reading the
    whole store after every generation cost the parent more the larger the store grew, while the
    workers waited.  ``feed`` (a ``runner.feed.Feed``): sweep there instead, so that several searches run
    by ``run.map(jobs)`` keep the workers fed together; without one ``run.map`` runs the jobs in turn."""
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

    seen: dict[tuple[str, str], int] = {}  # runs of a condition already counted (a race grows its runs)

    def run(conds: list[Condition]) -> tuple[int, int]:
        before = sum(seen.get((c.experiment, c.id), 0) for c in conds)
        planned = sum(c.runs for c in conds) - before
        rep = (feed.sweep if feed is not None else run_sweep)(
            conds, store, workers=workers, executor=executor, on_done=on_done,
            on_plan=(lambda todo: on_skip(planned - todo)) if on_skip else None, on_part=keep)
        if rep.failed:
            from ..errors import SimulationError  # only when a run failed

            raise SimulationError(f"{rep.failed} of {rep.done} runs failed (the first: {rep.first_error}); "
                                  f"`infomarket store failed {store.root}` lists them")
        for c in conds:
            seen[(c.experiment, c.id)] = max(c.runs, seen.get((c.experiment, c.id), 0))
        run.seconds = rep.run_seconds  # read by the caller at once, before another search's turn
        return rep.done, rep.skipped - before

    run.robots = robots
    run.map = feed.map if feed is not None else (lambda jobs: [job() for job in jobs])
    return run
