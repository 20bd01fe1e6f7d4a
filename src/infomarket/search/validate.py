"""``infomarket attack-search --validate``: how often each searcher recovers a planted weakness.

Every planted cell (``search.planted``) is searched by the study's own driver (``driver.search_cell``,
with the study's settings and baselines) on a runner that evaluates the planted landscape instead of
simulating, so a search of a cell takes seconds, not hours.  For each cell and each seed of the
validation, a searcher (the search, the random search, the best baseline) recovers the weakness when the
attack it chose on the selection seeds has a true damage of at least ``planted.RECOVERED`` of the known
optimum.  The recovery rate per searcher is over every (cell, seed); it is printed, written to
``OUT/validation.json`` when an output folder is given, and carried into every study report.
"""
from __future__ import annotations

import dataclasses
import json
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd

from ..store import Store
from . import planted, space
from .driver import DEFAULTS, search_cell
from .restarts import stream
from .study import Cell, Study, cells

SEARCHERS = ("search", "random", "baseline")


def planted_runner(kind: planted.Kind):
    """``run(conds)`` for ``search_cell`` on a planted landscape: each run's items from the attacker's
    parameters and the run's seed (nothing is simulated or stored); ``run.robots(conds)`` gives them as
    one honest robot per run, the shape ``objective.per_run`` reads."""
    values: dict[tuple[str, str], dict[int, float]] = {}

    def params(c) -> dict:
        g = c.config.swarm.groups[1].params
        return {n: float(g.get(n, DEFAULTS[n])) for n in space.NAMES}

    def run(conds) -> tuple[int, int]:
        made = found = 0
        for c in conds:
            have = values.setdefault((c.experiment, c.id), {})
            p = params(c)
            for r in range(c.runs):
                if r in have:
                    found += 1
                else:
                    have[r] = planted.items(kind, p, c.seed(r))
                    made += 1
        return made, found

    def robots(conds) -> pd.DataFrame:
        rows = [(c.experiment, c.id, r, v) for c in conds for r, v in sorted(values[(c.experiment, c.id)].items())]
        df = pd.DataFrame(rows, columns=["experiment", "condition", "run", "items_collected"])
        return df.assign(honest=True, wealth_share=0.0)

    run.robots = robots
    return run


def planted_cell(study: Study, kind: planted.Kind) -> Cell:
    """A cell named after the planted kind, on the study's first cell's configuration (whose seed keys
    the runs; its simulation is never run)."""
    first = cells(study)[0]
    return Cell(f"planted_{kind.name}", first.byzantines, first.config)


def recover(study: Study, kind: planted.Kind, seed: int) -> dict:
    """One planted cell searched with ``seed``: each searcher's chosen attack, its true damage and
    whether it recovered the weakness."""
    st = dataclasses.replace(study, settings=dataclasses.replace(study.settings, seed=seed))
    cell = planted_cell(st, kind)
    with tempfile.TemporaryDirectory() as folder:
        r = search_cell(st, cell, Store(Path(folder) / "store"), run=planted_runner(kind))
    row = {"kind": kind.name, "seed": seed}
    for who in SEARCHERS:
        label = r.chosen.get(who)
        if label is None:
            continue
        d = planted.damage(kind, {**DEFAULTS, **r.params[label]})
        row[who] = {"attack": label, "damage": round(d, 4),
                    "recovered": bool(d >= planted.RECOVERED * planted.OPTIMUM)}
    return row


def validate(study: Study, repeats: int, *, kinds: list[str] | None = None, seed: int | None = None,
             echo=None) -> dict:
    """Every planted kind (or those named) searched ``repeats`` times (validation seeds derived from
    ``seed``, default the study's, never equal to it): the rows and the recovery rate per searcher."""
    base = study.settings.seed if seed is None else seed
    rows = []
    t0 = time.perf_counter()
    for k in kinds or list(planted.KINDS):
        for i in range(repeats):
            row = recover(study, planted.KINDS[k], stream(base, "planted", i) % 2**31)
            rows.append(row)
            if echo:
                echo(row)
    rates = {who: float(np.mean([r[who]["recovered"] for r in rows if who in r])) for who in SEARCHERS
             if any(who in r for r in rows)}
    return {"rates": rates, "repeats": repeats, "kinds": kinds or list(planted.KINDS), "rows": rows,
            "seconds": round(time.perf_counter() - t0, 1)}


def line(row: dict) -> str:
    return f"{row['kind']:<11} seed {row['seed']:>10}  " + "  ".join(
        f"{who} {row[who]['damage']:.2f}{'*' if row[who]['recovered'] else ' '}" for who in SEARCHERS if who in row)


def text(result: dict) -> str:
    out = [f"Planted weaknesses: {len(result['kinds'])} kinds x {result['repeats']} seeds; recovered (*) = true "
           f"damage >= {planted.RECOVERED:.0%} of the optimum {planted.OPTIMUM:g} items.",
           "Recovery rate per searcher: " + ", ".join(f"{k} {v:.0%}" for k, v in result["rates"].items())]
    for k in result["kinds"]:
        mine = [r for r in result["rows"] if r["kind"] == k]
        out.append(f"  {k:<11} " + ", ".join(f"{w} {np.mean([r[w]['recovered'] for r in mine]):.0%}"
                                             for w in SEARCHERS if all(w in r for r in mine)))
    return "\n".join(out)


def write(out: Path, result: dict) -> Path:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    p = out / "validation.json"
    p.write_text(json.dumps(result, indent=2) + "\n")
    return p
