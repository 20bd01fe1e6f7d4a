"""Per-behaviour summaries of a robots table (one row per robot per run)."""
from __future__ import annotations

import pandas as pd


def summarise(robots: pd.DataFrame) -> pd.DataFrame:
    """Per behaviour: robots per run, honest or not, median items collected, median wealth share (%)."""
    runs = max(robots["run"].nunique(), 1) if "run" in robots else 1
    g = robots.groupby("behaviour", observed=True, sort=False)
    out = pd.DataFrame({
        "robots": g.size() // runs,
        "honest": g["honest"].first(),
        "median_items": g["items_collected"].median(),
        "median_wealth_share_pct": 100.0 * g["wealth_share"].median(),
    })
    return out.reset_index()
