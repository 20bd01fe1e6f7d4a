"""Gas of ``revealInformation`` and of a whole deposit as a round trip grows, and of the largest call
the contract allows, all measured with cold storage per transaction, as a chain charges it.

    python -m infomarket.evm.gasreport [--out docs/gas.md] [--backend revm|py-evm] [--rpc URL]
    python -m infomarket.evm.gasreport --constants [--out docs/gas.md]

``--constants`` measures nothing: it reads the report at ``--out`` and prints the constants of
``infomarket.ledger.gas`` (the chain model's gas) as they must read; ``tests/evm/test_gas_constants.py``
checks that they do.

For each payment scheme and each round-trip size n, one buyer receives n reveals from 16 sellers
(all for the same site, all within Theta of each other: the outlier weighting's worst case), then
deposits: ``buyItem`` and ``settle`` calls in batches of ``SETTLE_BATCH`` until settled; then it does a
second round trip of the same size. The first trip writes fresh storage; later trips reuse the slots
of the settled list, the steady state of a running swarm.

The bound: the largest call is a weighing call at the largest round trip the contract accepts (512
live records), and under ``outlier_distinct`` the worst round trip has 512 distinct sellers (no
comparison is skipped as "the same seller"). ``worst_call`` fills a round trip with 512 records of
512 distinct sellers, every pair similar, for every scheme, and measures every call of its deposit;
every call must stay under ``DECLARED_MAX_TX_GAS`` (the command exits 1 otherwise).

It runs on revm by default (seconds; cold storage per transaction, see ``backends``), one block per
transaction as on py-evm, and cross-checks the small sizes on py-evm, the reference EVM: every figure
must agree within ``CROSS_CHECK_TOLERANCE`` (the command exits 1 otherwise). They differ only by the
signatures, which are not deterministic: a zero byte of calldata costs 12 gas less than another.
"""
from __future__ import annotations

import argparse
import math
import random
import sys
from dataclasses import dataclass
from pathlib import Path
from statistics import mean

from ..errors import FormatError
from .market import (DECLARED_MAX_TX_GAS, DEFAULT_MAX_RECORDS_PER_TRIP, SETTLE_BATCH, ChainMarket, MarketParams,
                     connect, derived_account)
from .protocol import FOOD, PathInfo
from .units import to_units

#: Round-trip sizes measured: up to the contract's bound of live records per round trip (the chain model's
#: deposit table, ``ledger.gas``, reads "deposit, later trips" at these sizes).
SIZES = (1, 4, 16, 64, 128, 256, DEFAULT_MAX_RECORDS_PER_TRIP)
#: name -> (contract scheme, stake)
SCHEMES = {"delayed": ("delayed", 0.0), "outlier": ("outlier", 0.0), "outlier + staking": ("outlier", 0.04),
           "outlier_distinct": ("outlier_distinct", 0.0), "outlier_distinct + staking": ("outlier_distinct", 0.04)}
#: Schemes the contract has beyond the report's tables (the chain model charges them the outlier figures,
#: ``ledger.gas``): ``measure`` and ``worst_call`` take them too.
MORE_SCHEMES = {"capped_outlier + staking": ("capped_outlier", 0.04)}
#: The round-trip size whose mean reveal the chain model charges for every reveal.
MODEL_REVEAL_N = 16
SELLERS = 16
#: Distinct sellers of the worst round trip: one record each.
WORST_SELLERS = DEFAULT_MAX_RECORDS_PER_TRIP
#: Sizes measured again on py-evm when the report runs on revm, and how far apart (relative) any figure may be.
CROSS_CHECK_SIZES = (1, 4, 16)
CROSS_CHECK_TOLERANCE = 0.01


def gas_backend(name: str | None = "revm", rpc_url: str | None = None):
    """A chain to measure on: revm numbers its blocks as py-evm does (a block per transaction)."""
    backend = connect(rpc_url, name)
    if hasattr(backend, "automine"):
        backend.automine = True
    return backend


@dataclass(frozen=True)
class GasRow:
    """Gas measured for one scheme and round-trip size (deposit = buyItem + its settle calls)."""

    scheme: str
    n: int
    reveal_mean: float
    reveal_max: int
    deposit_first: int
    deposit_later: int
    transactions: int
    largest_tx: int


@dataclass(frozen=True)
class WorstCall:
    """A deposit at the largest round trip: its ``buyItem``, its largest ``settle``, how many calls and
    how much gas in all."""

    scheme: str
    n: int
    sellers: int
    reveal_max: int
    buy_item: int
    settle: int
    calls: int
    total: int

    @property
    def largest(self) -> int:
        """The most gas any single call of the deposit used (reveal, ``buyItem`` or ``settle``): what must fit a
        block."""
        return max(self.reveal_max, self.buy_item, self.settle)


