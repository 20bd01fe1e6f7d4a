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
    from ..errors import report
    from ..store import Store
    from .frames import MissingDataError
    from . import study
    from .sensitivity import from_store, local_robustness
    from .sensitivity_report import declared_answers, stem, summary_table, write

    out = study.out_dir(args.out)
    try:
        s = from_store(args.store, args.experiment)
    except MissingDataError as exc:
        return report(_named(args.store, exc), 2)
    local = None
    if args.local:
        try:
            near = from_store(args.local)
            local = local_robustness(near, s.points)
        except MissingDataError as exc:
            return report(f"--local {_named(args.local, exc)}", 2)
    table = declared_answers(s, Store(args.store), local)
    writable_dir(out)
    files = write(s, out, vector=args.vector, answers_table=table)
    print(summary_table(s).to_string(index=False))
    if local is not None:
        files.append(study.write_csv(local[0], out / f"{stem(s.design.experiment)}-robustness.csv"))
        if len(local[1]):
            files.append(study.write_csv(local[1], out / f"{stem(s.design.experiment)}-local-mu-star.csv"))
        print(local[0].to_string(index=False))
    if table is not None:
        print(table[["question", "output", "answer"]].to_string(index=False))
    print(f"wrote {', '.join(str(p) for p in files)}")
    return 0


def _named(path: str, exc: Exception) -> str:
    """``PATH: message``, with the path once: a message that already starts with it is left as it is."""
    text = str(exc)
    bare = str(path).rstrip("/")
    return text if bare and text.startswith(bare) else f"{path}: {text}"
