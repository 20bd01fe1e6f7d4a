"""``infomarket chain-study STORE [STORE ...] --out DIR``: the chain study's answers from its stores
(``analysis.chain_study``), written as chain-study.md, chain-study.csv and chain-study.png."""
from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

from ..cliargs import UsageError

if TYPE_CHECKING:  # pandas is imported where the stores are read
    import pandas as pd


def load(stores: list[str]) -> tuple[pd.DataFrame, pd.DataFrame | None, str]:
    """Per-run values of every store given, their chain measures (when a store keeps them) and a line on
    whether the questions were declared before each store's first run."""
    # the analysis loads when the command runs, not when the CLI starts (``infomarket --help`` stays fast)
    import pandas as pd

    from ..store import Store
    from .chain_study import DECLARATION, per_run
    from .frames import Frames

    frames, chains, locks = [], [], []
    for path in stores:
        store = Store(path)
        f = Frames.from_store(store)  # StoreError (exit 2) for a missing or foreign folder
        if not f.robots.empty:
            frames.append(f.robots)
        if callable(getattr(store, "chain", None)):  # a store that keeps the chain measures per run
            c = store.chain()
            if len(c):
                chains.append(c)
        status = DECLARATION.question_status(store.declarations())
        locks.append(f"{path}: {', '.join(sorted(status))}")
    robots = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
    chain = pd.concat(chains, ignore_index=True) if chains else None
    note = ("Declaration record (store.json) for chain_questions.toml: " + "; ".join(locks) +
            " ('not recorded': the store's record does not list this file; its commit precedes the runs)")
    return per_run(robots), chain, note


def add_subcommand(subparsers) -> None:
    """Add ``infomarket chain-study`` (answer the chain study's questions from its stores) to the command line."""
    p = subparsers.add_parser(
        "chain-study", help="answer the chain study's questions (does the paper's result survive the robots' "
                            "own chain?) from its stores, with a figure",
        description="Read the stores of chain_paper, chain_fig7, chain_sweep, chain_fig7_sweep (and "
                    "chain_partition) and write chain-study.md, chain-study.csv and chain-study.png in DIR: "
                    "each declared question (chain_questions.toml), its rule, run counts, effect with a 95 % "
                    "interval, and the answer (yes / no / inconclusive / not run / pending).")
    p.add_argument("stores", nargs="+", metavar="STORE", help="results stores (infomarket sweep NAME --out STORE)")
    p.add_argument("--out", required=True, metavar="DIR", help="folder for the answers and the figure")
    p.add_argument("--wall", default="", help="a line on how long the runs took, copied into chain-study.md")
    p.set_defaults(func=cmd_chain_study)


def cmd_chain_study(args: argparse.Namespace) -> int:
    """Run ``infomarket chain-study``: answer the declared questions and write the answers and the figure.

    Returns:
        The exit code (0).

    Raises:
        UsageError: the stores hold no completed run of the chain study.
    """
    # the analysis and matplotlib load when the command runs, not when the CLI starts
    from . import study
    from .chain_figure import figure
    from .chain_study import answer, markdown

    out = study.out_dir(args.out)
    runs, chain, locks = load(args.stores)
    if runs.empty:
        raise UsageError(f"{', '.join(args.stores)}: no completed runs of the chain study")
    a = answer(runs, chain)
    # stores of other experiments: nothing to answer
    if all(str(v).startswith((study.NOT_RUN, study.PENDING, study.NO_DATA)) for v in a.table["answer"]):
        raise UsageError(f"{', '.join(args.stores)}: no runs of the chain study's experiments (chain_paper, "
                         f"chain_fig7, chain_sweep, chain_fig7_sweep, chain_partition), so no question can be "
                         f"answered; run `infomarket sweep chain_paper --out STORE` first (docs/research.md)")
    a.locks = locks
    files = study.Report.of("chain-study", markdown(a, args.wall), table=a.table,
                            figure=lambda p: figure(a, p)).write(out)
    print(a.table[["question", "n", "answer"]].to_string(index=False))
    print(f"wrote {', '.join(str(f) for f in files)}")
    return 0
