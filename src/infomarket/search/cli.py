"""``infomarket attack-search``: the worst attack found against each defence (docs/attack-search.md)."""
from __future__ import annotations

import argparse
import functools
import time
from dataclasses import replace
from pathlib import Path

from ..cliargs import UsageError, at_least, dask_client, study_options, workers_count
from .baselines import rotation_grid


def _ints(text: str) -> list[int]:
    try:
        out = [int(t) for t in text.split(",") if t.strip()]
    except ValueError:
        raise UsageError(f"--byzantines {text!r}: expected whole numbers separated by commas, e.g. 1,3,8") from None
    if not out:  # a blank shell variable must not widen the search to every cell
        raise UsageError(f"--byzantines {text!r}: give at least one count, e.g. 3 (leave the option out for "
                         f"every count of the study)")
    return out


def _names(text: str) -> list[str]:
    out = [t.strip() for t in text.split(",") if t.strip()]
    if not out:
        raise UsageError(f"--defence {text!r}: give at least one defence, e.g. staking (leave the option out for "
                         f"every defence of the study)")
    return out


def _race(text: str) -> list[int]:
    try:
        return [int(t) for t in text.split(",") if t.strip()]
    except ValueError:
        raise UsageError(f"--race {text!r}: expected cumulative run counts separated by commas, e.g. 8,16,32") from None


SIZES = ("budget", "popsize", "restarts", "runs", "finalists", "confirmation_runs")
DESIGN = ("sigma0", "spread", "keep", "pool_baselines", "gate_rounds", "local", "local_sigma", "leaders", "leader_runs",
          "confirm_top", "refine", "refine_step")


def _reductions(st, declared, exp, chosen, all_cells, args) -> list[str]:
    """What makes this search smaller than the declared study (the report is marked reduced by it)."""
    out = []
    if len(chosen) < len(all_cells):
        out.append(f"{len(chosen)} of {len(all_cells)} cells")
    if args.steps is not None and args.steps != exp.steps:
        out.append(f"--steps {args.steps} (declared {exp.steps})")
    if args.transitory is not None and args.transitory != exp.transitory:
        out.append(f"--transitory {args.transitory} (declared {exp.transitory})")
    for key in SIZES:
        have, want = getattr(st.settings, key), getattr(declared.settings, key)
        if have < want:
            out.append(f"--{key.replace('_', '-')} {have} (declared {want})")
    if st.settings.race != declared.settings.race:
        out.append(f"--race {','.join(map(str, st.settings.race))} "
                   f"(declared {','.join(map(str, declared.settings.race))})")
    if st.settings.grid_step > declared.settings.grid_step:
        out.append(f"--grid-step {st.settings.grid_step:g} (declared {declared.settings.grid_step:g})")
    for key in DESIGN:  # another search design is not the declared study either
        have, want = getattr(st.settings, key), getattr(declared.settings, key)
        if have != want:
            out.append(f"--{key.replace('_', '-')} {have} (declared {want})")
    return out


def _list_baselines(st) -> int:
    grid = rotation_grid(st.settings.grid_step)
    for name, params in st.baselines.items():
        what = "reference" if name == st.reference else ("grid" if name in grid else "declared")
        print(f"{name}\t{what}\t" + ", ".join(f"{k}={v:g}" for k, v in params.items()))
    return 0