def _market(scheme: str, backend, seed: int, buyers: int, sellers: int = SELLERS, batch: int = SETTLE_BATCH):
    """A market for ``scheme`` whose one registrar may register every account at once (the registration
    policy changes no gas but the registrations')."""
    name, stake = {**SCHEMES, **MORE_SCHEMES}[scheme]
    params = MarketParams.from_floats(name, stake=stake, settle_batch=batch, registrars=1, registrar_threshold=1,
                                      registrar_quota=2**32)
    market = ChainMarket.deploy(params, backend=backend, seed=seed)
    sellers = [derived_account("gas-seller", i, seed) for i in range(sellers)]
    buyer_accounts = [derived_account("gas-buyer", i, seed) for i in range(buyers)]
    backend.fund([a.address for a in sellers + buyer_accounts])
    for s in sellers:
        market.grant_wealth(s, to_units(100.0))
    for b in buyer_accounts:
        market.grant_wealth(b, 0)  # registers the buyer
    return market, sellers, buyer_accounts


def _reveal_all(market, sellers, buyer, n: int, rng: random.Random, first_age: int = 0) -> list[int]:
    gas = []
    for k in range(n):
        seller = sellers[k % len(sellers)]
        angle = math.radians(rng.uniform(0.0, 20.0))
        info = PathInfo.from_floats(30 * math.cos(angle), 30 * math.sin(angle))
        lc = market.light_contract(seller, buyer, FOOD, first_age + k, info, (0.0, 0.0))
        gas.append(market.reveal(seller, lc, info).gas_used)
    return gas


def sellers_for(n: int) -> int:
    """Sellers of a measured round trip of ``n`` records: 16, or as many as the contract needs to accept
    them all (a seller's further records may take at most half of the room its first records leave:
    2 * (n - sellers) + sellers <= 512)."""
    return max(SELLERS, 2 * n - DEFAULT_MAX_RECORDS_PER_TRIP)


def measure(scheme: str, sizes=SIZES, *, trips: int = 2, backend=None, seed: int = 0) -> list[GasRow]:
    """Deploy a market for ``scheme`` (a key of ``SCHEMES``) and measure every size in ``sizes`` over
    ``trips`` round trips (``deposit_later`` is the last one's; with one trip it equals the first)."""
    backend = backend or gas_backend()
    market, sellers, buyers = _market(scheme, backend, seed, len(sizes), max(map(sellers_for, sizes)))
    rng = random.Random(seed)
    rows = []
    for n, buyer in zip(sizes, buyers):
        reveals, deposits, largest, count = [], [], 0, 0
        for trip in range(trips):
            reveals += _reveal_all(market, sellers[:sellers_for(n)], buyer, n, rng, trip * n)
            results = market.deposit(buyer.address, SETTLE_BATCH)
            deposits.append(sum(r.gas_used for r in results))
            largest = max(largest, *(r.gas_used for r in results))
            count = len(results)
        rows.append(GasRow(scheme, n, mean(reveals), max(reveals), deposits[0], deposits[-1], count, largest))
    return rows


def worst_call(scheme: str, n: int = DEFAULT_MAX_RECORDS_PER_TRIP, *, sellers: int = WORST_SELLERS,
               backend=None, seed: int = 0) -> WorstCall:
    """Fill one round trip with ``n`` records of ``sellers`` sellers (every pair similar) and deposit it:
    the most expensive calls the contract allows at that size, and what the whole deposit costs."""
    backend = backend or gas_backend()
    market, accounts, (buyer,) = _market(scheme, backend, seed, 1, sellers)
    reveals = _reveal_all(market, accounts, buyer, n, random.Random(seed))
    buy = market.buy_item(buyer.address).gas_used
    settles = []
    while market.pending_settlement(buyer.address)[0]:
        settles.append(market.settle(buyer.address, SETTLE_BATCH).gas_used)
    return WorstCall(scheme, n, sellers, max(reveals), buy, max(settles, default=0), 1 + len(settles),
                     buy + sum(settles))


