"""``infomarket sensitivity STORE --out DIR``: global sensitivity indices of a store's sampled design."""
from __future__ import annotations

import argparse

from ..cliargs import study_options, writable_dir


def add_subcommand(subparsers) -> None:
    """Add ``infomarket sensitivity`` (sensitivity indices of a store's sampled design) to the command line."""
    p = subparsers.add_parser(
        "sensitivity", help="Sobol'/Morris/PAWN indices of a store's sampled design: table, figures, report section",
        description="Compute the sensitivity indices (SALib) of every output of the sampled design kept in a "
                    "results store; with replicated points (runs >= 2) also the share of the variance that is "
                    "seed noise (the floor under every total index); write them as CSV and Parquet, draw them "
                    "(bars with 95 % intervals and the noise floor, PAWN beside Sobol', the second-order heat map "
                    "of a Sobol' design) and write STEM.md in DIR (STEM: the experiment's name, prefixed with "
                    "'sensitivity-' unless it starts with it).")
    p.add_argument("store", metavar="STORE", help="a results store swept from an experiment with [sweep.sample]")
    study_options(p, "folder for the table, figures and report", required=True, metavar="DIR")
    p.add_argument("--experiment", help="which design, when the store holds several")
    p.add_argument("--vector", choices=("svg", "pdf"), default="svg", help="vector format besides PNG")
    p.add_argument("--local", metavar="LOCAL_STORE",
                   help="a store holding a replicated local design around a point (e.g. `infomarket sweep "
                        "sensitivity_local`): is that point robust? Writes STEM-robustness.csv")
    p.set_defaults(func=cmd_sensitivity)


def cmd_sensitivity(args: argparse.Namespace) -> int:
    """Run ``infomarket sensitivity``: compute the indices, answer the declared questions, write the tables,
    figures and ``STEM.md``; returns the exit code."""
    # the analysis (SALib, matplotlib) loads when the command runs, not when the CLI starts
    from . import study
    from .sensitivity_report import SensitivityStudy, summary_table

    out = study.out_dir(args.out)
    sens = SensitivityStudy(args.experiment, args.vector, args.local)
    report = sens.answer(args.store)
    writable_dir(out)
    files = report.write(out)
    if sens.indices is not None:  # set by answer
        print(summary_table(sens.indices).to_string(index=False))
    if sens.robustness is not None:
        print(sens.robustness[0].to_string(index=False))
    if sens.answers is not None:
        print(sens.answers[["question", "output", "answer"]].to_string(index=False))
    print(f"wrote {', '.join(str(p) for p in files)}")
    return 0
