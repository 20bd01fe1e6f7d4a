"""What a run is worth: the per-run values an attack search optimises and a report compares.

``items``: items collected by the honest robots in the counted steps, per honest robot (the attacker
minimises it); ``liar_wealth``: the Byzantine robots' summed wealth share (the attacker maximises it).
``loss`` turns either into the number CMA-ES minimises.
"""
from __future__ import annotations

import pandas as pd

from ..errors import ArgumentError

OBJECTIVES = {"items": "honest items per honest robot (minimised)",
              "liar_wealth": "the Byzantine robots' wealth share (maximised)"}


def per_run(robots: pd.DataFrame) -> pd.DataFrame:
    """One row per (experiment, condition, run): ``items`` and ``liar_wealth``."""
    df = robots.assign(h_items=robots.items_collected.where(robots.honest, 0),
                       h=robots.honest.astype(int),
                       b_share=robots.wealth_share.where(~robots.honest, 0.0))
    g = df.groupby(["experiment", "condition", "run"], sort=True)
    out = g.agg(h_items=("h_items", "sum"), h=("h", "sum"), liar_wealth=("b_share", "sum")).reset_index()
    out["items"] = out.h_items / out.h.clip(lower=1)
    return out[["experiment", "condition", "run", "items", "liar_wealth"]]


def loss(values, objective: str):
    """What the optimiser minimises: honest items as they are, liars' wealth negated."""
    if objective == "items":
        return values
    if objective == "liar_wealth":
        return -values
    raise ArgumentError(f"unknown objective {objective!r}; allowed: {', '.join(OBJECTIVES)}")