def cross_check(rows: list[GasRow], sizes=CROSS_CHECK_SIZES, *, seed: int = 0) -> float:
    """Measure ``sizes`` of every scheme in ``rows`` again on py-evm, the reference EVM, and return the
    largest relative difference of any figure (the number of transactions must be equal)."""
    largest = 0.0
    for scheme in dict.fromkeys(r.scheme for r in rows):
        mine = {r.n: r for r in rows if r.scheme == scheme}
        for ref in measure(scheme, sizes, backend=connect(backend="py-evm"), seed=seed):
            row = mine[ref.n]
            if row.transactions != ref.transactions:
                return math.inf
            for name in ("reveal_mean", "reveal_max", "deposit_first", "deposit_later", "largest_tx"):
                largest = max(largest, abs(getattr(row, name) - getattr(ref, name)) / getattr(ref, name))
    return largest


def render(rows: list[GasRow], worst: list[WorstCall], backend: str = "revm", checked: float | None = None) -> str:
    """The Markdown of docs/gas.md (``checked``: the cross-check's largest relative difference)."""
    lines = [
        "# Gas of the on-chain market",
        "",
        f"Generated by `python -m infomarket.evm.gasreport` (`make gas`) on {backend}, which starts every",
        "transaction with cold accounts and storage (EIP-2929), as a chain does; Cancun rules; solc-js",
        "0.8.28, optimizer 200 runs, via-IR. One buyer, `n` reveals from 16 sellers for one site (at n = 512",
        "from 512: a seller's further records may take at most half of the room its first ones leave), every",
        "vector within Theta of every other (the outlier weighting's worst case), then a deposit:",
        f"`buyItem` and `settle(robot, {SETTLE_BATCH})` calls until the round trip is settled; then a second",
        "round trip of the same size. *First trip* writes fresh storage; *later trips* reuse the settled",
        "list's slots, the steady state of a running swarm. Gas includes the 21 000 of each transaction.",
        "*Largest tx* is the most gas one transaction of the deposit took.",
        "",
    ]
    lines += ["The chain model (docs/chain-model.md, `ledger.gas`) charges every reveal the *reveal, mean* at",
              f"n = {MODEL_REVEAL_N} and a deposit the *deposit, later trips* figure at the number of reveals it "
              "settles,",
              "linear between the sizes measured; a deposit of more than "
              f"{SIZES[-1]} reveals (the contract refuses reveals beyond",
              f"{DEFAULT_MAX_RECORDS_PER_TRIP} live records per round trip; the model does not) costs the "
              f"n = {SIZES[-1]} figure. `python -m",
              "infomarket.evm.gasreport --constants` prints those constants from this file.", ""]
    if checked is not None:
        lines += [f"Cross-check: the sizes {', '.join(map(str, CROSS_CHECK_SIZES))} measured again on py-evm, "
                        "the reference EVM: every figure", f"within {checked:.3%} (tolerance "
                        f"{CROSS_CHECK_TOLERANCE:.0%}; the signatures differ between runs, and a zero byte of calldata",
                        "costs 12 gas less than another). `tests/evm/test_revm_gas.py` compares every transaction.",
                        ""]
    for scheme in dict.fromkeys(r.scheme for r in rows):
        lines += [f"## {scheme}", "",
                  "| n | reveal, mean | reveal, max | deposit, first trip | deposit, later trips | transactions "
                  "| largest tx |",
                  "|---:|---:|---:|---:|---:|---:|---:|"]
        lines += [f"| {r.n} | {r.reveal_mean:,.0f} | {r.reveal_max:,} | {r.deposit_first:,} | {r.deposit_later:,} "
                  f"| {r.transactions} | {r.largest_tx:,} |" for r in rows if r.scheme == scheme]
        lines.append("")
    lines += ["## The bound: the largest calls at the largest round trip", "",
              "A round trip holds at most 512 live records and a call does at most one batch of work (at most",
              "48 units), so the most expensive call is a weighing call with 512 live records: it loads all 512",
              "and compares a few of them with all (a record costs ceil(512 / 64) = 8 units, under",
              "`outlier_distinct` ceil(512 / 40) = 13, whose comparisons also look up the other record's seller).",
              "The worst round trip has 512 distinct sellers, one record each, every pair similar: under",
              "`outlier_distinct` no comparison is then skipped as the same seller's. Measured for every scheme",
              "after filling one round trip so, with the whole deposit (`buyItem` and every `settle` call):", "",
              "| scheme | n | sellers | reveal, max | buyItem | settle, max | calls | deposit, all calls |",
              "|---|---:|---:|---:|---:|---:|---:|---:|"]
    lines += [f"| {w.scheme} | {w.n} | {w.sellers} | {w.reveal_max:,} | {w.buy_item:,} | {w.settle:,} | {w.calls} "
              f"| {w.total:,} |" for w in worst]
    everything = [r.largest_tx for r in rows] + [w.largest for w in worst]
    lines += ["", f"Largest single transaction measured: {max(everything, default=0):,} gas; declared bound "
              f"(`DECLARED_MAX_TX_GAS`): {DECLARED_MAX_TX_GAS:,}.", ""]
    return "\n".join(lines)


