"""``infomarket figures STORE --out DIR``: the paper's figures, the paper-vs-store table and a report."""
from __future__ import annotations

import argparse

from ..cliargs import creatable_dir, study_options


def add_subcommand(subparsers) -> None:
    """Add ``infomarket figures`` (the paper's figures and report from a store) and ``chain-study`` to the command
    line."""
    p = subparsers.add_parser(
        "figures", help="draw the paper's Figs. 2-7 from a results store and write report.md/html",
        description="Draw every figure of the paper that the store has data for (PNG and SVG/PDF), compare "
                    "the headline numbers with the paper, and write report.md and report.html in DIR.")
    p.add_argument("store", metavar="STORE", help="a results store (folder with store.json)")
    study_options(p, "folder for the figures and the report", required=True, metavar="DIR")
    p.add_argument("--vector", choices=("svg", "pdf"), default="svg", help="vector format besides PNG")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    p.set_defaults(func=cmd_figures)
    from .chain_cli import add_subcommand as add_chain_study  # `infomarket chain-study` (docs/research.md)

    add_chain_study(subparsers)


def cmd_figures(args: argparse.Namespace) -> int:
    """Exit 0 when the report is written, whatever the verdicts: a failed row is a finding, not an error."""
    # the analysis and matplotlib load when the command runs, not when the CLI starts
    from ..store import Store
    from .frames import Frames, store_meta
    from .report import build_report
    from .study import out_dir

    out = out_dir(args.out)
    store = Store(args.store)
    store_meta(store)  # a missing or foreign folder is named first
    # before the tables are read (a big store takes a while), and creating nothing: a damaged store, refused
    # next, leaves no empty --out behind
    creatable_dir(out)
    frames = Frames.of(store)  # StoreDamaged, naming the repair, for a damaged part
    echo = (lambda *a, **k: None) if getattr(args, "quiet", False) else print
    if frames.robots.empty and frames.history.empty:
        echo(f"{args.store}: the store holds no completed runs; writing an empty report")
    build_report(frames, out, vector=args.vector, echo=echo, label=str(args.store), store=store)
    return 0