def cmd_attack_search(args) -> int:
    """Run ``infomarket attack-search``: search each cell's worst attack into the store (resumable), then write the
    cells' frames and the summary; returns the exit code."""
    # with the command: `infomarket --help` imports neither scipy.stats nor the search, runner and store
    from ..analysis.study import out_dir, refuse_declared_seed
    from ..config import load_experiment
    from ..runner.execute import default_workers, local_executor
    from ..runner.feed import Feed, dask_threads
    from ..runner.progress import progress
    from ..store import Store
    from . import study as study_mod
    from .driver import planned_runs, search_cell, store_runner
    from .study import cells
    from .summary import write
    from . import adaptive, provenance, report

    exp = load_experiment(args.experiment)
    decl = study_mod.read(args.questions)  # the shipped file as the package read it, or the one given
    path, data = decl.path, decl.data
    st = study_mod.load(exp, data, path=path, budget=args.budget, popsize=args.popsize, restarts=args.restarts,
                        runs=args.runs,
                        finalists=args.finalists, race=_race(args.race) if args.race is not None else None,
                        keep=args.keep, confirmation_runs=args.confirmation_runs, grid_step=args.grid_step,
                        objective=args.objective, seed=args.seed, validation=args.validation_repeats,
                        pool_baselines=args.pool_baselines, gate_rounds=args.gate_rounds, local=args.local,
                        local_sigma=args.local_sigma, leaders=args.leaders, leader_runs=args.leader_runs,
                        spread=args.spread, sigma0=args.sigma0, confirm_top=args.confirm_top,
                        refine=args.refine, refine_step=args.refine_step)
    if args.list_baselines:
        return _list_baselines(st)
    if args.validate:
        return _validate(st, args)
    out = out_dir(args.out, "attack-search")
    defences = _names(args.defence) if args.defence is not None else None
    chosen = cells(st, defences, _ints(args.byzantines) if args.byzantines is not None else None)
    if args.steps is not None and args.transitory is not None and args.transitory >= args.steps:
        raise UsageError(f"--transitory {args.transitory}: must be below --steps {args.steps}")
    for c in chosen:  # every configuration is checked before anything runs
        c.with_attack({}, steps=args.steps, transitory=args.transitory)
    first = chosen[0].with_attack({}, steps=args.steps, transitory=args.transitory)
    declared = study_mod.load(exp, data, path=path)
    smaller = _reductions(st, declared, exp, chosen, cells(st), args)
    refuse_declared_seed(st.settings.seed, declared.settings.seed, (["--reduced"] if args.reduced else []) + smaller)
    reduced = "; ".join(([args.reduced] if args.reduced else []) + smaller)
    store = Store(out / "store", cache=True)  # read after every generation: each part read once
    store.refuse_foreign()
    total = planned_runs(st) * len(chosen)
    client = dask_client(args.dask) if args.dask else None
    workers = args.workers or default_workers()
    # before any run: a bad value must not surface after a cell's search
    learner = study_mod.learner(data.get("adaptive", {}), {"budget": args.adaptive_budget}, path.name)
    validation = _study_validation(st, out, args.quiet)
    need = data.get("validation", {}).get("min_recovery")
    if need is not None and not reduced and validation.get("search", 0.0) < need:
        raise UsageError(f"the planted validation gives the search a recovery rate of "
                         f"{validation.get('search', 0.0):.0%}"
                         f", below the {need:.0%} that {path.name} declares before its study runs (OUT/validation.json "
                         f"has every search); the study is not run")
    t0 = time.perf_counter()
    results = []
    try:
        with progress(f"attack-search {exp.name} ({len(chosen)} cell(s))", total, enabled=not args.quiet) as bar, \
                local_executor(1 if client is not None else workers) as pool:
            executor = client.get_executor(pure=False) if client is not None else pool
            feed = Feed(store, workers=dask_threads(client) if client is not None else workers, executor=executor,
                        on_done=bar.advance)
            run = store_runner(store, on_skip=lambda k: k and bar.skip(k), feed=feed)
            results = run.map([functools.partial(search_cell, st, c, store, run=run, steps=args.steps,
                                                 transitory=args.transitory) for c in chosen])
            for c, r in zip(chosen, results) if learner.budget else ():  # after every cell: its own pool
                r.extra["adaptive"] = _adaptive(adaptive, st, c, r, learner, out, args,
                                                1 if client is not None else workers)
    finally:
        if client is not None:
            client.close()
    wall = time.perf_counter() - t0
    feed.busy.wall_seconds = wall  # the whole command's, the adaptive attacker's training included
    busy = feed.busy.as_dict()
    written, text = write(out, st, results, reduced=reduced, wall_seconds=wall, steps=first.steps,
                          transitory=first.transitory)
    length = {"steps": first.steps, "transitory": first.transitory}
    header = {**provenance.report_header(store.meta().get(report.PROVENANCE), path), "validation": validation}
    answers = report.AttackSearch(st, results, reduced=reduced, wall_seconds=wall, header=header,
                                  records=_records(decl), busy=busy, **length)
    written += answers.write(store, out)
    text = report.markdown(answers.analysis, reduced=reduced, wall_seconds=wall, header=header,
                           records=_records(decl), busy=busy, **length)
    if not args.quiet:
        print(text)
        made = sum(r.done for r in results)
        kept = sum(r.skipped for r in results)
        print(f"attack-search: {made} runs made now, {kept} found in the store; {wall:.1f} s wall; "
              f"wrote {', '.join(str(p) for p in written)}")
    return 0


