"""``infomarket defence-search``: defences searched against the worst attack found (docs/defences.md)."""
from __future__ import annotations

import time

from ..cliargs import UsageError, at_least, dask_client, study_options, workers_count

#: outer settings an option may make smaller than declared (the report is then marked reduced)
SIZES = ("candidates", "refine", "cost_runs", "frontier", "confirmation_runs")
INNER = ("budget", "runs", "confirmation_runs")


def _list(text: str, what: str, cast=str) -> list:
    try:
        out = [cast(t.strip()) for t in text.split(",") if t.strip()]
    except ValueError:
        raise UsageError(f"{what} {text!r}: expected values separated by commas") from None
    if not out:  # a blank shell variable must not widen the study
        raise UsageError(f"{what} {text!r}: give at least one value (leave the option out for all)")
    return out


def _reductions(st, declared, args) -> list[str]:
    out = []
    if args.family is not None:
        out.append(f"families {', '.join(st.families) or '–'}{' and existing' if st.existing else ''}")
    if len(st.byzantines) < len(declared.byzantines):
        out.append(f"Byzantine counts {', '.join(map(str, st.byzantines))}")
    for k, v in (("steps", args.steps), ("transitory", args.transitory)):
        if v is not None and v != getattr(declared.experiment, k):
            out.append(f"--{k} {v} (declared {getattr(declared.experiment, k)})")
    for k in SIZES:
        have, want = getattr(st.settings, k), getattr(declared.settings, k)
        if have < want:
            out.append(f"--{k.replace('_', '-')} {have} (declared {want})")
    for k in INNER:
        have, want = getattr(st.inner.settings, k), getattr(declared.inner.settings, k)
        if have < want:
            out.append(f"--inner-{k.replace('_', '-')} {have} (declared {want})")
    if st.inner.settings.race != declared.inner.settings.race:
        out.append(f"--inner-race {','.join(map(str, st.inner.settings.race))}")
    if st.inner.settings.grid_step > declared.inner.settings.grid_step:
        out.append(f"--inner-grid-step {st.inner.settings.grid_step:g} "
                   f"(declared {declared.inner.settings.grid_step:g})")
    return out


def _list_families(st) -> int:
    for name, fam in st.families.items():
        print(f"{name}\t{fam.description}")
        for p in fam.params:
            print(f"  {p.name}\t{p.kind} [{p.low:g}, {p.high:g}], default {p.default:g}\t{', '.join(p.paths)}")
    for name in st.existing:
        print(f"{name}\texisting defence of the experiment (no free parameters)")
    return 0


def cmd_defence_search(args) -> int:
    """Run ``infomarket defence-search``: the min-max search of defences per family (resumable), its frontier
    confirmed and reported; returns the exit code."""
    from ..analysis.study import out_dir, refuse_declared_seed  # with the command: scipy.stats stays out of the parser
    # with the command: `infomarket --help` does not import the search, runner and store
    from ..config import load_experiment
    from ..runner.execute import default_workers, local_executor
    from ..runner.feed import Feed, dask_threads
    from ..runner.progress import progress
    from ..search.driver import store_runner
    from ..store import Store
    from . import driver, report
    from . import study as study_mod
    from .families import candidates as first

    exp = load_experiment(args.experiment)
    families = _list(args.family, "--family") if args.family is not None else None
    counts = _list(args.byzantines, "--byzantines", int) if args.byzantines is not None else None
    inner = {"budget": args.inner_budget, "runs": args.inner_runs, "confirmation_runs": args.inner_confirmation_runs,
             "grid_step": args.inner_grid_step,
             "race": _list(args.inner_race, "--inner-race", int) if args.inner_race is not None else None}
    declaration = study_mod.read(args.questions)
    st = study_mod.load(exp, declaration, families=families, byzantines=counts, inner=inner, candidates=args.candidates,
                        refine=args.refine, cost_runs=args.cost_runs, frontier=args.frontier,
                        confirmation_runs=args.confirmation_runs, seed=args.seed)
    if args.list_families:
        return _list_families(st)
    out = out_dir(args.out, "defence-search")
    if args.steps is not None and args.transitory is not None and args.transitory >= args.steps:
        raise UsageError(f"--transitory {args.transitory}: must be below --steps {args.steps}")
    st = study_mod.with_length(st, args.steps, args.transitory)
    every = [c for f in st.families.values() for c in first(f, st.settings.candidates, st.settings.seed)]
    study_mod.check(st, every + st.existing_candidates())
    declared = study_mod.load(exp, declaration)
    smaller = _reductions(st, declared, args)
    parts = ("families ", "Byzantine counts ")  # a part of the study, with its declared settings
    refuse_declared_seed(st.settings.seed, declared.settings.seed,
                         (["--reduced"] if args.reduced else []) + [r for r in smaller if not r.startswith(parts)])
    reduced = "; ".join(([args.reduced] if args.reduced else []) + smaller)
    client = dask_client(args.dask) if args.dask else None
    store = Store(out / "store", cache=True)
    store.refuse_foreign()
    workers = args.workers or default_workers()
    total = driver.planned_runs(st)
    t0 = time.perf_counter()
    try:
        with progress(f"defence-search {exp.name}", total, enabled=not args.quiet) as bar, \
                local_executor(1 if client is not None else workers) as pool:
            executor = client.get_executor(pure=False) if client is not None else pool
            feed = Feed(store, workers=dask_threads(client) if client is not None else workers, executor=executor,
                        on_done=bar.advance)
            run = store_runner(store, on_skip=lambda k: k and bar.skip(k), feed=feed)
            judged = driver.search(st, store, run)
            result = driver.confirm(st, judged, store, run)
    finally:
        if client is not None:
            client.close()
    wall = time.perf_counter() - t0
    feed.busy.wall_seconds = wall
    busy = feed.busy.as_dict()
    answers = report.DefenceSearch(st, result, reduced=reduced, wall_seconds=wall,
                                   records=declaration.record_markdown(), busy=busy)
    written = answers.write(store, out)
    if not args.quiet:
        print(report.markdown(answers.analysis, reduced=reduced, wall_seconds=wall,
                              provenance=store.meta().get(driver.NAME), busy=busy))
        print(f"defence-search: {sum(j.runs for j in judged)} search-phase runs, "
              f"{result.made + result.found} confirmation runs; {wall:.1f} s wall; "
              f"wrote {', '.join(str(p) for p in written)}")
    return 0


