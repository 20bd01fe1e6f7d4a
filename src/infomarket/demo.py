"""``infomarket demo``: a short version of the paper's Fig. 2, to see the whole story in a minute.

Naive robots navigate well together (2A) until one saboteur joins (2B); sceptical robots pay for
their caution (2C) but keep their chain when a scaboteur joins (2D).
"""
from __future__ import annotations

import time

from rich.console import Console
from rich.table import Table

from .config import load_experiment
from .runner import run_batch
from .runner.batch import default_workers, process_pool, warm
from .runner.progress import progress

SETUPS = (("fig2A", "25 naive"), ("fig2B", "24 naive + 1 saboteur"),
          ("fig2C", "25 sceptical"), ("fig2D", "24 sceptical + 1 scaboteur"))


def run_demo(runs: int = 8, workers: int | None = None) -> int:
    console = Console()
    workers = workers or default_workers()
    table = Table(title=f"Items collected per robot in 15 000 steps (median of {runs} runs per setup)")
    for col in ("panel", "swarm", "honest robots", "Byzantine robots", "paper (honest)"):
        table.add_column(col, justify="left" if col in ("panel", "swarm") else "right")
    paper = {"fig2A": "20", "fig2B": "~10 (halves)", "fig2C": "below 2A", "fig2D": "~2C, ~2x 2B"}
    t0 = time.perf_counter()
    steps = 0
    configs = [load_experiment(name) for name, _ in SETUPS]
    for cfg in configs:  # compile (first time only) before forking, so every worker shares the kernels
        warm(cfg)
    with progress("demo", runs * len(SETUPS)) as bar, process_pool(workers) as pool:
        for (name, swarm), cfg in zip(SETUPS, configs):
            res = run_batch(cfg, runs, cfg.seed, workers=workers, executor=pool, on_done=bar.advance)
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
