"""``infomarket terrain-report RESULTS --out DIR``: the terrain questions answered from their stores
(``analysis.terrain``, docs/terrain.md)."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..cliargs import study_options


def add_subcommand(subparsers) -> None:
    """Add ``infomarket terrain-report`` (answer the terrain questions from their stores) to the command line."""
    p = subparsers.add_parser("terrain-report", help="answer the terrain questions (corridor, two_food, crowd) "
                              "from their stores, with a figure")
    p.add_argument("results", help="folder holding the stores corridor/, two_food/, crowd/ "
                                   "(optionally corridor_waypoints/, crowd_sensing/)")
    study_options(p, "folder for terrain.md, terrain.json, terrain.png", required=True)
    p.set_defaults(func=cmd_terrain_report)


def cmd_terrain_report(args: argparse.Namespace) -> int:
    """Run ``infomarket terrain-report``: write ``terrain.md``, ``terrain.json`` and ``terrain.png``; returns the
    exit code."""
    # the analysis (scipy.stats, pandas) loads when the command runs, not when the CLI starts
    from . import study
    from .terrain import TerrainStudy

    out = study.out_dir(args.out)
    report = TerrainStudy().answer(Path(args.results))
    files = report.write(out)
    print(report.text("terrain.md"))
    print(f"wrote {', '.join(str(f) for f in files)}")
    return 0
