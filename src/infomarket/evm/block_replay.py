"""Replay the blocks a chain-model run produced on the EVM, block by block, and check every robot's balance
against the modelled ledger after every block (``infomarket chain demo --chain-period P``, docs/chain.md).

The input is the canonical chain a ``ledger.blocklog.BlockLog`` saw (genesis first) and the run's
purchase events (``record_events=True``), which carry what a light contract needs (the vector, the
seller's position, the age): the k-th reveal the model sent (in sending order) is the k-th purchase
event; each pair is checked to agree on buyer, seller, site and step.  Modelled block h is EVM block
``b0 + h``; its transactions run in the block's order: a reveal is the seller's ``revealInformation``
of a light contract signed by both robots, a deposit is the market's ``buyItem`` and the ``settle``
calls (as ``evm_replay`` maps them).

What the model charges that the contract does not: gas.  The model burns ``gas_price`` x gas from a
robot's balance (docs/chain-model.md, "Gas"); on the EVM gas is paid in ether, never in the market's
token.  So the replay keeps each robot's gas bill by the model's rule (a reveal that lands costs the gas
its sender set aside, a deposit that settles n records costs the measured table at n, never more than
the depositor's balance) and compares the EVM's balance with the modelled balance plus that bill.  The
model's reveal check includes the gas ("the branch could not pay": balance < stake + gas); the contract
checks the stake only, so with a gas price a reveal the model's rule refuses is not sent and is counted
(``gas_refused``).  Every other refusal is the contract's own (``InfoMarketInsufficientStake``), and the
balance check of that block says whether the model failed it too.

Tolerance per robot: the shares the contract floors to whole units (``evm_replay``'s rounding bound,
counted over the blocks so far) plus ``FLOAT_SLACK_UNITS``.  The replay stops at the first block whose
balances differ and reports it: block, height, step, robot, both balances.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from statistics import mean

from ..ledger.gas import GAS_DEPOSIT_N, gas_schedule, table_gas
from ..ledger.lock import STAKE_TOLERANCE

from .errors import ChainError, ContractRevert
from .evm_replay import FLOAT_SLACK_UNITS, REPLAY_NO_EXPIRY, BalanceRow, SITE_CODES, _count_rounding, market_params
from .market import ChainMarket, connect, derived_account
from .protocol import PathInfo
from .units import TOKEN_UNIT, to_units

@dataclass(frozen=True)
class BlockMismatch(BalanceRow):
    """The first block after which a robot's EVM balance is not the modelled one."""

    block: int = 0
    height: int = 0
    step: int = 0

    def __str__(self) -> str:
        return (f"block {self.block} (height {self.height}, made at step {self.step}): robot {self.robot} has "
                f"{self.chain_units / TOKEN_UNIT:.9f} on the EVM, the modelled ledger {self.expected:.9f} "
                f"(differs by {self.diff_units:.1f} units, allowed {self.bound_units + FLOAT_SLACK_UNITS:g})")


@dataclass
class BlockReplayReport:
    """What the block-by-block replay did and found."""

    robots: int
    backend: str = ""
    cold_storage: bool = True
    blocks_checked: int = 0
    reveals: int = 0
    deposits: int = 0
    #: reveals the contract refused (height, transaction seq, error name)
    refused: list[tuple[int, int, str]] = field(default_factory=list)
    #: reveals not sent: the model's rule refuses them for the gas (the contract has no gas in tokens)
    gas_refused: int = 0
    reveal_gas: list[int] = field(default_factory=list)        # measured on the EVM, per reveal
    model_reveal_gas: list[float] = field(default_factory=list)  # the model's gas units for the same reveal
    deposit_gas: list[int] = field(default_factory=list)       # buyItem + settle calls, per deposit
    model_deposit_gas: list[float] = field(default_factory=list)
    first_mismatch: BlockMismatch | None = None
    conserved: bool = True

    @property
    def ok(self) -> bool:
        """True when every block matched the model and tokens were conserved."""
        return self.first_mismatch is None and self.conserved

    def gas_summary(self) -> dict[str, float]:
        """Mean gas per reveal and per deposit, measured on the EVM and as the model counts it, and how many calls
        agree exactly."""
        def avg(xs):
            return mean(xs) if xs else float("nan")

        same_reveal = sum(1 for a, b in zip(self.reveal_gas, self.model_reveal_gas) if a == b)
        same_deposit = sum(1 for a, b in zip(self.deposit_gas, self.model_deposit_gas) if a == round(b))
        return {"reveal_evm": avg(self.reveal_gas), "reveal_model": avg(self.model_reveal_gas),
                "reveal_equal": same_reveal, "deposit_evm": avg(self.deposit_gas),
                "deposit_model": avg(self.model_deposit_gas), "deposit_equal": same_deposit}


