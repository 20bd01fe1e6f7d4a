"""``infomarket chain demo``: a small swarm whose every sale and deposit goes through the contract.

The simulator runs first and records its ledger events; each purchase then becomes a real light
contract (the seller's offer and the buyer's acceptance signed with their own keys) revealed on chain
by its seller, each refused purchase is checked to be refused by the contract too, and each deposit
is a ``buyItem`` by the market account. The command prints the gas and blocks this took and compares
every robot's on-chain balance with its wealth in the simulation (exit status 1 if any differs by more
than the fixed-point rounding allows, see ``evm_replay``). A run without deposits is refused before the
replay (exit status 2): with no deposit nothing is ever weighed or paid, and the comparison would pass
whatever the contract's rules.

``add_subcommand(subparsers)`` hangs ``chain demo`` under the main ``infomarket`` parser; the chosen
handler is stored as ``func`` (``args.func(args)`` returns the exit status). Heavy imports (the
simulator, web3) happen only when the command runs.
"""
from __future__ import annotations

import argparse
import sys
import time

from ..cliargs import at_least, seed_value
from ..errors import report as report_error
from ..payments import MARKETS

DEMO_SCHEMES = MARKETS


def _rpc_url(text: str) -> str:
    if not text.startswith(("http://", "https://")):
        raise argparse.ArgumentTypeError(f"must be an http(s):// JSON-RPC URL, not {text!r}")
    return text


def add_subcommand(subparsers) -> None:
    """Add ``chain`` (with its ``demo`` subcommand) to an argparse subparsers object."""
    chain = subparsers.add_parser("chain", help="run the information market on an Ethereum chain",
                                  description="The information market as a Solidity contract (docs/chain.md).")
    commands = chain.add_subparsers(dest="chain_command", metavar="COMMAND", required=True)
    demo = commands.add_parser(
        "demo", help="replay a small simulated swarm through the contract and compare the balances",
        description=__doc__.split("\n\n")[1].replace("\n", " "))
    demo.add_argument("--robots", type=at_least(1), default=25, help="swarm size (default 25)")
    demo.add_argument("--steps", type=at_least(1), default=3000, help="simulation steps (default 3000)")
    demo.add_argument("--scheme", choices=sorted(DEMO_SCHEMES), default="staking",
                      help="payment scheme: delayed, outlier (no stake) or staking (outlier, stake 0.04); "
                           "default staking")
    demo.add_argument("--experiment", default="fig4C",
                      help="experiment whose swarm composition is scaled down (default fig4C)")
    demo.add_argument("--seed", type=seed_value, default=0, help="simulation seed (default 0)")
    demo.add_argument("--backend", choices=("revm", "py-evm"), default="revm",
                      help="in-process EVM: revm (fast, default) or py-evm (the reference, slow); both "
                           "charge gas as a chain does (cold storage per transaction)")
    demo.add_argument("--rpc", type=_rpc_url, metavar="URL",
                      help="JSON-RPC node to use instead of an in-process EVM (needs an unlocked funded account)")
    demo.set_defaults(func=run_demo)


def demo_config(base, robots: int, steps: int, scheme: str):
    """``base`` with its swarm scaled to ``robots`` (every group keeps at least one robot when there
    is room), run for ``steps``, paying with ``scheme`` (a key of ``DEMO_SCHEMES``)."""
    groups = base.swarm.groups
    counts = [max(1, round(g.count * robots / base.swarm.robots)) if g.count else 0 for g in groups]
    largest = max(range(len(groups)), key=lambda k: counts[k])
    counts[largest] += robots - sum(counts)
    if counts[largest] < 0:  # more groups than robots: keep the first ones
        counts = [1 if k < robots else 0 for k in range(len(groups))]
    name, stake = DEMO_SCHEMES[scheme]
    payment = base.payment.model_dump()
    payment.update(scheme=name, stake=stake, params=payment["params"] if base.payment.scheme == name else {})
    return base.with_overrides(
        steps=steps, transitory=0,
        swarm={"robots": robots, "groups": [dict(g.model_dump(), count=c) for g, c in zip(groups, counts)]},
        payment=payment)


