"""The ``infomarket`` command line.

Bad input (a malformed experiment, an impossible option) prints one clear message and exits with code
2, before anything is written; no traceback reaches the user for errors infomarket raises on purpose.
"""
from __future__ import annotations

import importlib
import importlib.util
import os
import sys
import warnings
from pathlib import Path

from . import interrupts
from ._version import __version__
from .bench import cli as bench_cli
from .cliargs import Parser, at_least, seed_value, workers_count
from .errors import EXIT_FAILED, EXIT_USAGE, ConfigWarning, InfomarketError, os_error_message, report, show_warning

SUBCOMMAND_MODULES = ("infomarket.runner.cli", "infomarket.analysis.cli", "infomarket.viewer.cli",
                      "infomarket.evm.cli", "infomarket.analysis.sensitivity_cli")
SUBCOMMAND_MODULES += ("infomarket.analysis.terrain_cli",)  # terrain-report (docs/terrain.md)
SUBCOMMAND_MODULES += ("infomarket.search.cli",)  # attack-search (docs/attack-search.md)
SUBCOMMAND_MODULES += ("infomarket.rl.cli",)  # rl-train (docs/rl.md)
SUBCOMMAND_MODULES += ("infomarket.search.adaptive_cli",)  # adaptive-attack (docs/rl.md)
SUBCOMMAND_MODULES += ("infomarket.defence.cli",)  # defence-search (docs/defences.md)
SUBCOMMAND_MODULES += ("infomarket.ros.cli",)  # ros agent, ros swarm (docs/ros.md)


#: Options that name a file, a folder or an address: an empty value is refused, never taken as the working
#: folder (``Path("")``) or as "not given".
PATH_OPTIONS = frozenset({"out", "local", "movie", "questions", "scheduler", "dask"})


def _print_summary(robots, title: str) -> None:
    from rich.console import Console
    from rich.table import Table

    from .analysis import summarise  # with the command: `infomarket --help` stays light

    table = Table(title=title)
    for col in ("behaviour", "robots/run", "honest", "median items", "median wealth share"):
        table.add_column(col, justify="left" if col == "behaviour" else "right")
    for row in summarise(robots).itertuples():
        table.add_row(str(row.behaviour), str(row.robots), "yes" if row.honest else "no",
                      f"{row.median_items:g}", f"{row.median_wealth_share_pct:.2f} %")
    Console().print(table)


# ---------------------------------------------------------------------------------------------- run
def cmd_run(args) -> int:
    """Run ``infomarket run``: an experiment's runs into a results store, resumable, then a summary.

    Returns:
        0; 2 when a rule failed (the user's code: bad input) and 1 when a run failed otherwise; the
        interrupt exit code when stopped, after keeping the runs that had finished.
    """
    # with the command: `infomarket --help` does not import the runner
    from .runner.execute import default_workers
    from .runner.progress import progress
    from .runner.run import RunInterrupted, prepare, run_experiment

    cond = prepare(args.experiment, runs=args.runs, seed=args.seed, steps=args.steps, history_every=args.history)
    cfg, runs, seed = cond.config, cond.runs, cond.master_seed
    out = Path(args.out or Path("results") / cfg.name)
    workers = args.workers or min(default_workers(), runs)
    try:
        with progress(cfg.name, runs, enabled=not args.quiet) as bar:
            res = run_experiment(cond, out, workers=workers, force=args.force, on_done=bar.advance,
                                 on_plan=lambda todo: bar.skip(runs - todo))
    except RunInterrupted as stop:
        if not stop.kept:
            return report(f"interrupted before any of the {runs} runs finished; nothing kept", interrupts.exit_code())
        return report(f"interrupted: kept the {stop.kept} of {runs} runs that had finished in the store {out}; "
                      f"the same command again runs only the others", interrupts.exit_code())
    done = res.sweep
    if not args.quiet and len(res.robots):
        _print_summary(res.robots, f"{cfg.name}: {res.runs_done} runs x {cfg.steps} steps, master seed {seed}")
    if not args.quiet:
        kept = f", {done.skipped} already there" if done.skipped else ""
        print(f"wrote the results store {out}: {done.done} run(s) of {cfg.name}{kept} "
              f"(`infomarket figures {out}`, `infomarket store verify {out}`)")
        if done.done and done.run_seconds > 0:
            print(f"{done.env_steps / done.run_seconds:,.0f} env-steps/s per core "
                  f"(compile/load {done.compile_seconds:.2f} s)")
    if done.failed:
        return report(f"{done.failed} of {done.done} runs failed (the first: {done.first_error}); every error "
                      f"is listed by `infomarket store failed {out}`",
                      EXIT_USAGE if done.rule_errors else EXIT_FAILED)
    return 0


# --------------------------------------------------------------------------------------------- demo
def cmd_demo(args) -> int:
    """Run ``infomarket demo``: a short Fig. 2 in a minute (``demo.run_demo``); returns the exit code."""
    from .demo import run_demo  # with the command: `infomarket --help` stays light

    return run_demo(runs=args.runs, workers=args.workers)


