"""``infomarket bench``: the paper's setups against this machine's floor, swarm sizes, or sweep scaling."""
from __future__ import annotations

import argparse
import json

from ..cliargs import at_least
from ..errors import ConfigError, UsageError

SETUPS = ("fig2A", "fig2D", "fig4C", "fig4C+chain")


def _sizes(text: str) -> list[int]:
    try:
        sizes = [int(x) for x in text.split(",") if x.strip()]
    except ValueError:
        sizes = []
    if not sizes or min(sizes) < 1:
        raise argparse.ArgumentTypeError(f"must be robot counts separated by commas, like 25,100,1000; got {text!r}")
    return sizes


def add_subcommand(sub) -> None:
    """Add ``infomarket bench`` (time the paper's setups against this machine's floor) to the command line."""
    b = sub.add_parser("bench", help="time the Fig. 2A, 2D and 4C setups (and 4C with the chain model) against "
                                     "this machine's floor",
                       description="Single-process runs after compilation (medians), each beside a floor kernel "
                                   "measured in the same run; or, with --robots, robot-steps/s and peak memory "
                                   "by swarm size at the paper's density; or, with --scaling, sweep throughput.")
    b.add_argument("--json", action="store_true", help="print one JSON object")
    b.add_argument("--steps", type=at_least(1), help="steps per run (default 15000; 3000 with --env)")
    b.add_argument("--repeats", type=at_least(1),
                   help="timed runs per setup (median reported; default 7, 5 with --env)")
    mode = b.add_mutually_exclusive_group()
    mode.add_argument("--robots", type=_sizes, metavar="N,N,...",
                      help="instead: robot-steps/s and peak memory for these swarm sizes (one process each)")
    b.add_argument("--chain", action="store_true",
                   help="with --robots: every robot a blockchain node (25 signers, blocks every 10 steps)")
    mode.add_argument("--scaling", action="store_true",
                      help="instead: sweep throughput with 1 and 2 local workers and a local Dask cluster of 2")
    mode.add_argument("--env", action="store_true",
                      help="instead: the RL vector environment's agent-steps/s and env-steps/s beside the engine's "
                           "own env-steps/s on the attack_search setup (docs/rl.md; --steps default 3000 here)")
    b.add_argument("--many", action="store_true",
                   help="with the setups: also many runs of the attack search's cell (a sweep, a reduced attack "
                        "search and the RL vector env), each as a ratio to the engine's rate measured in the same "
                        "run, per CPU second (docs/performance.md)")
    b.add_argument("--batch", type=at_least(1), help="with --env: runs per vector env (B, default 64)")
    b.add_argument("--interval", type=at_least(1), help="with --env: engine steps per decision (K, default 10)")
    b.set_defaults(func=run)


def run(args) -> int:
    """Run ``infomarket bench`` with the chosen mode (default, ``--robots``, ``--scaling`` or ``--env``) and print
    or write its results; returns the exit code."""
    # with the command: `infomarket --help` does not import the benches
    from . import run_bench, run_scaling, run_swarm_sizes

    if args.chain and not args.robots:  # the default bench times fig4C+chain already; --chain alone did nothing
        raise UsageError("--chain goes with --robots (every robot a blockchain node at each swarm size); the "
                         "default bench already times fig4C+chain")
    if args.many and (args.robots or args.scaling or args.env):  # --many adds to the setups' bench only
        other = "--robots" if args.robots else "--scaling" if args.scaling else "--env"
        raise UsageError(f"--many goes with the setups' bench (no --robots, --scaling or --env); {other} is "
                         f"another bench: give one of them")
    if args.env:
        return _env(args)
    if args.batch is not None or args.interval is not None:
        raise UsageError("--batch and --interval go with --env (the RL vector environment's benchmark)")
    args.steps = 15000 if args.steps is None else args.steps
    if args.robots:
        _check_sizes(args)
    args.repeats = 7 if args.repeats is None else args.repeats
    if args.scaling:
        report = run_scaling(steps=args.steps)
        if args.json:
            print(json.dumps(report, indent=2))
        else:
            for k in ("local_1", "local_2", "dask_local_2"):
                print(f"{k:13s} {report[k]['env_steps_per_second']:>12,.0f} env-steps/s "
                      f"({report[k]['wall_seconds']:.2f} s for {report['runs']} runs)")
            print(f"2 workers vs 1: {report['speedup_2_vs_1']:.2f}x; Dask (2) vs local pool (2): "
                  f"{report['dask_vs_local_2']:.2f}")
        return 0
    if args.robots:
        def shout(n, r):
            if not args.json:
                print(f"{n:>7,} robots  {r['robot_steps_per_second']:>12,.0f} robot-steps/s  "
                      f"peak {r['peak_rss_mb']:8.1f} MB  ({r['seconds']:.1f} s for {r['steps']} steps)", flush=True)

        report = {"steps": args.steps, "chain": args.chain,
                  "robots": run_swarm_sizes(args.robots, args.steps, on_done=shout, chain=args.chain)}
        first, last = report["robots"][args.robots[0]], report["robots"][args.robots[-1]]
        report["largest_vs_smallest"] = last["robot_steps_per_second"] / first["robot_steps_per_second"]
        if args.json:
            print(json.dumps(report, indent=2))
        else:
            print(f"{args.robots[-1]:,} robots run at {report['largest_vs_smallest']:.0%} of the robot-steps/s "
                  f"of {args.robots[0]:,}")
        return 0
    report = run_bench(SETUPS, steps=args.steps, repeats=args.repeats)
    if args.many:
        report["many"] = _many(args.repeats)
    if args.json:
        print(json.dumps(report, indent=2))
        return 0
    from rich.console import Console
    from rich.table import Table

    t = Table(title=f"single-process runs, 25 robots x {args.steps} steps (median of {args.repeats})")
    for c in ("setup", "env-steps/s", "seconds/run", "x floor", "compile/load s"):
        t.add_column(c, justify="right")
    for name, r in report["setups"].items():
        t.add_row(name, f"{r['steps_per_second']:,.0f}", f"{r['seconds_per_run']:.3f}",
                  f"{r['ratio_to_floor']:.2f}", f"{r['compile_seconds']:.2f}")
    f = report["floor"]
    t.add_row("floor", f"{f['steps_per_second']:,.0f}", f"{f['seconds_per_run']:.3f}", "1.00", "")
    Console().print(t)
    for name, r in report["setups"].items():
        if "ratio_to_instant" in r:
            print(f"{name}: {r['ratio_to_instant']:.2f} x the env-steps/s of the instant ledger (goal: >= 0.5)")
    if args.many:
        _print_many(report["many"])
    print("x floor: how many times the floor kernel's time per step (neighbour search, one Gaussian draw, "
          "the rotation and dead reckoning per robot) each setup takes, measured in this run")
    return 0


