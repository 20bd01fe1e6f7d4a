"""``infomarket demo``: a short version of the paper's Fig. 2, to see the whole story in a minute.

Naive robots navigate well together (2A) until one saboteur joins (2B); sceptical robots pay for
their caution (2C) but keep their chain when a scaboteur joins (2D).
"""
from __future__ import annotations

import time

from rich.console import Console
from rich.table import Table

from .config import load_experiment
from .runner.batch import run_conditions
from .runner.execute import default_workers
from .runner.plan import conditions
from .runner.progress import progress

SETUPS = (("fig2A", "25 naive"), ("fig2B", "24 naive + 1 saboteur"),
          ("fig2C", "25 sceptical"), ("fig2D", "24 sceptical + 1 scaboteur"))


def run_demo(runs: int = 8, workers: int | None = None) -> int:
    """Run Fig. 2's four setups ``runs`` times each and print a table of items per robot beside the paper's.

    Args:
        runs: runs per setup (shorter than the paper's, to take about a minute).
        workers: processes to use (default: ``runner.execute.default_workers``).

    Returns:
        The exit code.
    """
    console = Console()
    workers = workers or default_workers()
    table = Table(title=f"Items collected per robot in 15 000 steps (median of {runs} runs per setup)")
    for col in ("panel", "swarm", "honest robots", "Byzantine robots", "paper (honest)"):
        table.add_column(col, justify="left" if col in ("panel", "swarm") else "right")
    paper = {"fig2A": "20", "fig2B": "~10 (halves)", "fig2C": "below 2A", "fig2D": "~2C, ~2x 2B"}
    t0 = time.perf_counter()
    steps = 0
    conds = [c for name, _ in SETUPS for c in conditions(load_experiment(name), runs=runs)]
    with progress("demo", runs * len(SETUPS)) as bar:  # one pool, one warm-up for the four kernels
        results = run_conditions(conds, workers=workers, on_done=bar.advance)
    for (name, swarm), res in zip(SETUPS, results):
        steps += runs * res.steps
        d = res.robots
        honest = d[d.honest].items_collected.median()
        byz = d[~d.honest].items_collected
        table.add_row(name.removeprefix("fig"), swarm, f"{honest:g}",
                      f"{byz.median():g}" if len(byz) else "-", paper[name])
    wall = time.perf_counter() - t0
    console.print(table)
    console.print(f"{len(SETUPS) * runs} runs, {steps:,} env-steps in {wall:.1f} s wall "
                  f"({steps / wall:,.0f} env-steps/s on {workers} worker(s), compilation included).")
    console.print("Next: .venv/bin/infomarket run fig2B --runs 16  |  .venv/bin/infomarket list  |  docs/extending.md")
    return 0