# ----------------------------------------------------------------------------------- list / check
def cmd_list(args) -> int:
    """Three tables (rich): long descriptions wrap inside their column instead of being cut."""
    import tomllib

    from rich import box
    from rich.console import Console
    from rich.table import Table

    # with the command: `infomarket --help` stays light
    from .config import shipped_experiments
    from .registry import behaviours, payments

    def table(title: str, *columns: str) -> Table:
        t = Table(title=title, title_justify="left", box=box.SIMPLE_HEAD, show_edge=False, pad_edge=False)
        for c in columns:
            t.add_column(c, no_wrap=c in ("name", "robots"), overflow="fold")
        return t

    def params(spec) -> str:
        return ", ".join(f"{p}={spec.defaults.get(p, '?')}" for p in spec.params)

    console = Console(soft_wrap=False)
    exps = table("shipped experiments", "name", "description")
    for name, path in shipped_experiments().items():
        try:
            text = str(tomllib.loads(path.read_text()).get("description", "")).strip()
        except (OSError, tomllib.TOMLDecodeError):
            text = ""
        exps.add_row(name, text or path.read_text().splitlines()[0].lstrip("# "))
    rules = table("behaviours", "name", "robots", "description", "parameters (defaults)")
    for name, b in behaviours().items():
        rules.add_row(name, "honest" if b.honest else "byzantine", b.description, params(b))
    schemes = table("payment schemes", "name", "description", "parameters (defaults)")
    for name, p in payments().items():
        schemes.add_row(name, p.description, params(p))
    for t in (exps, rules, schemes):
        console.print(t)
        console.print()
    return 0


def cmd_check(args) -> int:
    """Run ``infomarket check``: validate an experiment file and print what it would run (swarm, scheme, chain,
    sweep size) without running it; returns 0."""
    from .config import chain as chain_rules, load_experiment  # with the command: `--help` stays light

    cfg = load_experiment(args.experiment)
    if cfg.plugins:  # validating needs the rules they register: say that their code ran
        print(f"note: validating imported (and so ran) the plugin code this file names: {', '.join(cfg.plugins)}",
              file=sys.stderr, flush=True)
    groups = ", ".join(f"{g.count} {g.behaviour}" for g in cfg.swarm.groups if g.count)
    per = " per condition" if cfg.sweep is not None else ""
    runs = (cfg.sweep.runs or cfg.runs) if cfg.sweep is not None else cfg.runs
    print(f"{cfg.name}: valid. {groups}; scheme {cfg.payment.scheme} (stake {cfg.payment.stake}); "
          f"{cfg.steps} steps, transitory {cfg.transitory}, {runs} runs{per}, seed {cfg.seed}; "
          f"config hash {cfg.config_hash()}")
    swept = cfg.sweep is not None and any(k.startswith("chain.") for k in cfg.sweep.grid) or cfg.sweep is not None \
        and any(k.startswith("chain.") for values in cfg.sweep.axes.values() for v in values for k in v.set)
    print(chain_rules.describe(cfg.chain) + (" (the base: the sweep sets [chain] keys per condition)" if swept else ""))
    if cfg.sweep is not None and cfg.sweep.sample is not None:  # the design is checked at every corner
        from .runner.design import make_design

        d = make_design(cfg)
        runs = cfg.sweep.runs or cfg.runs
        print(f"sampled design: {d.method}, {d.samples} base samples, {d.points} points over {len(d.names)} "
              f"keys ({', '.join(d.names)}); outputs {', '.join(d.outputs)}")
        print(f"sweep: {d.points:,} conditions x {runs} runs = {d.points * runs:,} runs "
              f"(`infomarket sweep {args.experiment}`)")
    elif cfg.sweep is not None:  # every condition is built and validated, as the sweep would
        from .runner.plan import conditions

        conds = conditions(cfg)
        what = [f"{key} ({len(values)} values)" for key, values in cfg.sweep.grid.items()]
        what += [f"{name} ({len(values)} values)" for name, values in cfg.sweep.axes.items()]
        print(f"sweep: {' x '.join(what)}")
        print(f"sweep: {len(conds):,} conditions x {conds[0].runs} runs = {sum(c.runs for c in conds):,} runs "
              f"(`infomarket sweep {args.experiment}`)")
    return 0