def _check_sizes(args) -> None:
    """Every swarm size of --robots fits in memory, checked here before any process starts."""
    # with the command: `infomarket --help` stays light
    from .setups import chain_at
    from .swarm import scaled_config

    for n in args.robots:
        try:
            scaled_config(n, args.steps, chain=chain_at(n) if args.chain else None)
        except ConfigError as exc:
            why = str(exc).split("\n", 1)[-1].strip()
            raise UsageError(f"--robots {n:,}: {why}") from None


def _env(args) -> int:
    try:  # the vector env needs the optional rl extra: refused with a message if missing
        from .env import run_env_bench
        import gymnasium  # noqa: F401 - only to find out whether the rl extra is installed
    except ModuleNotFoundError as exc:
        raise UsageError(f"bench --env needs {exc.name}: pip install 'infomarket[rl]'") from exc
    # with the command, once the rl extra is known to be there
    from ..config import sizes
    from ..rl.envs import configured
    from .env import ENV_SETUP

    steps, batch = 3000 if args.steps is None else args.steps, args.batch or 64
    too_big = sizes.batch_too_big(configured(ENV_SETUP, None, steps, min(1000, steps // 3)), batch,
                                  f"--batch {batch}")
    if too_big:
        raise UsageError(too_big)
    r = run_env_bench(steps=steps, batch=batch,
                      interval=args.interval or 10, repeats=5 if args.repeats is None else args.repeats)
    if args.json:
        print(json.dumps(r, indent=2))
        return 0
    print(f"{r['setup']}: {r['robots']} robots, {r['agents']} agents, B = {r['batch']} runs, K = {r['interval']} "
          f"steps per decision, {r['steps']} steps per episode (median of {r['repeats']})")
    print(f"vector env  {r['agent_steps_per_second']:>12,.0f} agent-steps/s  "
          f"{r['vector_env_steps_per_second']:>12,.0f} env-steps/s")
    print(f"engine      {'':>12}                {r['engine_env_steps_per_second']:>12,.0f} env-steps/s")
    print(f"ratio {r['ratio_to_engine']:.2f} of the engine's env-steps/s (goal: >= {r['goal']})")
    return 0


def _many(repeats: int) -> dict:
    """The many-run paths at the attack search's own run length, beside the engine (``bench.many``), and
    the RL vector env (``bench.env``) when Gymnasium is installed."""
    from .many import run_many_bench  # imports the search and the store: only when asked for

    many = run_many_bench(repeats=min(repeats, 5))
    try:
        import gymnasium  # noqa: F401 - only to find out whether the rl extra is installed
    except ModuleNotFoundError:
        many["vector_env"] = None
        return many
    from .env import run_env_bench  # imports Gymnasium (an optional dependency)

    many["vector_env"] = run_env_bench(repeats=min(repeats, 5))
    return many


def _print_many(m: dict) -> None:
    e = m["engine"]["env_steps_per_second"]
    print(f"many runs of {m['setup']}, {m['steps']} steps a run, per CPU second of this process:")
    print(f"  engine      {e:>12,.0f} env-steps/s  {m['engine']['runs_per_second']:>8,.2f} runs/s")
    for k in ("sweep", "search", "search_pool"):
        r = m.get(k)
        if r:
            print(f"  {k:11s} {r['env_steps_per_second']:>12,.0f} env-steps/s  {r['runs_per_second']:>8,.2f} runs/s  "
                  f"{r['ratio_to_engine']:.2f} of the engine's (goal >= {r['goal']}; {r['runs']} runs)")
    p = m.get("search_pool")
    if p:
        print(f"  {p['workers']} workers: {p['wall_env_steps_per_second']:,.0f} env-steps per wall second, "
              f"{p['wall_ratio_to_engine_per_worker']:.2f} of the engine's on every worker (a quiet machine only)")
    v = m.get("vector_env")
    if v:
        print(f"  vector env  {v['vector_env_steps_per_second']:>12,.0f} env-steps/s  "
              f"{v['ratio_to_engine']:.2f} of the "
              f"engine's {v['engine_env_steps_per_second']:,.0f} on {v['steps']}-step episodes (goal >= {v['goal']}; "
              f"B = {v['batch']})")
