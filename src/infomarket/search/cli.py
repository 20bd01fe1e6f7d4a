"""``infomarket attack-search``: the worst attack found against each defence (docs/attack-search.md)."""
from __future__ import annotations

import time
from pathlib import Path

from ..cliargs import UsageError, at_least


def _ints(text: str) -> list[int]:
    try:
        out = [int(t) for t in text.split(",") if t.strip()]
    except ValueError:
        raise UsageError(f"--byzantines {text!r}: expected whole numbers separated by commas, e.g. 1,3,8") from None
    if not out:
        raise UsageError("--byzantines: give at least one count")
    return out


def cmd_attack_search(args) -> int:
    from ..config import load_experiment
    from ..runner.execute import default_workers, local_executor, warm
    from ..runner.progress import progress
    from ..store import Store
    from . import report, study as study_mod
    from .driver import search_cell, store_runner
    from .study import cells

    exp = load_experiment(args.experiment)
    st = study_mod.load(exp, budget=args.budget, popsize=args.popsize, runs=args.runs,
                        heldout_runs=args.heldout_runs, best=args.best, objective=args.objective, seed=args.seed)
    defences = [d for d in args.defence.split(",") if d] if args.defence else None
    chosen = cells(st, defences, _ints(args.byzantines) if args.byzantines else None)
    if args.steps is not None and args.transitory is not None and args.transitory >= args.steps:
        raise UsageError(f"--transitory {args.transitory}: must be below --steps {args.steps}")
    for c in chosen:  # every configuration is checked before anything runs
        c.with_attack({}, steps=args.steps, transitory=args.transitory)
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {out}: exists and is not a directory")
    store = Store(out / "store", cache=True)  # read after every generation: each part read once
    store.refuse_foreign()
    s = st.settings
    per_cell = (s.generations * s.popsize + len(st.baselines) - bool(st.reference)) * s.runs + (
        min(s.best, s.generations * s.popsize)
                                                     + len(st.baselines)) * s.heldout_runs
    total = per_cell * len(chosen)
    client = None
    if args.dask:
        try:
            from distributed import Client
        except ImportError:
            raise UsageError("Dask is not installed: pip install 'infomarket[dask]'") from None
        try:
            client = Client(args.dask, timeout="5s")
        except (OSError, TimeoutError) as exc:
            raise UsageError(f"--dask {args.dask}: no Dask scheduler answers there ({exc})") from None
    workers = args.workers or default_workers()
    t0 = time.perf_counter()
    results = []
    try:
        if client is None and workers > 1:
            warm(chosen[0].with_attack({}, steps=args.steps, transitory=args.transitory))  # forked workers inherit it
        with progress(f"attack-search {exp.name} ({len(chosen)} cell(s))", total, enabled=not args.quiet) as bar, \
                local_executor(1 if client is not None else workers) as pool:
            executor = client.get_executor(pure=False) if client is not None else pool
            run = store_runner(store, executor=executor, on_done=bar.advance, on_skip=lambda k: k and bar.skip(k))
            for c in chosen:
                results.append(search_cell(st, c, store, run=run, steps=args.steps, transitory=args.transitory))
    finally:
        if client is not None:
            client.close()
    wall = time.perf_counter() - t0
    analysis = report.analyse(st, results)
    written = report.write(out, analysis, reduced=args.reduced or "", wall_seconds=wall)
    if not args.quiet:
        print(report.markdown(analysis, reduced=args.reduced or "", wall_seconds=wall))
        made = sum(r.done for r in results)
        kept = sum(r.skipped for r in results)
        print(f"attack-search: {made} runs made now, {kept} found in the store; {wall:.1f} s wall; "
              f"wrote {', '.join(str(p) for p in written)}")
    return 0


def add_subcommand(sub) -> None:
    p = sub.add_parser("attack-search", help="optimise the parameterised attacker (CMA-ES) against each defence; "
                                             "resumable, compared with the hand-written attacks on held-out seeds")
    p.add_argument("experiment", help="a study experiment (the shipped attack_search, or a file like it)")
    p.add_argument("--defence", help="defence(s) to search, comma-separated (default: every one of the study)")
    p.add_argument("--byzantines", metavar="K", help="Byzantine count(s), comma-separated (default: the study's)")
    p.add_argument("--budget", type=at_least(1), metavar="N", help="candidate evaluations per cell (default: declared)")
    p.add_argument("--popsize", type=at_least(2), help="CMA-ES population (default: declared)")
    p.add_argument("--runs", type=at_least(1), help="runs per candidate (default: declared)")
    p.add_argument("--heldout-runs", type=at_least(2), help="held-out runs per attack (default: declared)")
    p.add_argument("--best", type=at_least(1), help="best candidates re-evaluated on held-out seeds (default: declared)")
    p.add_argument("--objective", choices=["items", "liar_wealth"], help="what the attack optimises (default: items)")
    p.add_argument("--seed", type=at_least(0), help="the optimiser's seed (default: declared)")
    p.add_argument("--steps", type=at_least(1), help="steps per run (default: the experiment's), for a reduced search")
    p.add_argument("--transitory", type=at_least(0), help="steps not counted (default: the experiment's)")
    p.add_argument("--out", required=True, help="folder: the results store (OUT/store) and the report")
    p.add_argument("--workers", type=at_least(1), help="local processes (default: one per core)")
    p.add_argument("--dask", metavar="ADDRESS", help="run on a Dask scheduler, e.g. tcp://host:8786")
    p.add_argument("--reduced", metavar="TEXT", help="label the report as a reduced run (what was reduced)")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    p.set_defaults(func=cmd_attack_search)
