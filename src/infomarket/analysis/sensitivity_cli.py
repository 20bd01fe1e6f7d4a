"""``infomarket sensitivity STORE --out DIR``: global sensitivity indices of a store's sampled design."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..cliargs import UsageError, writable_dir


def add_subcommand(subparsers) -> None:
    p = subparsers.add_parser(
        "sensitivity", help="Sobol'/Morris indices of a store's sampled design: table, figures, report section",
        description="Compute the sensitivity indices (SALib) of every output of the sampled design kept in a "
                    "results store; write them as CSV and Parquet, draw them (bars with 95 % intervals, the "
                    "second-order heat map of a Sobol' design) and write sensitivity-EXPERIMENT.md in DIR.")
    p.add_argument("store", metavar="STORE", help="a results store swept from an experiment with [sweep.sample]")
    p.add_argument("--out", required=True, metavar="DIR", help="folder for the table, figures and report")
    p.add_argument("--experiment", help="which design, when the store holds several")
    p.add_argument("--vector", choices=("svg", "pdf"), default="svg", help="vector format besides PNG")
    p.add_argument("--at", type=_point, metavar="NAME=VALUE,...",
                   help="a point (e.g. the paper's) whose local robustness to check along every driving "
                        "parameter: writes sensitivity-EXPERIMENT-robustness.csv")
    p.set_defaults(func=cmd_sensitivity)


def _point(text: str) -> dict[str, float]:
    out = {}
    for part in text.split(","):
        name, eq, value = part.partition("=")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{part!r} is not NAME=NUMBER") from None
        if not eq or not name.strip():
            raise argparse.ArgumentTypeError(f"{part!r} is not NAME=NUMBER")
    return out


def cmd_sensitivity(args: argparse.Namespace) -> int:
    from ..errors import report
    from .frames import MissingDataError
    from .sensitivity import from_store, summary_table, write

    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {out}: exists and is not a directory")
    try:
        s = from_store(args.store, args.experiment)
    except MissingDataError as exc:
        return report(f"{args.store}: {exc}", 2)
    local = None
    if args.at:
        from ..store import Store
        from .sensitivity import robustness, run_outputs

        try:
            local = robustness(s, run_outputs(Store(args.store).robots(), s.design), args.at)
        except MissingDataError as exc:
            raise UsageError(str(exc)) from None
    writable_dir(out)
    files = write(s, out, vector=args.vector)
    print(summary_table(s).to_string(index=False))
    if local is not None:
        path = out / f"sensitivity-{s.design.experiment}-robustness.csv"
        local.to_csv(path, index=False)
        files.append(path)
        print(local.to_string(index=False))
    print(f"wrote {', '.join(str(p) for p in files)}")
    return 0
