"""``infomarket sweep`` and ``infomarket reproduce``: many runs into a resumable results store."""
from __future__ import annotations

from pathlib import Path

from .. import interrupts
from ..cliargs import UsageError, at_least, dask_client, fraction, seed_value, workers_count
from ..errors import EXIT_FAILED, EXIT_USAGE, report

PAPER = ("fig2A", "fig2B", "fig2C", "fig2D", "fig3A", "fig3B", "fig3C", "fig4A", "fig4B", "fig4C",
         "fig5", "fig6A", "fig6B", "fig7")
#: Named sets of shipped experiments that ``infomarket sweep NAME`` runs into one store.
SUITES = {"future": ("future_honest", "future_liar", "future_farmer", "future_surfer")}


def _client(args):
    """A dask.distributed Client when asked for; None for the local process pool."""
    if not (args.scheduler or args.dask_local):
        return None, None
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise UsageError("Dask is not installed: pip install 'infomarket[dask]'") from None
    if args.scheduler:
        return dask_client(args.scheduler, "--scheduler"), None
    cluster = LocalCluster(n_workers=args.dask_local, threads_per_worker=1, processes=True,
                           dashboard_address=None)
    return Client(cluster), cluster


def _execute(experiments, args, label: str) -> int:
    import time

    # with the command: `infomarket --help` does not import the runner, the engine or the store
    from ..config import sizes
    from ..runner.execute import default_workers
    from ..runner.progress import progress
    from ..runner.sweep import plan, run_sweep
    from ..store import Store

    if args.workers is not None and (args.scheduler or args.dask_local):  # local processes, or Dask's: not both
        other = f"--scheduler {args.scheduler}" if args.scheduler else f"--dask-local {args.dask_local}"
        raise UsageError(f"--workers {args.workers} and {other}: --workers sets local processes, which a Dask "
                         f"run does not use; give one of them")
    conds = plan(experiments, runs=getattr(args, "runs", None), seed=getattr(args, "seed", None),
                 scale=getattr(args, "scale", 1.0))
    need = sum(sizes.results_bytes(c.config, c.runs) for c in conds)
    if need > sizes.limit()[0]:  # the store, read whole by `figures`, and the sweep's plan must fit
        biggest = max(conds, key=lambda c: sizes.results_bytes(c.config, c.runs))
        why = sizes.runs_too_big(biggest.config, sum(c.runs for c in conds))
        raise UsageError(f"{label}: {sum(c.runs for c in conds):,} runs in {len(conds)} condition(s): "
                         f"{why or 'too many runs for memory'}")
    if args.events:
        for c in conds:
            why = sizes.run_too_big(c.config, record_events=True)
            if why:
                raise UsageError(f"--events: {c.experiment} [{c.id}]: {why}")
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {out}: exists and is not a directory")
    store = Store(out)
    store.refuse_foreign()  # a file, or a folder of something else: refused before anything starts
    client, cluster = _client(args)  # before creating anything: a scheduler that does not answer writes nothing
    workers = args.workers or default_workers()
    t0 = time.perf_counter()
    total = sum(c.runs for c in conds)
    try:
        with progress(label, total, enabled=not args.quiet) as bar:
            done = run_sweep(conds, store, workers=workers,
                             executor=client.get_executor(pure=False) if client is not None else None,
                             on_done=bar.advance,
                             on_plan=lambda todo: bar.skip(total - todo),
                             record_events=args.events, retry_failed=args.retry_failed)
    except KeyboardInterrupt:
        return report(_interrupted(store, conds, total, args), interrupts.exit_code())
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    wall = time.perf_counter() - t0
    executor = (f"Dask scheduler {args.scheduler}" if args.scheduler else
                f"local Dask cluster of {args.dask_local}" if args.dask_local else f"{workers} local process(es)")
    if not args.quiet:
        print(f"{label}: {done.done} runs done, {done.skipped} already in the store, "
              f"{len(conds)} condition(s); {done.env_steps:,} env-steps in {wall:.1f} s wall "
              f"({done.env_steps / wall if wall > 0 else 0:,.0f} env-steps/s) on {executor}")
        print(f"store: {out}")
    if done.failed:
        return report(f"{done.failed} of {done.done} runs failed (the first: {done.first_error}); every error "
                      f"is listed by `infomarket store failed {out}`; `--retry-failed` reruns them",
                      EXIT_USAGE if done.rule_errors else EXIT_FAILED)
    return 0