def run_demo(args: argparse.Namespace) -> int:
    """Handler of ``infomarket chain demo``; returns the exit status."""
    try:
        from .. import load_experiment, simulate
        from ..errors import ConfigError
        from .errors import ChainError
        from .market import connect
        from .evm_replay import replay_result
    except ImportError as exc:
        return report_error(f"infomarket chain needs the chain extra (pip install 'infomarket[chain]'): {exc}", 1)
    try:
        config = demo_config(load_experiment(args.experiment), args.robots, args.steps, args.scheme)
        if args.rpc:
            connect(args.rpc)  # fail before simulating if the node is not there
        if config.payment.scheme == "outlier" and config.payment_params()["theta"] > 180:
            raise ConfigError("the contract needs theta in [0, 180] degrees")
    except (ConfigError, ValueError, ChainError) as exc:
        return report_error(exc, 2)
    composition = ", ".join(f"{g.count} {g.behaviour}" for g in config.swarm.groups if g.count)
    print(f"chain demo: {args.robots} robots ({composition}), {args.steps} steps, scheme {args.scheme} "
          f"(stake {config.payment.stake:g}), seed {args.seed}")
    t0 = time.perf_counter()
    result = simulate(config, seed=args.seed, record_events=True)
    kinds = result.events["kind"].value_counts()
    print(f"simulated in {time.perf_counter() - t0:.1f} s: {kinds.get('purchase', 0)} purchases, "
          f"{kinds.get('refused', 0)} refused, {kinds.get('deposit', 0)} deposits")
    if not kinds.get("deposit", 0) or not kinds.get("purchase", 0):
        return report_error(f"the simulation made {kinds.get('purchase', 0)} purchases and {kinds.get('deposit', 0)} "
                            "deposits: with no purchase paid out by a deposit the comparison would prove nothing; "
                            "run more --steps or --robots", 2)
    t0 = time.perf_counter()
    try:
        report, rows = replay_result(result, rpc_url=args.rpc, backend=args.backend)
    except ChainError as exc:
        return report_error(exc, 1)
    print(f"replayed on {args.rpc or f'the in-process EVM ({args.backend})'} in {time.perf_counter() - t0:.1f} s")
    print(_report_text(report, rows))
    good = all(r.ok for r in rows) and report.conserved() and not report.disagreements
    print("on-chain balances match the simulated ledger (within the fixed-point rounding bound)" if good else
          "on-chain balances DO NOT match the simulated ledger")
    return 0 if good else 1


def _report_text(report, rows) -> str:
    s = report.summary()
    lines = [
        f"  reveals                 {s['reveals']}",
        f"  gas measured on         {report.backend}" + ("" if report.cold_storage else
                                                          " (warm storage across transactions: below a chain's gas; "
                                                          "--backend py-evm or --rpc for a chain's)"),
        f"  gas per reveal          {s['gas_per_reveal']:,.0f} (mean)",
        f"  gas per deposit         {s['gas_per_buy_item']:,.0f} (mean), {s['max_gas_buy_item']:,} (max): buyItem "
        f"and {s['settle_calls']} settle calls in all; largest single transaction {s['largest_tx']:,}",
        f"  gas per item delivered  {s['gas_per_item']:,.0f}  ({s['items']} items, reveals included)",
        f"  blocks used             {s['blocks_used']}",
        f"  refusals confirmed      {s['refusals_confirmed']}",
        f"  records expired         {s['expired']}",
        f"  money conserved         {'yes' if report.conserved() else 'NO'} "
        f"(supply {report.total_supply / 1e9:.9f} = balances + locked stakes)",
        "  robot   on chain        simulated       diff (units)  bound",
    ]
    lines += [f"  {r.robot:5d}   {r.chain_units / 1e9:13.9f}   {r.expected:13.9f}   {r.diff_units:11.3f}  "
              f"{r.bound_units:5d}{'' if r.ok else '  <- differs'}" for r in rows]
    lines += [f"  disagreement: {d}" for d in report.disagreements]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Stand-alone entry (``python -m infomarket.chain.cli chain demo ...``), same as the main CLI's."""
    parser = argparse.ArgumentParser(prog="infomarket")
    add_subcommand(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