def add_subcommand(sub) -> None:
    """Add ``infomarket defence-search`` (defences searched against the worst attack) to the command line."""
    p = sub.add_parser("defence-search", help="defences searched against the worst attack an inner attack search "
                                              "finds (min-max), the frontier confirmed on fresh seeds; resumable")
    p.add_argument("experiment", help="a study experiment (the shipped attack_search, or a file like it)")
    p.add_argument("--family", help="famil(ies) to search, comma-separated; `existing`: the experiment's own "
                                    "defences (default: every one)")
    p.add_argument("--byzantines", metavar="K", help="Byzantine count(s), comma-separated; the target count is "
                                                     "always kept (default: the experiment's)")
    p.add_argument("--candidates", type=at_least(1), help="first candidates per family (default: declared)")
    p.add_argument("--refine", type=at_least(0), help="candidates around each family's best trade (default: declared)")
    p.add_argument("--cost-runs", type=at_least(2), help="search-phase runs with no Byzantines per candidate "
                                                          "(default: declared)")
    p.add_argument("--frontier", type=at_least(0), help="new candidates confirmed at most (default: declared)")
    p.add_argument("--confirmation-runs", type=at_least(2), help="paired runs per confirmed defence and count "
                                                                 "(default: declared)")
    p.add_argument("--inner-budget", type=at_least(1), metavar="N", help="the inner attack search's evaluations "
                                                                         "(default: declared)")
    p.add_argument("--inner-runs", type=at_least(1), metavar="N", help="runs per inner evaluation (default: declared)")
    p.add_argument("--inner-confirmation-runs", type=at_least(2), metavar="N",
                   help="the inner search's runs per chosen attack (default: declared)")
    p.add_argument("--inner-grid-step", type=float, metavar="DEGREES",
                   help="the inner search's rotation grid step (default: declared)")
    p.add_argument("--inner-race", metavar="N,N,...", help="the inner search's cumulative runs per raced attack "
                                                           "(default: declared)")
    p.add_argument("--list-families", action="store_true", help="list the families and their parameters and exit")
    p.add_argument("--steps", type=at_least(1), help="steps per run (default: the experiment's), for a reduced study")
    p.add_argument("--transitory", type=at_least(0), help="steps not counted (default: the experiment's)")
    study_options(p, "folder: the results store (OUT/store) and the report",
                  questions="the study's questions file: families, settings and rules (default: the shipped "
                            "defence/questions.toml)",
                  seed="the study's seed: designs and seed sets (default: declared)")
    p.add_argument("--workers", type=workers_count, help="local processes (default: one per core)")
    p.add_argument("--dask", metavar="ADDRESS", help="run on a Dask scheduler, e.g. tcp://host:8786")
    p.add_argument("--reduced", metavar="TEXT", help="label the report as a reduced run (what was reduced)")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    p.set_defaults(func=cmd_defence_search)