def match_purchases(txs, events) -> dict:
    """Each reveal the model sent (``txs``: seq -> ``ChainTx``, e.g. ``BlockLog.txs``) with its purchase
    event: the k-th reveal in sending order is the k-th purchase logged.  Checked to agree on buyer,
    seller, site and step; ``ChainError`` when they do not (or the events were not recorded)."""
    records = events.to_dict("records") if hasattr(events, "to_dict") else list(events)
    purchases = [r for r in records if r["kind"] == "purchase"]
    reveals = [txs[s] for s in sorted(txs) if txs[s].kind == "reveal"]
    if len(purchases) != len(reveals):
        raise ChainError(f"the run sent {len(reveals)} reveals but logged {len(purchases)} purchases: "
                         "record the run's events (record_events=True) from its first step")
    out = {}
    for tx, ev in zip(reveals, purchases):
        site = SITE_CODES[ev["site"]]
        if (int(ev["buyer"]), int(ev["seller"]), site, int(ev["step"])) != (tx.buyer, tx.seller, tx.site, tx.step):
            raise ChainError(f"reveal {tx.seq} (step {tx.step}, seller {tx.seller} to buyer {tx.buyer}) does not "
                             f"match its purchase event (step {ev['step']}, seller {ev['seller']} to buyer "
                             f"{ev['buyer']})")
        out[tx.seq] = ev
    return out


def replay_blocks(blocks, purchase_of: dict, config, *, seed: int = 0, backend: str | None = None,
                  blocks_valid: int = 8, progress=None) -> BlockReplayReport:
    """Replay ``blocks`` (the canonical chain, genesis first: ``ledger.blocklog.Block``) on a fresh market,
    one EVM block per modelled block, checking every balance after every block.  ``purchase_of``: each
    reveal's purchase event by transaction seq (``match_purchases``); ``config``: the run's experiment."""
    import numpy as np

    robots = config.swarm.robots
    params = market_params(config)
    params = replace(params, stake_expiry=REPLAY_NO_EXPIRY)  # the chain model refuses stake expiry
    price = config.chain.gas_price
    _, table = gas_schedule(config.payment.scheme, config.payment.stake)
    table_n, table = np.asarray(GAS_DEPOSIT_N, dtype=np.float64), np.asarray(table, dtype=np.float64)
    stake = config.payment.stake

    chain = connect(None, backend)
    market = ChainMarket.deploy(params, backend=chain, seed=seed)
    accounts = [derived_account("robot", i, seed) for i in range(robots)]
    chain.fund([a.address for a in accounts])
    wealth = to_units(config.payment.initial_wealth)
    for a in accounts:
        market.grant_wealth(a, wealth)
    base = chain.block_number + 1
    report = BlockReplayReport(robots, backend=chain.name, cold_storage=chain.cold_storage)
    bound = [0] * robots
    gas_bill = [0.0] * robots        # money the model burned from each robot as gas, so far
    open_sellers: list[list[int]] = [[] for _ in range(robots)]
    minted = (wealth + market.bond) * robots

    def balance(i: int) -> int:
        return market.balance_of(accounts[i].address)

    for number, blk in enumerate(blocks):
        if progress is not None:
            progress(number)
        chain.advance_to(base + blk.height)
        for tx in blk.txs:
            if tx.kind == "deposit":
                buyer = tx.buyer
                n = len(open_sellers[buyer])
                results = market.deposit(accounts[buyer].address)
                minted += params.reward
                report.deposits += 1
                report.deposit_gas.append(sum(r.gas_used for r in results))
                report.model_deposit_gas.append(float(table_gas(table_n, table, float(n))))
                _count_rounding(bound, buyer, open_sellers[buyer])
                open_sellers[buyer] = []
                if price > 0:
                    left = balance(buyer) / TOKEN_UNIT - gas_bill[buyer]
                    gas_bill[buyer] += min(price * report.model_deposit_gas[-1], max(left, 0.0))
                continue
            ev = purchase_of[tx.seq]
            seller, buyer = tx.seller, tx.buyer
            if price > 0 and balance(seller) / TOKEN_UNIT - gas_bill[seller] < stake + tx.gas - STAKE_TOLERANCE:
                report.gas_refused += 1  # the model's check, with the gas the contract does not charge
                continue
            info = PathInfo.from_floats(float(ev["x"]), float(ev["y"]))
            position = (float(ev.get("seller_x", 0.0)), float(ev.get("seller_y", 0.0)))
            lc = market.light_contract(accounts[seller], accounts[buyer], SITE_CODES[ev["site"]], int(ev["age"]),
                                       info, position, blocks_valid)
            try:
                result = market.reveal(accounts[seller], lc, info)
            except ContractRevert as err:
                report.refused.append((blk.height, tx.seq, err.name))
                continue
            report.reveals += 1
            report.reveal_gas.append(result.gas_used)
            report.model_reveal_gas.append(tx.gas / price if price > 0 else float(gas_schedule(
                config.payment.scheme, stake)[0]))
            open_sellers[buyer].append(seller)
            gas_bill[seller] += tx.gas
        for i in range(robots):
            expected = float(blk.balances[i]) + gas_bill[i]
            row = BlockMismatch(i, balance(i), expected, bound[i], blk.id, blk.height, blk.step)
            if not row.ok:
                report.first_mismatch = row
                return _finish(report, market, accounts, minted)
        report.blocks_checked += 1
    return _finish(report, market, accounts, minted)


def _finish(report: BlockReplayReport, market, accounts, minted: int) -> BlockReplayReport:
    held = sum(market.balance_of(a.address) + market.locked_stake(a.address) + market.bond_of(a.address)
               for a in accounts)
    report.conserved = held == market.total_supply() == minted
    return report
