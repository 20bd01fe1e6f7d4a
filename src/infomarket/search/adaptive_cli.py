"""``infomarket adaptive-attack``: train the adaptive attacker (``search.adaptive``) against one cell of an
attack-search study, checkpointed per generation in ``--out`` (the same command again resumes), then
write its policy and a summary (docs/rl.md, "The adaptive attacker")."""
from __future__ import annotations

import argparse
import json
import math
import time

from ..cliargs import UsageError, at_least, study_options, workers_count

#: The policy's and the summaries' file names in ``--out``.
POLICY_FILE, SUMMARY_JSON, SUMMARY_MD = "policy.npz", "summary.json", "summary.md"


def _positive(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        v = float("nan")
    if not (v > 0 and math.isfinite(v)):
        raise argparse.ArgumentTypeError(f"must be a finite number above 0, got {text!r}")
    return v


def add_subcommand(sub) -> None:
    """Add ``infomarket adaptive-attack`` (train an adaptive attacker against one study cell) to the command line."""
    p = sub.add_parser("adaptive-attack", help="train an adaptive attacker (a policy over the RL observation) "
                                               "against one cell of an attack-search study, by evolution strategies",
                       description="Evolution strategies (antithetic, rank-normalised, common random numbers per "
                                   "generation) over a linear policy from each Byzantine robot's observation to its "
                                   "attack parameters, played through the RL interface's compiled runs; "
                                   "checkpointed per generation in --out, so the same command again resumes "
                                   "(docs/rl.md).")
    p.add_argument("experiment", help="a study experiment (the shipped attack_search, or a file like it)")
    p.add_argument("--defence", required=True, help="the cell's defence (attack_search: outlier, staking, ...)")
    p.add_argument("--byzantines", required=True, type=at_least(1), metavar="K", help="the cell's Byzantine count")
    p.add_argument("--budget", required=True, type=at_least(1), metavar="N",
                   help="candidate evaluations (each generation: its centre and 2 x --pairs perturbations)")
    p.add_argument("--pairs", type=at_least(1), default=8, help="antithetic pairs per generation (default 8)")
    p.add_argument("--runs", type=at_least(1), default=4,
                   help="runs per candidate, the same seeds for the whole generation (default 4)")
    p.add_argument("--sigma", type=_positive, default=0.05,
                   help="perturbation scale, in action ranges (default 0.05)")
    p.add_argument("--lr", type=_positive, default=0.02, help="Adam's step size, in action ranges (default 0.02)")
    p.add_argument("--interval", type=at_least(1), default=10, help="engine steps per decision, K (default 10)")
    p.add_argument("--objective", choices=["items", "liar_wealth"], default="items",
                   help="what the attack optimises (default items: the honest robots' items, minimised)")
    p.add_argument("--steps", type=at_least(2), help="steps per run (default: the experiment's)")
    p.add_argument("--transitory", type=at_least(0), help="steps not counted (default: the experiment's)")
    study_options(p, "folder: checkpoint, policy.npz, summary.json and summary.md", required=True,
                  seed="the training's seed (default 0)", seed_default=0)
    p.add_argument("--eval-runs", type=at_least(0), default=16,
                   help="runs on fresh seeds comparing the learned policy with its start, paired (default 16; 0: none)")
    p.add_argument("--workers", type=workers_count, default=1, help="local processes (default 1)")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors")
    p.set_defaults(func=cmd_adaptive_attack)


def _evaluate(cell, policy, start, runs: int, seed: int, steps, transitory, workers: int) -> dict:
    """The learned policy and the constant attack it started from on the same fresh seeds (paired)."""
    import numpy as np

    from .adaptive import Policy, confirm, evaluation_seeds  # with the command: `--help` stays light

    seeds = evaluation_seeds(cell.with_attack(policy.base, steps=steps, transitory=transitory).seed, seed, runs)
    first = Policy.constant(start, policy.actions, policy.interval, policy.base)
    learned = confirm(cell, policy, seeds, steps=steps, transitory=transitory, workers=workers)["items"].to_numpy()
    before = confirm(cell, first, seeds, steps=steps, transitory=transitory, workers=workers)["items"].to_numpy()
    d = before - learned
    se = float(d.std(ddof=1) / np.sqrt(len(d))) if len(d) > 1 else float("nan")
    return {"runs": runs, "seeds": seeds, "learned_items": learned.tolist(), "start_items": before.tolist(),
            "learned_mean": float(learned.mean()), "start_mean": float(before.mean()),
            "start_minus_learned_mean": float(d.mean()), "standard_error": se,
            "positive_share": float((d > 0).mean())}


def _markdown(s: dict) -> str:
    t = s["training"]
    lines = [f"# Adaptive attacker: {s['experiment']}, defence {s['defence']}, {s['byzantines']} Byzantine(s)", "",
             f"OpenAI-ES, {s['generations']} generations x {1 + 2 * t['pairs']} candidates x {t['runs']} runs "
             f"({s['runs_played']} runs of {s['steps']} steps, {s['transitory']} not counted), sigma {t['sigma']}, "
             f"lr {t['lr']}, seed {t['seed']}, objective {t['objective']}; actions {', '.join(t['actions'])} every "
             f"{t['interval']} steps, started at {t['start']}.", "",
             "| generation | honest items per honest robot: centre | best candidate (by fitness) |", "|---|---|---|"]
    lines += [f"| {r['generation']} | {r['centre_items']:.3f} | {r['best_items']:.3f} |" for r in s["curve"]]
    e = s.get("evaluation")
    if e:
        lines += ["", f"On {e['runs']} fresh seeds (paired): honest items per honest robot "
                      f"{e['learned_mean']:.3f} under "
                      f"the learned policy, {e['start_mean']:.3f} under its start; start minus learned "
                      f"{e['start_minus_learned_mean']:+.3f} (standard error {e['standard_error']:.3f}), positive "
                      f"in {100 * e['positive_share']:.0f} % of runs."]
    lines += ["", f"Policy: `{POLICY_FILE}` (`infomarket.search.adaptive.Policy.load`); at an all-zero observation "
                  f"it plays {s['policy_at_rest']}.", ""]
    return "\n".join(lines)


def cmd_adaptive_attack(args) -> int:
    """Run ``infomarket adaptive-attack``: train (resuming from the checkpoint in ``--out``), then play the learned
    policy and the constant attack it started from on the same fresh seeds; returns the exit code."""
    # with the command: `infomarket --help` does not import the engine
    from .. import interrupts
    from ..cliargs import writable_dir
    from ..config import load_experiment
    from ..errors import report
    from ..runner.progress import progress
    from . import study as study_mod
    from ..agents.observe import OBSERVATION
    from ..agents.runs import ACTIONS
    from .adaptive import resumed_generations, train
    from .adaptive_play import BATCH, check_memory

    from ..analysis.study import out_dir  # with the command: scipy.stats stays out of the parser

    out = out_dir(args.out, holds="the checkpoint, the policy and the summary")
    if not args.defence.strip():
        raise UsageError(f"--defence {args.defence!r}: name one defence of the study, e.g. staking")
    exp = load_experiment(args.experiment)
    (cell,) = study_mod.cells(study_mod.load(exp), [args.defence.strip()], [args.byzantines])
    steps = args.steps if args.steps is not None else exp.steps
    transitory = args.transitory if args.transitory is not None else exp.transitory
    if transitory >= steps:
        raise UsageError(f"--transitory {transitory}: must be below --steps {steps} (items count after it)")
    cfg = cell.with_attack({}, steps=args.steps, transitory=args.transitory)  # the configuration is valid
    pop = 1 + 2 * args.pairs
    if args.budget < pop:  # a generation is the smallest step: a smaller budget would be overspent
        raise UsageError(f"--budget {args.budget}: one generation evaluates 1 + 2 x --pairs = {pop} candidates; give "
                         f"--budget at least {pop} (or fewer --pairs)")
    generations = args.budget // pop
    check_memory(cfg, min(BATCH, pop * args.runs), f"{pop} candidates x {args.runs} runs", pop * args.runs,
                 (len(OBSERVATION) + 1) * len(ACTIONS))
    writable_dir(out)
    done = resumed_generations(out)
    t0 = time.perf_counter()
    quiet = args.quiet
    label = f"adaptive-attack {cell.experiment}"
    try:
        with progress(label, generations * pop * args.runs, enabled=not quiet) as bar:
            bar.skip(min(done, generations) * pop * args.runs)
            policy = train(cell, args.budget, pairs=args.pairs, runs=args.runs, sigma=args.sigma, lr=args.lr,
                           seed=args.seed, steps=args.steps, transitory=args.transitory, interval=args.interval,
                           objective=args.objective, checkpoint=out, workers=args.workers, on_runs=bar.advance)
        evaluation = None
        if args.eval_runs:
            start = policy.info["start_policy"]
            with progress(f"{label}: evaluation", 2 * args.eval_runs, enabled=not quiet) as bar:
                evaluation = _evaluate(cell, policy, start, args.eval_runs, args.seed, args.steps, args.transitory,
                                       args.workers)
                bar.advance(2 * args.eval_runs)
    except KeyboardInterrupt:
        kept = resumed_generations(out)
        return report(f"interrupted: {kept} of {generations} generation(s) kept in {out}; the same command again "
                      f"resumes from there", interrupts.exit_code())
    policy.save(out / POLICY_FILE)
    summary = {"experiment": exp.name, "defence": cell.defence, "byzantines": cell.byzantines,
               "steps": steps, "transitory": transitory, "training": policy.info["training"],
               "generations": policy.info["generations"], "runs_played": policy.info["runs_played"],
               "curve": policy.info["curve"], "policy_at_rest": policy.at_rest(),
               "weights": {a: dict(zip((*OBSERVATION, "constant"), policy.weights[:, k].tolist()))
                           for k, a in enumerate(policy.actions)},
               "evaluation": evaluation, "wall_seconds": time.perf_counter() - t0}
    for name, text in ((SUMMARY_JSON, json.dumps(summary, indent=2)), (SUMMARY_MD, _markdown(summary))):
        tmp = out / (name + ".tmp")
        tmp.write_text(text)
        tmp.replace(out / name)
    if not quiet:
        print(_markdown(summary))
        print(f"adaptive-attack: wrote {', '.join(str(out / n) for n in (POLICY_FILE, SUMMARY_JSON, SUMMARY_MD))}")
    return 0