def _records(decl) -> list[str]:
    """The report's record section, naming the questions file by its file name (as the study's reports do)."""
    return replace(decl, name=decl.path.name).record_markdown()


def _validate(st, args) -> int:
    """``--validate``: the planted weaknesses searched with the study's settings, the recovery rate per
    searcher printed (and written to OUT/validation.json with --out)."""
    from . import validate  # with the command: `infomarket --help` does not import the search

    repeats = args.validation_repeats if args.validation_repeats is not None else (st.settings.validation or 3)
    if repeats < 1:
        raise UsageError(f"--validation-repeats {repeats}: --validate needs at least 1")
    kinds = _names(args.kinds) if args.kinds is not None else None
    for k in kinds or []:
        if k not in validate.planted.KINDS:
            raise UsageError(f"--kinds {k}: not a planted weakness; allowed: {', '.join(validate.planted.KINDS)}")
    result = validate.validate(st, repeats, kinds=kinds, echo=None if args.quiet else lambda r: print(validate.line(r)))
    print(validate.text(result))
    if args.out:
        print(f"wrote {validate.write(Path(args.out), result)}")
    return 0


def _study_validation(st, out: Path, quiet: bool) -> dict:
    """The planted suite's recovery rates for a study's report: ``validation`` seeds per planted weakness
    with the study's settings (none when 0), kept in OUT/validation.json so a resumed study reuses them."""
    import json

    from . import validate  # with the command: `infomarket --help` does not import the search

    n = st.settings.validation
    if not n:
        return {}
    path = out / "validation.json"
    key = {"settings": repr(st.settings)}
    if path.exists():
        kept = json.loads(path.read_text())
        if kept.get("key") == key:
            return kept["rates"]
    result = {**validate.validate(st, n), "key": key}
    validate.write(out, result)
    if not quiet:
        print(validate.text(result))
    return result["rates"]


def _adaptive(adaptive, st, cell, r, learner, out: Path, args, workers: int):
    """The second searcher of a cell: the adaptive attacker trained on search seeds of its own (checkpointed
    under OUT/adaptive/EXPERIMENT, so a search started again resumes it), then played on the cell's
    confirmation seeds, where the report compares it with the parametric search's attack."""
    folder = out / "adaptive" / cell.experiment
    length = {"steps": args.steps, "transitory": args.transitory}
    policy = adaptive.train(cell, learner.budget, pairs=learner.pairs, runs=learner.runs,
                            sigma=float(learner.sigma), lr=float(learner.lr), seed=st.settings.seed,
                            objective=st.settings.objective, checkpoint=folder, workers=workers, **length)
    policy.save(folder / "policy.npz")
    return adaptive.confirm(cell, policy, r.confirmation_seeds, workers=workers, **length)


