"""``infomarket ros agent`` and ``infomarket ros swarm`` (docs/ros.md).

Both first make sure the ROS 2 client can be loaded (``env.ensure``: the command re-executes itself
once with the wheels' library path and ``RMW_IMPLEMENTATION``); without the wheels each says so in one
line and exits with status 2. Heavy imports happen only when a command runs.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..cliargs import at_least, seed_value
from ..errors import report as report_error
from .schedule import PARALLEL, WINDOW


def _rpc_url(text: str) -> str:
    if not text.startswith(("http://", "https://")):
        raise argparse.ArgumentTypeError(f"must be an http(s):// JSON-RPC URL, not {text!r}")
    return text


def _drop(text: str) -> float:
    try:
        p = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not 0 <= p < 1:
        raise argparse.ArgumentTypeError(f"must be in [0, 1), got {text}")
    return p


def _robot_list(text: str) -> list[int]:
    """``0,3,5``, ``0-4`` or a mix (``0-2,7``): robot numbers, each once, in order."""
    robots: list[int] = []
    try:
        for part in text.split(","):
            lo, _, hi = part.partition("-")
            robots += range(int(lo), int(hi or lo) + 1)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected robot numbers such as 0,2 or 0-4, got {text!r}") from None
    if not robots or min(robots) < 0 or len(set(robots)) != len(robots):
        raise argparse.ArgumentTypeError(f"expected distinct robot numbers >= 0, got {text!r}")
    return robots


def _controlled(text: str) -> list[int] | str:
    return "all" if text == "all" else _robot_list(text)


def _seconds(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected seconds, got {text!r}") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {text}")
    return value


def _agent_options(p) -> None:
    """What an agent process takes, whether it hosts one robot's agent or many."""
    p.add_argument("--rpc", type=_rpc_url, required=True, metavar="URL", help="the chain's JSON-RPC node")
    p.add_argument("--market", required=True, metavar="ADDRESS", help="the market contract's address")
    p.add_argument("--drop", type=_drop, default=0.0, metavar="P", help="lose this share of the messages it "
                   "sends (a fault to test the protocol's retries; default 0)")
    p.add_argument("--seed", type=seed_value, default=0, help="seed of the drops")
    p.add_argument("--controller", action="store_true", help="ask the robot's controller before selling or "
                   "buying (topics /robot_N/market/ask and /robot_N/market/decision, docs/ros.md); default: do "
                   "what the tasks say (the registered behaviour's decisions)")
    p.add_argument("--controller-timeout", type=_seconds, metavar="S", help="with --controller: after S seconds "
                   "without an answer take the behaviour's decision (default: wait for the answer)")


