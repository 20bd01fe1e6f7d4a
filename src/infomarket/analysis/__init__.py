"""Analysis of simulation results (pandas in, pandas out), callable from notebooks.

``summarise`` is imported eagerly (the CLI prints it after every run); the figure and report
functions, which need matplotlib and scipy, load on first use::

    from infomarket import analysis
    fig = analysis.fig2(store.robots())           # a matplotlib Figure
    table = analysis.headline_table("results/")   # paper vs this store, one row per headline number
"""
from importlib import import_module

from .summary import summarise

_LAZY = {
    "fig2": "figures", "fig3": "figures", "fig4": "figures", "fig5": "figures", "fig6": "figures",
    "fig7": "figures", "FIGURES": "figures",
    "headline_table": "headline", "load_rules": "headline",
    "build_report": "report", "collect_provenance": "provenance",
    "Frames": "frames", "MissingDataError": "frames",
    "mann_whitney": "stats", "pearson": "stats", "mean_band": "stats", "regression_band": "stats",
    "compare": "stats", "holm": "stats", "tost": "stats", "paired": "stats", "median_ratio": "stats",
    "hodges_lehmann": "stats", "cliffs_delta": "stats",
    "swarm_throughput": "metrics", "wealth_curves": "metrics",
}

__all__ = ["summarise", *_LAZY]  # noqa: PLE0604 - the keys of _LAZY, all strings


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