# --------------------------------------------------------------------------------------------- main
def build_parser() -> Parser:
    """The ``infomarket`` argument parser with every command (each package adds its own through its
    ``add_subcommand``)."""
    p = Parser(prog="infomarket", description="Information-market robot swarm simulator.")
    p.add_argument("--version", action="version", version=f"infomarket {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    r = sub.add_parser("run", help="run an experiment N times into a results store (robots, runs, ...; resumable)")
    r.add_argument("experiment", help="a .toml file, an original .json file, or a shipped name (e.g. fig2B)")
    r.add_argument("--runs", type=at_least(1), help="number of runs (default: the file's)")
    r.add_argument("--seed", type=seed_value, help="master seed (default: the file's)")
    r.add_argument("--steps", type=at_least(1), help="steps per run (default: the file's)")
    r.add_argument("--history", type=at_least(0), metavar="K",
                   help="also store the history table: every robot's wealth every K steps")
    r.add_argument("--out", help="results store folder (default: results/NAME); resumed if it holds these runs")
    r.add_argument("--workers", type=workers_count, help="processes (default: one per core)")
    r.add_argument("--force", action="store_true",
                   help="replace this experiment's earlier runs in --out (made with another configuration or seed)")
    r.add_argument("--quiet", action="store_true", help="print nothing but errors")
    r.set_defaults(func=cmd_run)

    bench_cli.add_subcommand(sub)

    d = sub.add_parser("demo", help="a short Fig. 2-like comparison: naive vs sceptical, with and without a saboteur")
    d.add_argument("--runs", type=at_least(1), default=8, help="runs per setup")
    d.add_argument("--workers", type=workers_count, help="processes (default: one per core)")
    d.set_defaults(func=cmd_demo)

    ls = sub.add_parser("list", help="shipped experiments, behaviours and payment schemes")
    ls.set_defaults(func=cmd_list)

    c = sub.add_parser("check", help="validate an experiment file and print what it describes",
                       description="Validate an experiment file and print what it describes. Validation imports "
                                   "the plugins the file names (their code runs), since their rules are needed to "
                                   "check the file; check says so when it does.")
    c.add_argument("experiment")
    c.set_defaults(func=cmd_check)

    for extra in SUBCOMMAND_MODULES:  # each subsystem adds its own commands
        package = extra.rsplit(".", 1)[0]
        if importlib.util.find_spec(package) is not None and importlib.util.find_spec(extra) is not None:
            importlib.import_module(extra).add_subcommand(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    """The ``infomarket`` command line: parse ``argv``, run the command, return its exit code.

    Bad input (a configuration, an option, a store) is one ``infomarket: error:`` line and exit code 2,
    never a traceback; Ctrl-C and SIGTERM stop any command, keeping what it finished.

    Args:
        argv: the arguments (default: ``sys.argv[1:]``); given, the caller is a test or a program, so a stop
            signal returns its exit code instead of leaving the process.
    """
    parser = build_parser()
    args = parser.parse_args(argv)
    empty = [k for k, v in vars(args).items() if isinstance(v, str) and not v.strip() and k in PATH_OPTIONS]
    if empty:  # Path("") is the working folder: an empty path would silently write or read there
        return report(f"--{empty[0].replace('_', '-')} {vars(args)[empty[0]]!r} is empty; give a path (or leave the "
                      f"option out)")
    quiet = bool(getattr(args, "quiet", False))
    notice = os.environ.get("INFOMARKET_COMPILE_NOTICE")
    if quiet:  # the engine's "compiling the step kernel..." line too (workers inherit the variable)
        os.environ["INFOMARKET_COMPILE_NOTICE"] = "0"
    try:
        with interrupts.handling() as stop:  # Ctrl-C and SIGTERM stop any command at once (docs/sweeps.md)
            code = _run(args, quiet)
    finally:
        if quiet:
            if notice is None:
                os.environ.pop("INFOMARKET_COMPILE_NOTICE", None)
            else:
                os.environ["INFOMARKET_COMPILE_NOTICE"] = notice
    if stop.signum and argv is None:  # the program itself, stopped: what it keeps is kept, leave now
        interrupts.exit_now(code)
    return code


def _run(args, quiet: bool = False) -> int:
    try:
        with warnings.catch_warnings():  # a configuration's warning as one `infomarket: warning:` line
            warnings.showwarning = show_warning
            if quiet:  # --quiet prints nothing but errors
                warnings.simplefilter("ignore", ConfigWarning)
            return int(args.func(args) or 0)
    except KeyboardInterrupt:
        return report("interrupted", interrupts.exit_code())
    except InfomarketError as exc:
        if interrupts.requested():  # e.g. a Ctrl-C inside `import duckdb`, raised as "needs DuckDB"
            return report("interrupted", interrupts.exit_code())
        # bad input (configuration, options, store) is a ValueError: exit 2; anything else: 1
        return report(exc)
    except BrokenPipeError:  # output piped into e.g. `head`: stop quietly, like other Unix tools
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except OSError as exc:  # a full disk, a read-only folder, a name too long, a file where a folder must be
        if interrupts.requested():
            return report("interrupted", interrupts.exit_code())
        return report(os_error_message(exc), EXIT_USAGE)
    except MemoryError:
        return report("ran out of memory; ask for less (fewer robots, steps, runs or --workers), or free "
                      "memory first", EXIT_USAGE)
    except Exception:
        if interrupts.requested():  # after a stop signal, an error on the way out is the stop's
            return report("interrupted", interrupts.exit_code())
        raise


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