def _interrupted(store, conds, total: int, args) -> str:
    """What Ctrl-C left: how many of the planned runs are committed in the store, and the command that
    resumes (the same one: committed runs are skipped)."""
    import shlex

    try:
        committed = store.completed_runs() if store.exists() else set()
        planned = {(c.experiment, c.id, r) for c in conds for r in range(c.runs)}
        kept = f"{len(planned & committed):,} of {total:,} runs committed in {store.root}"
    except Exception:  # noqa: BLE001  (a store that cannot be read now: say so, and how to check it)
        kept = f"the runs committed so far are in {store.root} (`infomarket store verify {store.root}`)"
    words = ["infomarket", args.command]
    words += [args.what] if args.command == "reproduce" else [args.experiment]
    words += ["--out", str(args.out)]
    for flag, value in (("--runs", getattr(args, "runs", None)), ("--scale", getattr(args, "scale", 1.0)),
                        ("--seed", getattr(args, "seed", None)), ("--samples", getattr(args, "samples", None)),
                        ("--workers", args.workers), ("--scheduler", args.scheduler),
                        ("--dask-local", args.dask_local)):
        if value is not None and not (flag == "--scale" and value == 1.0):
            words += [flag, str(value)]
    words += ["--events"] if args.events else []
    words += ["--retry-failed"] if args.retry_failed else []
    words += ["--quiet"] if args.quiet else []
    return f"interrupted: {kept}; resume with: {shlex.join(words)}"


def cmd_sweep(args) -> int:
    """Run ``infomarket sweep``: every condition of an experiment, or of a shipped set of them, into a results
    store (resumable); returns the exit code."""
    # with the command: `infomarket --help` stays light
    from ..config import load_experiment
    from ..config.load import looks_like_path

    # a shipped suite's name wins over a same-named folder (e.g. the store of `sweep future --out future`),
    # as shipped experiments' names do; `./future` names the folder
    if args.experiment in SUITES and not looks_like_path(args.experiment):
        return _execute([load_experiment(name) for name in SUITES[args.experiment]], args, args.experiment)
    exp = load_experiment(args.experiment)
    if getattr(args, "samples", None) is not None:
        exp = _with_samples(exp, args.samples)
    return _execute([exp], args, "sweep")


def _with_samples(exp, samples: int):
    """``exp`` with another base sample size of its sampled design (a quick look at a big study)."""
    # with the command: `infomarket --help` stays light
    from ..config.load import validate
    from ..errors import ConfigError

    if exp.sweep is None or exp.sweep.sample is None:
        raise UsageError(f"--samples: {exp.name} has no [sweep.sample] design")
    data = exp.model_dump()
    data["sweep"]["sample"]["samples"] = samples
    try:
        return validate(data, f"--samples {samples}")
    except ConfigError as exc:
        raise UsageError(str(exc).replace("invalid experiment\n  ", "")) from None


def cmd_reproduce(args) -> int:
    """Run ``infomarket reproduce paper``: every experiment of the paper's figures into one store.

    Raises:
        UsageError: the target is not ``paper``.
    """
    from ..config import load_experiment  # with the command: `infomarket --help` stays light

    if args.what != "paper":
        raise UsageError(f"reproduce: unknown target {args.what!r}; allowed: paper")
    return _execute([load_experiment(name) for name in PAPER], args, "paper")


def _executor_options(p) -> None:
    p.add_argument("--out", required=True, help="results store folder (created; resumed if it exists)")
    p.add_argument("--workers", type=workers_count, help="local processes (default: one per core)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--scheduler", metavar="ADDRESS", help="run on a Dask scheduler, e.g. tcp://host:8786")
    g.add_argument("--dask-local", type=at_least(1), metavar="N", help="run on a local Dask cluster of N workers")
    p.add_argument("--events", action="store_true",
                   help="also store every run's event log (purchases, refusals, deposits) and what each "
                        "seller was paid at each deposit (the events and payments tables)")
    p.add_argument("--retry-failed", action="store_true", help="rerun the runs that failed in an earlier sweep")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")


