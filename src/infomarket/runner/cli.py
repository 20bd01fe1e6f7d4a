"""``infomarket sweep`` and ``infomarket reproduce``: many runs into a resumable results store."""
from __future__ import annotations

from pathlib import Path

from ..cliargs import UsageError, at_least, fraction

PAPER = ("fig2A", "fig2B", "fig2C", "fig2D", "fig3A", "fig3B", "fig3C", "fig4A", "fig4B", "fig4C",
         "fig5", "fig6A", "fig6B", "fig7")


def _client(args):
    """A dask.distributed Client when asked for; None for the local process pool."""
    if not (args.scheduler or args.dask_local):
        return None, None
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise UsageError("Dask is not installed: pip install 'infomarket[dask]'") from None
    if args.scheduler:
        try:
            return Client(args.scheduler, timeout="5s"), None
        except (OSError, TimeoutError) as exc:
            raise UsageError(f"--scheduler {args.scheduler}: no Dask scheduler answers there ({exc})") from None
    cluster = LocalCluster(n_workers=args.dask_local, threads_per_worker=1, processes=True,
                           dashboard_address=None)
    return Client(cluster), cluster


def _execute(experiments, args, label: str) -> int:
    import time

    from ..runner.batch import default_workers
    from ..runner.progress import progress
    from ..runner.sweep import plan, run_sweep
    from ..store import Store

    conds = plan(experiments, runs=getattr(args, "runs", None), seed=getattr(args, "seed", None),
                 scale=getattr(args, "scale", 1.0))
    store = Store(args.out)
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {out}: exists and is not a directory")
    client, cluster = _client(args)  # before creating anything: a scheduler that does not answer writes nothing
    workers = args.workers or default_workers()
    t0 = time.perf_counter()
    try:
        try:
            store.create()
        except OSError as exc:
            raise UsageError(f"--out {out}: cannot write there ({exc.strerror or exc})") from None
        total = sum(c.runs for c in conds)
        with progress(label, total, enabled=not args.quiet) as bar:
            report = run_sweep(conds, store, workers=workers, client=client, on_done=bar.advance,
                               on_plan=lambda todo: bar.advance(total - todo) if total - todo else None)
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    wall = time.perf_counter() - t0
    executor = (f"Dask scheduler {args.scheduler}" if args.scheduler else
                f"local Dask cluster of {args.dask_local}" if args.dask_local else f"{workers} local process(es)")
    print(f"{label}: {report.done} runs done, {report.skipped} already in the store, "
          f"{len(conds)} condition(s); {report.env_steps:,} env-steps in {wall:.1f} s wall "
          f"({report.env_steps / wall if wall > 0 else 0:,.0f} env-steps/s) on {executor}")
    print(f"store: {out}")
    return 0


def cmd_sweep(args) -> int:
    from ..config import load_experiment

    return _execute([load_experiment(args.experiment)], args, "sweep")


def cmd_reproduce(args) -> int:
    from ..config import load_experiment

    if args.what != "paper":
        raise UsageError(f"reproduce: unknown target {args.what!r}; allowed: paper")
    return _execute([load_experiment(name) for name in PAPER], args, "paper")


def _executor_options(p) -> None:
    p.add_argument("--out", required=True, help="results store folder (created; resumed if it exists)")
    p.add_argument("--workers", type=at_least(1), help="local processes (default: one per core)")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--scheduler", metavar="ADDRESS", help="run on a Dask scheduler, e.g. tcp://host:8786")
    g.add_argument("--dask-local", type=at_least(1), metavar="N", help="run on a local Dask cluster of N workers")
    p.add_argument("--quiet", action="store_true", help="no progress output")


def add_subcommand(sub) -> None:
    s = sub.add_parser("sweep", help="run every condition of an experiment into a results store (resumable)")
    s.add_argument("experiment")
    s.add_argument("--runs", type=at_least(1), help="runs per condition (default: the file's)")
    s.add_argument("--seed", type=at_least(0), help="master seed (default: the file's)")
    _executor_options(s)
    s.set_defaults(func=cmd_sweep)

    r = sub.add_parser("reproduce", help="rerun every experiment of the paper into one results store")
    r.add_argument("what", choices=["paper"], help="what to reproduce")
    r.add_argument("--scale", type=fraction, default=1.0,
                   help="fraction of the paper's runs per condition (at least 2), e.g. 0.125 for a quick check")
    _executor_options(r)
    r.set_defaults(func=cmd_reproduce)
