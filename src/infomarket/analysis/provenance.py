"""Where a report's numbers come from: package versions, configuration hashes, seeds, runs, dates.

Read from the runs table (one row per committed run) and store.json, so a report can be traced to
the exact configurations and seeds that produced it and rerun run by run.
"""
from __future__ import annotations

import datetime as dt
from dataclasses import dataclass

import pandas as pd

from .._version import __version__
from .frames import Frames

LISTED = 3  # list up to this many distinct values in a cell; beyond, give the count


@dataclass(frozen=True)
class Provenance:
    """Where a report's numbers come from: report-wide facts (dates, versions, totals) and one row per experiment."""
    facts: dict[str, str]          # report-wide: dates, versions, totals
    experiments: pd.DataFrame      # one row per experiment


def _few(values) -> str:
    distinct = sorted({str(v) for v in values if pd.notna(v)})
    if len(distinct) <= LISTED:
        return ", ".join(distinct) or "-"
    return f"{len(distinct)} distinct ({', '.join(distinct[:2])}, ...)"


def _seeds(values: pd.Series) -> str:
    s = pd.Series(values).dropna().astype("uint64")
    if s.empty:
        return "-"
    if s.nunique() <= LISTED:
        return ", ".join(str(v) for v in sorted(s.unique()))
    return f"{s.nunique()} distinct, {s.min()} .. {s.max()}"


def collect_provenance(source, store_path: str | None = None) -> Provenance:
    """The provenance of the tables of ``source`` (anything ``Frames.of`` reads)."""
    f = Frames.of(source)
    runs = f.runs
    facts = {
        "report date": dt.datetime.now(dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "report made by": f"infomarket {__version__}",
    }
    if store_path:
        facts["store"] = str(store_path)
    if f.meta:
        facts["store created"] = str(f.meta.get("created", "-"))
        facts["store created by"] = f"infomarket {f.meta.get('package_version', '?')}"
    facts["runs in the store"] = str(len(runs))
    if runs.empty:
        return Provenance(facts, pd.DataFrame())
    if "package_version" in runs.columns:
        facts["package versions of the runs"] = _few(runs["package_version"])
    rows = []
    for name, g in runs.groupby("experiment", sort=True):
        rows.append({
            "experiment": name,
            "runs": len(g),
            "conditions": g["condition"].nunique() if "condition" in g.columns else 1,
            "steps": _few(g.get("steps", [])),
            "transitory": _few(g.get("transitory", [])),
            "config hashes": _few(g.get("config_hash", [])),
            "seeds": _seeds(g["seed"]) if "seed" in g.columns else "-",
            "package versions": _few(g.get("package_version", [])),
            "status": ", ".join(f"{k}: {v}" for k, v in g["status"].value_counts().sort_index().items())
            if "status" in g.columns else "-",
        })
    return Provenance(facts, pd.DataFrame(rows))
