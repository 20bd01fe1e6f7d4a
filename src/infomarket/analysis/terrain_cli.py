"""``infomarket terrain-report RESULTS --out DIR``: the terrain questions answered from their stores
(``analysis.terrain``, docs/terrain.md)."""
from __future__ import annotations

import argparse
import json
from pathlib import Path


def add_subcommand(subparsers) -> None:
    """Add ``infomarket terrain-report`` (answer the terrain questions from their stores) to the command line."""
    p = subparsers.add_parser("terrain-report", help="answer the terrain questions (corridor, two_food, crowd) "
                              "from their stores, with a figure")
    p.add_argument("results", help="folder holding the stores corridor/, two_food/, crowd/ "
                                   "(optionally corridor_waypoints/, crowd_sensing/)")
    p.add_argument("--out", required=True, help="folder for terrain.md, terrain.json, terrain.png")
    p.set_defaults(func=cmd_terrain_report)


def cmd_terrain_report(args: argparse.Namespace) -> int:
    """Run ``infomarket terrain-report``: write ``terrain.md``, ``terrain.json`` and ``terrain.png``; returns the
    exit code."""
    # the analysis (scipy.stats, pandas) loads when the command runs, not when the CLI starts
    from . import study
    from .terrain import answer, figure, jsonable, markdown

    out = study.out_dir(args.out)
    a = answer(Path(args.results))
    text = markdown(a)
    files = study.Report.of("terrain", text, extra=[("terrain.json", json.dumps(jsonable(a), indent=1))],
                            figure=lambda p: figure(a, p)).write(out)
    print(text)
    print(f"wrote {', '.join(str(f) for f in files)}")
    return 0