def add_subcommand(sub) -> None:
    """Add ``sweep``, ``reproduce`` and the ``store`` commands (verify, repair, failed, sql) to the command line."""
    s = sub.add_parser("sweep", help="run every condition of an experiment into a results store (resumable)")
    s.add_argument("experiment", help="an experiment file, a shipped experiment, or a shipped set: "
                                      + ", ".join(f"{k} ({' + '.join(v)})" for k, v in SUITES.items()))
    s.add_argument("--runs", type=at_least(1), help="runs per condition (default: the file's)")
    s.add_argument("--scale", type=fraction, default=1.0,
                   help="fraction of the runs per condition (at least 2), e.g. 0.125 for a quick check")
    s.add_argument("--seed", type=seed_value, help="master seed (default: the file's)")
    s.add_argument("--samples", type=at_least(1), metavar="N",
                   help="base samples of a [sweep.sample] design (default: the file's), e.g. 16 for a quick look")
    _executor_options(s)
    s.set_defaults(func=cmd_sweep)

    r = sub.add_parser("reproduce", help="rerun every experiment of the paper into one results store")
    r.add_argument("what", choices=["paper"], help="what to reproduce")
    r.add_argument("--scale", type=fraction, default=1.0,
                   help="fraction of the paper's runs per condition (at least 2), e.g. 0.125 for a quick check")
    _executor_options(r)
    r.set_defaults(func=cmd_reproduce)

    st = sub.add_parser("store", help="check, repair or inspect a results store")
    ss = st.add_subparsers(dest="store_command", required=True, metavar="ACTION")
    for name, func, text in (
            ("verify", cmd_store_verify, "check every part against its commit record; list damaged and orphan parts"),
            ("repair", cmd_store_repair, "move damaged parts aside (into STORE/damaged/) so the next sweep reruns "
                                         "their runs"),
            ("failed", cmd_store_failed, "list the runs that failed, with their errors")):
        a = ss.add_parser(name, help=text, description=text)
        a.add_argument("store", metavar="STORE")
        a.set_defaults(func=func)
    text = ("run a DuckDB SQL query over the store's verified parts (tables robots, history, events, payments, "
            "sites, configs, chain, runs: docs/data.md); needs pip install 'infomarket[sql]'")
    a = ss.add_parser("sql", help=text, description=text)
    a.add_argument("store", metavar="STORE")
    a.add_argument("query", metavar="QUERY",
                   help="e.g. \"SELECT condition, avg(items_collected) FROM robots GROUP BY ALL\"")
    a.add_argument("--csv", action="store_true", help="print CSV instead of a text table")
    a.set_defaults(func=cmd_store_sql)


def _open(path: str):
    from ..store import Store, StoreError  # with the command: `infomarket --help` does not import pyarrow

    store = Store(path)
    if not store.exists():
        raise StoreError(f"{path}: not an infomarket results store (no store.json)")
    store.meta()  # an unreadable store.json: a StoreError naming it
    return store


def cmd_store_verify(args) -> int:
    """Run ``infomarket store verify``: list damaged parts and orphans; returns non-zero when a part is damaged."""
    store = _open(args.store)
    found = store.verify()
    for p in found.damaged:
        print(f"damaged: {p.path}: {p.why}")
    for o in found.orphans:
        print(f"orphan:  {o} (no commit record: left by an interrupted sweep; ignored by readers)")
    print(f"{args.store}: {found.parts} committed part(s), {len(found.damaged)} damaged, "
          f"{len(found.orphans)} orphan(s)")
    if found.damaged:
        return report(f"{args.store} is damaged; `infomarket store repair {args.store}` moves the damaged parts "
                      f"aside, and the next sweep reruns their runs")
    return 0


def cmd_store_repair(args) -> int:
    """Run ``infomarket store repair``: move damaged parts and orphans aside (into ``damaged/``) so the next sweep
    reruns exactly their runs; returns 0."""
    store = _open(args.store)
    with store.lock():
        found, moved = store.repair()
    for m in moved:
        print(f"moved aside: {m}")
    if not moved:
        print(f"{args.store}: nothing to repair ({found.parts} committed part(s), all intact)")
    else:
        print(f"{args.store}: {len({p.part for p in found.damaged})} damaged part(s) and {len(found.orphans)} "
              f"orphan(s) moved into {store.root / 'damaged'}; the next `sweep`/`reproduce` with the same "
              f"--out reruns exactly their runs")
    return 0


def cmd_store_failed(args) -> int:
    """Run ``infomarket store failed``: print each failed run with its seed and error; returns 0."""
    failed = _open(args.store).failed()
    for row in failed.itertuples():
        print(f"{row.experiment} [{row.condition}] run {row.run} (seed {row.seed}):")
        print("  " + row.error.strip().replace("\n", "\n  "))
    print(f"{args.store}: {len(failed)} failed run(s)")
    return 0


def cmd_store_sql(args) -> int:
    """Run ``infomarket store sql``: a DuckDB query over the store's tables, printed as a table or CSV; returns 0."""
    df = _open(args.store).sql(args.query)
    if args.csv:
        print(df.to_csv(index=False), end="")
    else:
        print(df.to_string(index=False) if len(df.columns) else "(no columns)")
    return 0
