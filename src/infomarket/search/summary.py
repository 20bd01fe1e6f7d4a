"""What a search leaves beside its store: each cell's frames as Parquet, and a short summary.

``OUT/cells/EXPERIMENT/{candidates,selection,confirmation}.parquet`` hold ``CellSearch``'s frames (every
evaluation, the race, the confirmation runs), so a report can be made again without the search;
``OUT/search.json`` and the text printed give per cell the chosen attacks and their confirmation medians:
a description of what was found, not the study's answers (those need the paired statistics of the
report, ``search.report``).
"""
from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

import numpy as np

from ..store.files import write_parquet_atomic, write_text_atomic
from .driver import CellSearch
from .study import Study

FRAMES = ("candidates", "selection", "confirmation")


def cell_summary(study: Study, r: CellSearch) -> dict:
    """The chosen attacks of one cell, their confirmation medians, and the search's size and cost."""
    obj = study.settings.objective
    conf = r.confirmation
    median = {a: float(np.median(conf[conf.attack == a][obj])) for a in dict.fromkeys(r.chosen.values())}
    out = {"defence": r.cell.defence, "byzantines": r.cell.byzantines, "experiment": r.cell.experiment,
           "evaluations": {k: int(v) for k, v in r.candidates.searcher.value_counts().sort_index().items()},
           "chosen": dict(r.chosen), "confirmation_median": median,
           "params": {a: r.params[a] for a in median}, "cost": r.cost, "runs_made": r.done, "runs_found": r.skipped}
    ref = r.chosen.get("reference")
    if ref and "worst" in r.chosen and median[ref]:
        out["worst_loss"] = 1.0 - median[r.chosen["worst"]] / median[ref]
    return out


def write(out: Path, study: Study, results: list[CellSearch], *, reduced: str = "", wall_seconds: float | None = None,
          steps: int | None = None, transitory: int | None = None) -> tuple[list[Path], str]:
    """The frames and ``search.json`` into ``out``; returns the paths written and the summary's text."""
    out = Path(out)
    paths = []
    for r in results:
        folder = out / "cells" / r.cell.experiment
        folder.mkdir(parents=True, exist_ok=True)
        for name in FRAMES:
            paths.append(write_parquet_atomic(getattr(r, name), folder / f"{name}.parquet"))
    cells = [cell_summary(study, r) for r in results]
    data = {"reduced": reduced, "wall_seconds": wall_seconds, "steps": steps, "transitory": transitory,
            "objective": study.settings.objective, "settings": asdict(study.settings), "cells": cells}
    paths.append(write_text_atomic(json.dumps(data, indent=2) + "\n", out / "search.json"))
    return paths, text(data)


def text(data: dict) -> str:
    """The search's summary ``data`` as a short Markdown table: each cell's chosen attacks and confirmation
    medians."""
    lines = ["# Attack search (summary)", ""]
    if data["reduced"]:
        lines += [f"**REDUCED RUN ({data['reduced']}): not the declared study.**", ""]
    lines += [f"Objective {data['objective']}; medians on the confirmation seeds.", "",
              "| defence | Byzantines | search | random | baseline | worst | reference | worst loss |",
              "|---|---|---|---|---|---|---|---|"]
    for c in data["cells"]:
        m = c["confirmation_median"]
        role = [f"{c['chosen'][k]} ({m[c['chosen'][k]]:.3g})" if k in c["chosen"] else "–"
                for k in ("search", "random", "baseline", "worst", "reference")]
        loss = f"{c['worst_loss']:.1%}" if "worst_loss" in c else "–"
        lines.append(f"| {c['defence']} | {c['byzantines']} | " + " | ".join(role) + f" | {loss} |")
    return "\n".join(lines) + "\n"
