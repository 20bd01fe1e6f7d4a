"""``infomarket chain-study STORE [STORE ...] --out DIR``: the chain study's answers from its stores
(``analysis.chain_report``), written as chain-study.md, chain-study.csv and chain-study.png."""
from __future__ import annotations

import argparse

from ..cliargs import study_options


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
    study_options(p, "folder for the answers and the figure", required=True, metavar="DIR")
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
    from .chain_report import ChainStudy

    out = study.out_dir(args.out)
    chain = ChainStudy(args.wall)
    files = chain.write(args.stores, out)
    print(chain.answers.table[["question", "n", "answer"]].to_string(index=False))
    print(f"wrote {', '.join(str(f) for f in files)}")
    return 0
