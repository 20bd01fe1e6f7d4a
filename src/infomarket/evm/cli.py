"""``infomarket chain demo``: a small swarm whose every sale and deposit goes through the contract.

The simulator runs first and records its ledger events; each purchase then becomes a real light
contract (the seller's offer and the buyer's acceptance signed with their own keys) revealed on chain
by its seller, each refused purchase is checked to be refused by the contract too, and each deposit
is a ``buyItem`` by the market account. The command prints the gas and blocks this took and compares
every robot's on-chain balance with its wealth in the simulation (exit status 1 if any differs by more
than the fixed-point rounding allows, see ``evm_replay``). A run without deposits is refused before the
replay (exit status 2): with no deposit nothing is ever weighed or paid, and the comparison would pass
whatever the contract's rules.

With the chain model on (``--chain-period P``, or an experiment whose ``[chain]`` section has
``consensus = "poa"``) the robots run their own Proof-of-Authority chain (docs/chain-model.md): the
demo records every block the model makes (``ledger.blocklog``) and replays the canonical chain on the
EVM one block per modelled block, checking every robot's balance against the modelled ledger after
every block, and names the first block that differs (``chain.block_replay``).

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
#: ``--scheme`` value that keeps the experiment's own payment section (any scheme the contract implements).
FROM_EXPERIMENT = "experiment"


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
    demo.add_argument("--scheme", choices=sorted(DEMO_SCHEMES) + [FROM_EXPERIMENT], default="staking",
                      help="payment scheme: delayed, outlier (no stake), staking (outlier, stake 0.04), or "
                           "experiment (the experiment's own payment section, e.g. capped_outlier); default "
                           "staking")
    demo.add_argument("--experiment", default="fig4C",
                      help="experiment whose swarm composition is scaled down (default fig4C)")
    demo.add_argument("--seed", type=seed_value, default=0, help="simulation seed (default 0)")
    demo.add_argument("--backend", choices=("revm", "py-evm"), default="revm",
                      help="in-process EVM: revm (fast, default) or py-evm (the reference, slow); both "
                           "charge gas as a chain does (cold storage per transaction)")
    demo.add_argument("--rpc", type=_rpc_url, metavar="URL",
                      help="JSON-RPC node to use instead of an in-process EVM (needs an unlocked funded account)")
    demo.add_argument("--chain-period", type=at_least(1), metavar="P",
                      help="run the chain model (robots as Proof-of-Authority nodes, a block every P steps; "
                           "docs/chain-model.md) and replay its blocks one by one on the EVM, checking every "
                           "balance after every block (revm only)")
    demo.add_argument("--gas-price", type=non_negative_float, metavar="G",
                      help="with the chain model: money per unit of gas the model charges (default: the "
                           "experiment's [chain] gas_price, 0 without one)")
    demo.set_defaults(func=run_demo)


#: The largest swarm ``chain demo`` takes: its swarm is scaled up in the experiment's own arena, so memory
#: grows as robots squared (0.3 GB at 2 000 robots, 3.7 GB at 20 000, for 10 steps).
MAX_DEMO_ROBOTS = 10_000


def demo_config(base, robots: int, steps: int, scheme: str):
    """``base`` with its swarm scaled to ``robots`` (every group keeps at least one robot when there
    is room), run for ``steps``, paying with ``scheme`` (a key of ``DEMO_SCHEMES``, or ``FROM_EXPERIMENT``:
    as ``base`` pays)."""
    groups = base.swarm.groups
    counts = [max(1, round(g.count * robots / base.swarm.robots)) if g.count else 0 for g in groups]
    largest = max(range(len(groups)), key=lambda k: counts[k])
    counts[largest] += robots - sum(counts)
    if counts[largest] < 0:  # more groups than robots: keep the first ones
        counts = [1 if k < robots else 0 for k in range(len(groups))]
    payment = base.payment.model_dump()
    if scheme != FROM_EXPERIMENT:
        name, stake = DEMO_SCHEMES[scheme]
        payment.update(scheme=name, stake=stake, params=payment["params"] if base.payment.scheme == name else {})
    return base.with_overrides(
        steps=steps, transitory=0,
        swarm={"robots": robots, "groups": [dict(g.model_dump(), count=c) for g, c in zip(groups, counts)]},
        payment=payment)


def non_negative_float(text: str) -> float:
    """A float option that must be finite and >= 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not value >= 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a finite number >= 0, got {text}")
    return value


