"""Quantities derived from the tables, shared by the figures and the headline table so both always
show the same numbers.  Pure pandas/numpy; nothing here plots or judges."""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..registry import get_payment
from .frames import MissingDataError, require

THETA_DEG = get_payment("outlier").defaults["theta"]  # outlier threshold (paper, Fig. 7): the scheme's default
RUN = ["condition", "run"]  # a run is unique within one experiment by (condition, run)


def median(robots: pd.DataFrame, column: str, honest: bool) -> float:
    """Median of ``column`` over the honest (or Byzantine) robots of every run of a panel."""
    values = robots.loc[robots["honest"] == honest, column]
    if values.empty:
        raise MissingDataError(f"no {'honest' if honest else 'Byzantine'} robots in {_name(robots)}")
    return float(values.median())


def iqr(values: pd.Series) -> float:
    """Interquartile range (75th minus 25th percentile) of ``values``, the spread the paper's box plots show."""
    return float(values.quantile(0.75) - values.quantile(0.25))


def share_gap_pp(robots: pd.DataFrame) -> float:
    """Median wealth share of honest robots minus that of Byzantine robots, in percentage points."""
    return 100.0 * (median(robots, "wealth_share", True) - median(robots, "wealth_share", False))


def swarm_throughput(robots: pd.DataFrame) -> pd.DataFrame:
    """Fig. 7's metric: items collected by the whole swarm after the transitory period, one row per run,
    with the sweep keys (byzantines, market, rotation_angle) kept."""
    rows = require(robots, "fig7", ("byzantines", "market", "rotation_angle", "items_collected"))
    keys = ["byzantines", "market", "rotation_angle", *RUN]
    out = rows.groupby(keys, observed=True)["items_collected"].sum().rename("throughput").reset_index()
    return out


def wealth_curves(history: pd.DataFrame, robots: pd.DataFrame | None = None,
                  name: str = "fig5") -> dict[str, dict[bool, pd.DataFrame]]:
    """Per-run mean wealth and mean wealth share of honest and Byzantine robots at every recorded step.

    Returns ``{"wealth": {True: df, False: df}, "share": {...}}`` where each df is runs x steps.  The
    mean is taken over a group's robots within each run first, so runs (independent) are the samples
    of any confidence band, not robots (which interact).  Steps missing from some run are dropped.
    A history without an ``honest`` column takes it from ``robots`` (same experiment, run and robot)."""
    h = require(history, name, ("step", "robot", "wealth")).copy()
    if "honest" not in h.columns:
        if robots is None:
            raise MissingDataError(f"{name}: the history has no honest column and no robots table was given")
        extra = [c for c in ("honest", "behaviour") if c not in h.columns and c in robots.columns]
        who = require(robots, name, ("robot", "honest"))[[*RUN, "robot", *extra]]
        h = h.merge(who, on=[*RUN, "robot"], how="inner")
        if h.empty:
            raise MissingDataError(f"{name}: history and robots tables share no run")
    total = h.groupby([*RUN, "step"], observed=True)["wealth"].transform("sum")
    h["share"] = np.where(total > 0, h["wealth"] / total.where(total > 0, 1.0), 0.0)
    per_run = h.groupby(["honest", *RUN, "step"], observed=True)[["wealth", "share"]].mean()
    out: dict[str, dict[bool, pd.DataFrame]] = {"wealth": {}, "share": {}}
    for honest in (True, False):
        if honest not in per_run.index.get_level_values("honest"):
            continue
        group = per_run.xs(honest, level="honest")
        for col in ("wealth", "share"):
            out[col][honest] = group[col].unstack("step").dropna(axis=1)
    if True not in out["wealth"]:
        raise MissingDataError(f"{name}: no honest robots in the history")
    return out


#: Fig. 6's caption: drift against wealth "after 15 000 timesteps" (the runs themselves last 100 000).
FIG6_STEP = 15000


def drift_and_share(robots: pd.DataFrame, history: pd.DataFrame, name: str,
                    step: int = FIG6_STEP) -> tuple[pd.DataFrame, str]:
    """Honest robots' |drift| and wealth share for Fig. 6: at ``step`` when the history recorded it
    (the paper's caption), else at the end of the runs.  Returns the rows and a label saying which."""
    rows = robots[robots["experiment"] == name] if "experiment" in robots.columns else robots
    rows = require(rows, name, ("drift", "wealth_share", "honest"))
    h = history[history["experiment"] == name] if len(history) and "experiment" in history.columns else history
    if len(h) and step in set(h["step"].unique()):
        at = h[h["step"] == step][[*RUN, "robot", "wealth"]]
        total = at.groupby(RUN, observed=True)["wealth"].transform("sum")
        at = at.assign(share_at=at["wealth"] / total.where(total > 0, 1.0))
        rows = rows.merge(at[[*RUN, "robot", "share_at"]], on=[*RUN, "robot"], how="inner")
        rows = rows.assign(wealth_share=rows["share_at"]).drop(columns="share_at")
        label = f"after {step:,} steps".replace(",", " ")
    else:
        steps = int(rows["steps"].iloc[0]) if "steps" in rows.columns else None
        label = "at the end of the runs" if steps is None else f"after {steps:,} steps".replace(",", " ")
    honest = rows[rows["honest"]]
    return honest.assign(abs_drift=honest["drift"].abs()), label


def behaviour_label(rows: pd.DataFrame, honest: bool) -> str:
    """The behaviours of the honest (or Byzantine) robots of a panel, e.g. ``sceptical``."""
    names = []
    if {"behaviour", "honest"} <= set(rows.columns):
        names = sorted(rows.loc[rows["honest"] == honest, "behaviour"].astype(str).unique())
    return ", ".join(names) or ("honest" if honest else "Byzantine")


def _name(rows: pd.DataFrame) -> str:
    if "experiment" in rows.columns and len(rows):
        return str(rows["experiment"].iloc[0])
    return "the panel"
