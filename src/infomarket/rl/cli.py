"""``infomarket rl-train``: the training example (``rl.train``), evolution strategies over a linear
policy for the Byzantine robots, and its learned attack compared with the constant liar on held-out
seeds (docs/rl.md)."""
from __future__ import annotations

import json
import math
import time

from ..cliargs import UsageError, at_least, seed_value, writable_file


def _positive(text: str) -> float:
    try:
        v = float(text)
    except ValueError:
        v = float("nan")
    if not (v > 0 and math.isfinite(v)):  # inf would turn every policy weight into NaN
        import argparse

        raise argparse.ArgumentTypeError(f"must be a finite number above 0, got {text!r}")
    return v


#: Bytes per ES iteration of the learning curve kept in memory (a Python float and its list slot).
CURVE_BYTES = 32


def add_subcommand(sub) -> None:
    """Add ``infomarket rl-train`` (learn an attack by evolution strategies through the RL environment) to the
    command line."""
    t = sub.add_parser("rl-train", help="learn an attack with evolution strategies through the RL vector env",
                       description="Evolution strategies (numpy) over a linear policy shared by the `attacker` robots, "
                                   "played through the Gymnasium vector environment (docs/rl.md); then the learned "
                                   "policy and the experiment's own attack (attack_search: the constant 20° liar) "
                                   "on the same held-out seeds, compared run by run.")
    t.add_argument("experiment", nargs="?", default="attack_search",
                   help="an experiment with `attacker` robots (default attack_search)")
    t.add_argument("--defence", help="the sweep cell's defence (attack_search: outlier, staking, theta20, ...)")
    t.add_argument("--byzantines", type=at_least(1), help="the sweep cell's Byzantine count (attack_search: 1, 3, 8)")
    t.add_argument("--steps", type=at_least(2), default=10000, help="steps per episode (default 10000)")
    t.add_argument("--transitory", type=at_least(0), default=5000,
                   help="items count from this step on (default 5000)")
    t.add_argument("--interval", type=at_least(1), default=10, help="engine steps per decision, K (default 10)")
    t.add_argument("--iterations", type=at_least(1), default=40, help="ES iterations (default 40)")
    t.add_argument("--pairs", type=at_least(1), default=16,
                   help="antithetic pairs per iteration: 2 x pairs runs in one vector env (default 16)")
    t.add_argument("--sigma", type=_positive, default=0.5, help="perturbation scale, in logits (default 0.5)")
    t.add_argument("--lr", type=_positive, default=0.2, help="Adam's step size (default 0.2)")
    t.add_argument("--eval-runs", type=at_least(2), default=32, help="held-out seeds to compare on (default 32)")
    t.add_argument("--seed", type=seed_value, default=0, help="the training's seed (default 0)")
    t.add_argument("--out", help="write the learned policy, the learning curve and the comparison here (JSON)")
    t.add_argument("--json", action="store_true", help="print the result as one JSON object")
    t.add_argument("--quiet", action="store_true", help="no progress")
    t.set_defaults(func=cmd_rl_train)


def cmd_rl_train(args) -> int:
    """Run ``infomarket rl-train``: train the policy, then compare it with the experiment's own attack on held-out
    seeds.

    Raises:
        UsageError: the optional ``rl`` extra (gymnasium) is not installed.
    """
    try:
        from .envs import AttackVectorEnv  # gymnasium is an optional extra: refused with a message if missing
    except ModuleNotFoundError as exc:
        raise UsageError(f"rl-train needs {exc.name}: pip install 'infomarket[rl]'") from None
    # with the command, after the optional extra is known to be there
    from ..runner.progress import progress
    from .run import compare, describe

    if args.transitory >= args.steps:
        raise UsageError(f"--transitory {args.transitory}: must be below --steps {args.steps}")
    if args.out is not None and not args.out.strip():  # a blank variable: not "no file", and not this folder
        raise UsageError(f"--out {args.out!r}: give a file for the result (or leave the option out)")
    # a file that can be written (its folder exists and takes files): checked before minutes of training
    out = writable_file(args.out) if args.out else None
    if args.defence is not None and not args.defence.strip():
        raise UsageError(f"--defence {args.defence!r}: name one defence of the experiment's sweep, e.g. staking")
    cell = {k: v for k, v in (("defence", args.defence), ("byzantines", args.byzantines)) if v is not None}
    from ..config import sizes  # with the command, like every import here: `infomarket --help` stays light
    from .envs import configured

    cfg = configured(args.experiment, cell or None, args.steps, args.transitory)
    # the 2 x pairs worlds held at once, and the learning curve (a float per iteration, in a list)
    too_big = sizes.batch_too_big(cfg, 2 * args.pairs, f"--pairs {args.pairs}",
                                  extra={"learning curve": CURVE_BYTES * args.iterations})
    if too_big:
        raise UsageError(too_big)
    t0 = time.perf_counter()
    env = AttackVectorEnv(args.experiment, 2 * args.pairs, cell=cell or None, steps=args.steps,
                          transitory=args.transitory, interval=args.interval)
    from .train import train  # after the environment is built: a bad argument is refused before this import

    with progress("ES", args.iterations * 2 * args.pairs, enabled=not (args.quiet or args.json)) as bar:
        bar.skip(0)
        trained = train(env, iterations=args.iterations, pairs=args.pairs, sigma=args.sigma, lr=args.lr,
                        seed=args.seed, on_iteration=lambda i, f: bar.advance(2 * args.pairs))
    result = compare(env, trained, args.eval_runs, args.seed)
    result.update(settings={k: getattr(args, k) for k in ("experiment", "defence", "byzantines", "steps",
                                                           "transitory", "interval", "iterations", "pairs",
                                                           "sigma", "lr", "eval_runs", "seed")},
                  wall_seconds=time.perf_counter() - t0)
    if out is not None:
        tmp = out.with_name(out.name + ".tmp")
        tmp.write_text(json.dumps(result, indent=2))
        tmp.replace(out)
    print(json.dumps(result, indent=2) if args.json else describe(result))
    return 0