def chain_config(config, period: int | None, gas_price: float | None):
    """``config`` with the chain model on when ``period`` is given (its other ``[chain]`` keys kept), and
    the gas price set when given; unchanged when neither is."""
    if period is None and gas_price is None:
        return config
    chain = config.chain.model_dump()
    if period is not None:
        chain.update(consensus="poa", period=period)
    if gas_price is not None:
        chain.update(gas_price=gas_price)
    return config.with_overrides(chain=chain)


def run_demo(args: argparse.Namespace) -> int:
    """Handler of ``infomarket chain demo``; returns the exit status."""
    try:
        # the chain extra (web3, py-evm, pyrevm) is optional: refused with a message if it is missing
        from .. import load_experiment, simulate
        from ..config import sizes
        from ..errors import ConfigError
        from .errors import ChainError
        from .market import connect
        from .evm_replay import market_params, replay_result
    except ImportError as exc:
        return report_error(f"infomarket chain needs the chain extra (pip install 'infomarket[chain]'): {exc}", 1)
    try:
        if args.robots > MAX_DEMO_ROBOTS:
            raise ConfigError(f"--robots {args.robots:,}: the demo packs its swarm into the experiment's arena, where "
                              f"every robot is in range of a share of all the others, so its buffers and event log "
                              f"grow as robots squared (measured: 2 000 robots 0.3 GB, 20 000 robots 3.7 GB for 10 "
                              f"steps); at most {MAX_DEMO_ROBOTS:,} (`infomarket bench --robots N --chain` times "
                              f"larger swarms at the paper's density)")
        config = demo_config(load_experiment(args.experiment), args.robots, args.steps, args.scheme)
        period, gas_price = getattr(args, "chain_period", None), getattr(args, "gas_price", None)
        if gas_price and period is None and not config.chain.enabled:  # named by its flag, before the config's check
            raise ConfigError("--gas-price needs the chain model: give --chain-period P too")
        config = chain_config(config, period, gas_price)
        if config.chain.enabled and (args.rpc or args.backend != "revm"):
            raise ConfigError("the block-by-block replay of the chain model needs the revm backend (its blocks "
                              "are set by the replay): drop --rpc and --backend py-evm")
        if args.rpc:
            connect(args.rpc)  # fail before simulating if the node is not there
        if config.payment.scheme == "outlier" and config.payment_params()["theta"] > 180:
            raise ConfigError("the contract needs theta in [0, 180] degrees")
        market_params(config)  # a scheme the contract does not implement is refused before simulating
        too_big = sizes.run_too_big(config, record_events=True)  # the demo keeps the whole event log
        if too_big:
            raise ConfigError(f"--steps {args.steps} --robots {args.robots}: {too_big}")
    except (ConfigError, ValueError, ChainError) as exc:
        return report_error(exc, 2)
    composition = ", ".join(f"{g.count} {g.behaviour}" for g in config.swarm.groups if g.count)
    scheme = config.payment.scheme if args.scheme == FROM_EXPERIMENT else args.scheme
    print(f"chain demo: {args.robots} robots ({composition}), {args.steps} steps, scheme {scheme} "
          f"(stake {config.payment.stake:g}), seed {args.seed}")
    if config.chain.enabled:
        return _run_chain_demo(config, args)
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