def _fault(text: str):
    # at parse time: a light module (no engine, no ROS 2)
    from .faults import parse_fault

    try:
        return parse_fault(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def add_subcommand(subparsers) -> None:
    """Add ``ros`` (with ``agent`` and ``swarm``) to an argparse subparsers object."""
    ros = subparsers.add_parser("ros", help="run the market on ROS 2 robots: one agent process per robot",
                                description="The information market over ROS 2 with a real chain node (docs/ros.md).")
    commands = ros.add_subparsers(dest="ros_command", metavar="COMMAND", required=True)
    a = commands.add_parser("agent", help="one robot's market agent (a ROS 2 node with its own key)")
    a.add_argument("--robot", type=at_least(0), required=True, help="the robot's number (its topics: /robot_N/...)")
    a.add_argument("--state", type=Path, required=True, help="folder of its key (created, mode 0600) and state")
    _agent_options(a)
    a.set_defaults(func=run_agent)
    h = commands.add_parser("host", help="many robots' market agents in one process (for large swarms)",
                            description="The agents of --robots, each its own ROS 2 node with its own key, "
                                        "hosted in this one OS process.")
    h.add_argument("--robots", type=_robot_list, required=True, metavar="LIST",
                   help="the robots hosted, e.g. 0-9 or 0,2,4")
    h.add_argument("--state", type=Path, required=True, metavar="DIR",
                   help="folder holding each robot's key and state in DIR/robot_N")
    _agent_options(h)
    h.set_defaults(func=run_host)
    s = commands.add_parser("swarm", help="the engine as the world, one agent process per robot, a chain node",
                            description="Run EXPERIMENT scaled to --robots with one market agent process per "
                                        "robot in lock step with the engine, and check that every balance on "
                                        "chain equals the engine's ledger (DIR/report.json).")
    s.add_argument("experiment", help="experiment whose swarm is scaled down (e.g. fig4C)")
    s.add_argument("--robots", type=at_least(2), default=6, help="swarm size (default 6)")
    s.add_argument("--steps", type=at_least(1), default=2000, help="simulation steps (default 2000)")
    s.add_argument("--seed", type=seed_value, default=0, help="simulation seed (default 0)")
    s.add_argument("--out", type=Path, required=True, metavar="DIR", help="folder of report.json, logs, agent state")
    s.add_argument("--scheme", default="staking", help="payment scheme as in `chain demo` (default staking)")
    s.add_argument("--rpc", type=_rpc_url, metavar="URL",
                   help="JSON-RPC node to use (an unlocked funded account pays gas); default: start a Hardhat node")
    s.add_argument("--fault", type=_fault, action="append", default=[], metavar="FAULT",
                   help="kill:ROBOT@STEP, drop:P or hostile (may be repeated)")
    s.add_argument("--agents-per-process", type=at_least(1), default=1, metavar="K",
                   help="host up to K robots' agents in each OS process (default 1: a process per robot)")
    s.add_argument("--controlled", type=_controlled, default=[], metavar="LIST",
                   help="robots whose agents ask their controller (all, or e.g. 0,2); start the controllers "
                        "yourself, in the swarm's ROS domain (docs/ros.md)")
    s.add_argument("--controller-timeout", type=_seconds, metavar="S",
                   help="controlled agents take the behaviour's decision after S seconds without an answer")
    s.add_argument("--retry-after", type=_seconds, default=1.0, metavar="S",
                   help="send a sale's tasks again after S seconds without its outcome, then after twice as "
                        "long each time up to 4 S (default 1)")
    s.add_argument("--parallel-trades", type=at_least(1), default=PARALLEL, metavar="N",
                   help=f"carry out up to N sales of disjoint robots at once (default {PARALLEL}; 1: one after "
                        "the other)")
    s.add_argument("--window", type=at_least(0), default=WINDOW, metavar="STEPS",
                   help=f"step the world up to STEPS steps past its earliest unfinished trade (default {WINDOW}; "
                        "0: every trade of a step done before the next step)")
    s.set_defaults(func=run_swarm)


def _ready() -> str | None:
    from . import env  # with the command: `infomarket --help` does not look for ROS 2

    return env.ensure()


def run_agent(args) -> int:
    return _serve([args.robot], lambda robot: args.state, args)


def run_host(args) -> int:
    return _serve(args.robots, lambda robot: args.state / f"robot_{robot}", args)


def _serve(robots: list[int], folder, args) -> int:
    reason = _ready()
    if reason:
        return report_error(reason, 2)
    # after ensure(): it loads ROS 2 and the chain client
    from ..errors import UsageError
    from .agent import MarketAgent, spin

    try:
        agents = [MarketAgent(r, folder(r), args.rpc, args.market, drop=args.drop, seed=args.seed,
                              controller=args.controller, controller_timeout=args.controller_timeout)
                  for r in robots]
    except (OSError, ValueError, UsageError) as exc:
        return report_error(exc, 2)
    try:
        spin(agents)
    except KeyboardInterrupt:
        return 0
    return 0


def run_swarm(args) -> int:
    reason = _ready()
    if reason:
        return report_error(reason, 2)
    # after ensure(): the engine, the chain client and ROS 2 load with the command only
    from ..errors import ConfigError, UsageError
    from ..evm.cli import DEMO_SCHEMES, FROM_EXPERIMENT
    from ..evm.errors import ChainError
    from .faults import merge
    from .swarm import Swarm, prepare, write_report

    if args.scheme not in (*DEMO_SCHEMES, FROM_EXPERIMENT):
        return report_error(f"--scheme {args.scheme!r}: choose {', '.join(sorted(DEMO_SCHEMES))} "
                            f"or {FROM_EXPERIMENT}", 2)
    faults = merge(args.fault)
    try:
        config, params = prepare(args.experiment, args.robots, args.steps, args.scheme, faults)
    except (ConfigError, ChainError, ValueError) as exc:
        return report_error(exc, 2)
    controlled = list(range(args.robots)) if args.controlled == "all" else args.controlled
    if any(r >= args.robots for r in controlled):
        return report_error(f"--controlled: robots are 0..{args.robots - 1}", 2)
    try:
        swarm = Swarm(config, params, args.seed, args.out, args.rpc, faults, per_process=args.agents_per_process,
                      controlled=controlled, controller_timeout=args.controller_timeout, retry=args.retry_after,
                      parallel=args.parallel_trades, window=args.window)
    except ConfigError as exc:
        return report_error(exc, 2)
    try:
        report = swarm.run()
    except UsageError as exc:  # no chain node to start: the user's to set up
        return report_error(exc, 2)
    except (RuntimeError, ChainError) as exc:
        return report_error(exc, 1)
    finally:
        swarm.close()
    path = write_report(report, args.out)
    m, g = report["messages"], report["gas"]
    print(f"{report['light_contracts']} light contracts, {report['deposits']} deposits, {report['refusals_confirmed']} "
          f"refusals confirmed; {m['protocol']} protocol messages; gas {g['total']:,}; "
          f"{report['refused_messages']} hostile or stale messages refused; {report['restarted_agents']} agents "
          f"restarted; {report['wall_seconds']:.1f} s")
    good = report["on_chain_matches_engine"]
    print(f"on-chain balances {'equal' if good else 'DO NOT equal'} the engine's ledger (within the rounding "
          f"bound); report: {path}")
    return 0 if good else 1


def main(argv: list[str] | None = None) -> int:
    """Stand-alone entry (``python -m infomarket.ros.cli ros ...``)."""
    parser = argparse.ArgumentParser(prog="infomarket")
    add_subcommand(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