def parse(text: str) -> list[GasRow]:
    """The per-scheme rows of a report ``render`` wrote (the bound's table is not read)."""
    rows, scheme = [], None
    for line in text.splitlines():
        if line.startswith("## "):
            scheme = line[3:].strip()
            scheme = scheme if scheme in SCHEMES else None
        elif scheme and line.startswith("| ") and line[2:3].isdigit():
            cells = [c.strip().replace(",", "") for c in line.strip("|").split("|")]
            n, mean_, top, first, later, count, largest = cells
            rows.append(GasRow(scheme, int(n), float(mean_), int(top), int(first), int(later), int(count),
                               int(largest)))
    return rows


def constants(rows: list[GasRow]) -> str:
    """The constants of ``infomarket.ledger.gas`` as they must read for ``rows`` (a report's rows): the
    mean reveal at ``MODEL_REVEAL_N`` and the later trips' deposit at every size, per scheme."""
    schemes = list(dict.fromkeys(r.scheme for r in rows))
    sizes = [r.n for r in rows if r.scheme == schemes[0]]
    if any([r.n for r in rows if r.scheme == s] != sizes for s in schemes):
        raise FormatError("the report's schemes were measured at different sizes")
    if MODEL_REVEAL_N not in sizes:
        raise FormatError(f"the report has no n = {MODEL_REVEAL_N} row, whose mean reveal the model charges")
    reveal = {s: round(r.reveal_mean) for s in schemes for r in rows if r.scheme == s and r.n == MODEL_REVEAL_N}
    lines = ["GAS_REVEAL = {"] + [f'    "{s}": {reveal[s]:_},' for s in schemes] + ["}"]
    lines.append(f"GAS_DEPOSIT_N = ({', '.join(map(str, sizes))})")
    lines.append("GAS_DEPOSIT = {")
    for s in schemes:
        later = ", ".join(f"{r.deposit_later:_}" for r in rows if r.scheme == s)
        lines.append(f'    "{s}": ({later}),')
    lines.append("}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """``python -m infomarket.evm.gasreport``: measure the contract's gas on an in-process EVM (or a node) and
    write the gas report; returns the exit code."""
    parser = argparse.ArgumentParser(prog="python -m infomarket.evm.gasreport", description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("docs/gas.md"), help="Markdown file to write")
    parser.add_argument("--backend", choices=("revm", "py-evm"), default="revm",
                        help="in-process EVM, both with cold storage per transaction as a chain: revm (default, "
                             "seconds; its small sizes cross-checked on py-evm) or py-evm (the reference, minutes)")
    parser.add_argument("--rpc", metavar="URL", help="JSON-RPC node to measure on instead")
    parser.add_argument("--constants", action="store_true",
                        help="measure nothing: print infomarket.ledger.gas's constants from the report at --out")
    args = parser.parse_args(argv)
    if args.constants:
        if not args.out.is_file():
            print(f"--out {args.out}: no such report (run without --constants to measure it)", file=sys.stderr)
            return 2
        rows = parse(args.out.read_text())
        if not rows:
            print(f"--out {args.out}: no gas table in it", file=sys.stderr)
            return 2
        try:
            print(constants(rows))
        except FormatError as err:
            print(f"--out {args.out}: {err}", file=sys.stderr)
            return 2
        return 0
    rows = [row for scheme in SCHEMES for row in measure(scheme, backend=gas_backend(args.backend, args.rpc))]
    worst = [worst_call(scheme, backend=gas_backend(args.backend, args.rpc)) for scheme in SCHEMES]
    checked = cross_check(rows) if args.rpc is None and args.backend == "revm" else None
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(render(rows, worst, args.rpc or args.backend, checked))
    print(f"wrote {args.out}")
    if checked is not None and checked > CROSS_CHECK_TOLERANCE:
        print(f"revm and py-evm differ by {checked:.2%}, more than {CROSS_CHECK_TOLERANCE:.0%}", file=sys.stderr)
        return 1
    return 1 if any(r.largest_tx > DECLARED_MAX_TX_GAS for r in rows) or any(
        w.largest > DECLARED_MAX_TX_GAS for w in worst) else 0


if __name__ == "__main__":
    raise SystemExit(main())