def _run_chain_demo(config, args) -> int:
    """The chain model's demo: simulate with a block log, then replay the canonical chain block by block."""
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

    # with the command: `infomarket --help` does not import the engine or the EVM client
    from ..engine.simulation import Simulation
    from ..ledger.blocklog import BlockLog
    from .block_replay import match_purchases, replay_blocks
    from .errors import ChainError

    c = config.chain
    print(f"chain model: Proof-of-Authority, a block every {c.period} steps (out of turn +{c.out_of_turn_delay}), "
          f"{'a backbone of latency ' + str(c.latency) + ', ' if c.backbone else ''}loss {c.loss:g}, "
          f"gas price {c.gas_price:g}")
    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn())
    with Progress(*columns, transient=True, disable=not sys.stderr.isatty()) as bar:
        sim = Simulation(config, args.seed, record_events=True)
        t0 = time.perf_counter()
        log = BlockLog(sim)
        task = bar.add_task("simulating (observing every block)", total=config.steps)
        log.run(progress=lambda t: bar.update(task, completed=t))
        observed = time.perf_counter() - t0
        result = sim.result()
        m = result.totals["chain"]
        blocks = log.canonical()
        print(f"simulated in {observed:.1f} s, observing every step: {m['blocks']} blocks made "
              f"({len(log.blocks)} seen), canonical height {m['height']}, {m['forks']} forks, {m['reorgs']} "
              f"reorganisations taking out {m['reorganised_tx']} transactions, {m['failed_tx']} failed, "
              f"{m['pending_tx']} pending at the end, mean payment delay {m['mean_payment_delay']:.1f} steps")
        deposits = sum(1 for b in blocks for tx in b.txs if tx.kind == "deposit")
        reveals = sum(1 for b in blocks for tx in b.txs if tx.kind == "reveal")
        if not deposits or not reveals:
            return report_error(f"the canonical chain holds {reveals} reveals and {deposits} deposits: with no "
                                "purchase paid out by a deposit the comparison would prove nothing; run more "
                                "--steps or --robots", 2)
        t0 = time.perf_counter()
        task = bar.add_task("replaying blocks on the EVM", total=len(blocks))
        try:
            report = replay_blocks(blocks, match_purchases(log.txs, result.events), config, seed=args.seed,
                                   progress=lambda k: bar.update(task, completed=k))
        except ChainError as exc:
            return report_error(exc, 1)
    print(f"replayed {len(blocks)} blocks ({reveals} reveals, {deposits} deposits) on the in-process EVM "
          f"({report.backend}) in {time.perf_counter() - t0:.1f} s, checking every balance after every block")
    g = report.gas_summary()
    print(f"  reveals landed          {report.reveals}; refused by the contract {len(report.refused)}; "
          f"refused by the model's gas check (not sent) {report.gas_refused}")
    print(f"  gas per reveal          {g['reveal_evm']:,.0f} measured (mean), {g['reveal_model']:,.0f} modelled; "
          f"equal for {g['reveal_equal']} of {report.reveals}")
    print(f"  gas per deposit         {g['deposit_evm']:,.0f} measured (mean), {g['deposit_model']:,.0f} modelled; "
          f"equal for {g['deposit_equal']} of {report.deposits}")
    print(f"  money conserved         {'yes' if report.conserved else 'NO'}")
    if report.first_mismatch is not None:
        print(f"first mismatch: {report.first_mismatch}")
    print(f"every robot's balance matches the modelled ledger at all {report.blocks_checked} blocks" if report.ok
          else f"balances DO NOT match the modelled ledger (checked {report.blocks_checked} blocks before)")
    return 0 if report.ok else 1


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
        f"(supply {report.total_supply / 1e9:.9f} = balances + locked stakes and bonds)",
        "  robot   on chain        simulated       diff (units)  bound",
    ]
    lines += [f"  {r.robot:5d}   {r.chain_units / 1e9:13.9f}   {r.expected:13.9f}   {r.diff_units:11.3f}  "
              f"{r.bound_units:5d}{'' if r.ok else '  <- differs'}" for r in rows]
    lines += [f"  disagreement: {d}" for d in report.disagreements]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Stand-alone entry (``python -m infomarket.evm.cli chain demo ...``), same as the main CLI's."""
    parser = argparse.ArgumentParser(prog="infomarket")
    add_subcommand(parser.add_subparsers(dest="command", required=True))
    args = parser.parse_args(argv)
    return args.func(args)


if __name__ == "__main__":
    sys.exit(main())