def add_subcommand(sub) -> None:
    """Add ``infomarket attack-search`` (the worst attack found against each defence) to the command line."""
    p = sub.add_parser("attack-search", help="the worst attack found against each defence: CMA-ES "
                                             "restarts and a random search, raced, confirmed on fresh seeds; resumable")
    p.add_argument("experiment", nargs="?", default="attack_search",
                   help="a study experiment (default: the shipped attack_search, or a file like it)")
    p.add_argument("--defence", help="defence(s) to search, comma-separated (default: every one of the study)")
    p.add_argument("--byzantines", metavar="K", help="Byzantine count(s), comma-separated (default: the study's)")
    p.add_argument("--budget", type=at_least(1), metavar="N",
                   help="evaluations per cell of the global search, and of the random search (default: declared)")
    p.add_argument("--popsize", type=at_least(2), help="CMA-ES population of the first restart (default: declared)")
    p.add_argument("--restarts", type=at_least(1), help="CMA-ES restarts (default: declared)")
    p.add_argument("--runs", type=at_least(1), help="runs per candidate evaluation (default: declared)")
    p.add_argument("--finalists", type=at_least(1), help="best distinct points per searcher raced (default: declared)")
    p.add_argument("--race", metavar="N,N,...",
                   help="cumulative runs per raced attack at each stage (default: declared)")
    p.add_argument("--keep", type=float, help="fraction of raced attacks kept after each stage (default: declared)")
    p.add_argument("--confirmation-runs", type=at_least(2), help="runs per chosen attack on the confirmation seeds "
                                                                 "(default: declared)")
    p.add_argument("--grid-step", type=float, metavar="DEGREES", help="rotation grid's step (default: declared)")
    p.add_argument("--sigma0", type=float, help="CMA-ES step of a global restart, in the unit cube (default: declared)")
    p.add_argument("--spread", type=float, help="share of the budget on spread start points (default: declared)")
    p.add_argument("--pool-baselines", action=argparse.BooleanOptionalAction, default=None,
                   help="race the baselines in the search's own pool (default: declared)")
    p.add_argument("--gate-rounds", type=at_least(0), metavar="N",
                   help="rounds of opening one gate at a time on the best point (default: declared)")
    p.add_argument("--local", type=at_least(0), metavar="N",
                   help="restarts that refine the best points found, with step --local-sigma (default: declared)")
    p.add_argument("--refine", type=at_least(0), metavar="N",
                   help="widest rounds of the last phase's moves (search.refine) in the budget (default: declared)")
    p.add_argument("--refine-step", type=float, help="its first step, in the unit cube (default: declared)")
    p.add_argument("--local-sigma", type=float, help="CMA-ES step of a local restart (default: declared)")
    p.add_argument("--leaders", type=at_least(0), metavar="N",
                   help="best start points run again on --leader-runs seeds before each choice (default: declared)")
    p.add_argument("--confirm-top", type=at_least(1), metavar="K",
                   help="the race's K best attacks of each searcher and of the baselines confirmed (default: declared)")
    p.add_argument("--leader-runs", type=at_least(1), metavar="N",
                   help="runs of a re-evaluated leader (default: declared)")
    p.add_argument("--objective", choices=["items", "liar_wealth"], help="what the attack optimises (default: items)")
    p.add_argument("--adaptive-budget", type=at_least(0), metavar="N",
                   help="evaluations per cell of the adaptive attacker, the second searcher "
                        "(0: none; default: declared)")
    p.add_argument("--validate", action="store_true",
                   help="search the planted weaknesses (known optima) with the study's settings and print the recovery "
                        "rate per searcher, then exit (docs/attack-search.md, \"Planted weaknesses\")")
    p.add_argument("--validation-repeats", type=at_least(0), metavar="N",
                   help="seeds per planted weakness: of --validate (default: declared, else 3), and of the "
                        "validation a "
                        "study runs before its cells (0: none; default: declared)")
    p.add_argument("--kinds", help="with --validate: planted weaknesses to search, comma-separated (default: all)")
    p.add_argument("--list-baselines", action="store_true", help="list the baselines (declared and rotation grid) "
                                                                 "and exit")
    p.add_argument("--steps", type=at_least(1), help="steps per run (default: the experiment's), for a reduced search")
    p.add_argument("--transitory", type=at_least(0), help="steps not counted (default: the experiment's)")
    study_options(p, "folder: the results store (OUT/store) and the report",
                  questions="the study's questions file: settings, baselines, questions (default: the package's "
                            "questions.toml)",
                  seed="the search's seed: optimisers and seed sets (default: declared)")
    p.add_argument("--workers", type=workers_count, help="local processes (default: one per core)")
    p.add_argument("--dask", metavar="ADDRESS", help="run on a Dask scheduler, e.g. tcp://host:8786")
    p.add_argument("--reduced", metavar="TEXT", help="label the report as a reduced run (what was reduced)")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    p.set_defaults(func=cmd_attack_search)
