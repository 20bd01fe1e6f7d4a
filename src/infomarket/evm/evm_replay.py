"""Replay a simulated swarm's event log on the EVM, through the contract, and compare the two ledgers.

The simulator's ledger and the contract implement the same rules (docs/model.md §5) in floats and
in fixed point. Feeding the contract the same events (every purchase as a real light contract
revealed by its seller, every deposit as the market's ``buyItem``) and comparing every robot's final
balance is the conformance check between the two backends.

How close must they be? Each share the contract pays is floored to a whole unit (1e-9 token) and the
remainder stays with the depositing robot, so a robot's on-chain balance may differ from the exact
value by less than one unit per share it received or paid out; ``ReplayReport.rounding_bound`` counts
exactly those, per robot. The simulator's float error is below 1e-3 unit for runs of this size, so the
comparison allows ``FLOAT_SLACK_UNITS`` on top of the bound and nothing more.
"""
from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from statistics import mean

from ..engine.world import SITE_NAMES
from ..errors import ArgumentError
from ..payments import default_theta
from .errors import ChainError, ContractRevert
from .market import SCHEMES, ChainMarket, MarketParams, connect, derived_account
from .protocol import PathInfo
from .units import TOKEN_UNIT, to_units

#: The stake expiry (blocks) that stands for the simulation's "never": no replay comes near 2^40 blocks.
REPLAY_NO_EXPIRY = 2**40
#: Allowance for the simulator's own floating-point error, in units (1e-9 token).
FLOAT_SLACK_UNITS = 0.5
SITE_CODES = {**{k: k for k in range(len(SITE_NAMES))}, **{name: k for k, name in enumerate(SITE_NAMES)}}


@dataclass(frozen=True)
class BalanceRow:
    """One robot's balance on chain against the simulated ledger."""

    robot: int
    chain_units: int
    expected: float
    bound_units: int

    @property
    def diff_units(self) -> float:
        """Chain balance minus the model's expected wealth, in token units."""
        return self.chain_units - self.expected * TOKEN_UNIT

    @property
    def ok(self) -> bool:
        """Whether the difference is within the rounding bound (plus the float slack of the model's own sums)."""
        return abs(self.diff_units) <= self.bound_units + FLOAT_SLACK_UNITS


@dataclass
class ReplayReport:
    """What the replay cost and the state it left on chain."""

    robots: int
    reveal_gas: list[int] = field(default_factory=list)
    buy_gas: list[int] = field(default_factory=list)
    first_block: int = 0
    last_block: int = 0
    refusals_confirmed: int = 0
    expired: int = 0
    largest_tx: int = 0
    settle_calls: int = 0
    backend: str = ""
    #: whether the backend charged gas with cold storage per transaction, as a chain does
    cold_storage: bool = True
    disagreements: list[str] = field(default_factory=list)
    balances: list[int] = field(default_factory=list)
    pots: list[int] = field(default_factory=list)
    rounding_bound: list[int] = field(default_factory=list)
    total_supply: int = 0
    minted: int = 0
    #: the robots' registration bonds, locked (part of what was minted)
    bonds: int = 0

    @property
    def items(self) -> int:
        """Items delivered on chain (one ``buyItem`` each)."""
        return len(self.buy_gas)

    @property
    def blocks_used(self) -> int:
        """Blocks the replay spanned, from its first to its last."""
        return self.last_block - self.first_block

    @property
    def gas_per_item(self) -> float:
        """All the gas of the market's activity (reveals, buys and settlements) per item delivered."""
        return (sum(self.reveal_gas) + sum(self.buy_gas)) / self.items if self.items else float("nan")

    def conserved(self) -> bool:
        """Money on chain is exactly what was granted plus the rewards: nothing created or lost."""
        return sum(self.balances) + sum(self.pots) + self.bonds == self.total_supply == self.minted

    def compare(self, expected: Sequence[float]) -> list[BalanceRow]:
        """Each robot's on-chain balance against ``expected`` (the simulated ledger's, in tokens)."""
        if len(expected) != self.robots:
            raise ArgumentError(f"expected {self.robots} balances, got {len(expected)}")
        return [BalanceRow(i, self.balances[i], float(expected[i]), self.rounding_bound[i])
                for i in range(self.robots)]

    def summary(self) -> dict[str, float]:
        """The replay's costs as a flat dict for tables: reveals, items, mean and worst gas per call and per item,
        blocks used."""
        def avg(xs: list[int]) -> float:
            return mean(xs) if xs else float("nan")

        return {"reveals": len(self.reveal_gas), "items": self.items, "gas_per_reveal": avg(self.reveal_gas),
                "gas_per_buy_item": avg(self.buy_gas), "max_gas_buy_item": max(self.buy_gas, default=0),
                "gas_per_item": self.gas_per_item, "blocks_used": self.blocks_used,
                "refusals_confirmed": self.refusals_confirmed, "expired": self.expired, "largest_tx": self.largest_tx,
                "settle_calls": self.settle_calls}


@dataclass(frozen=True)
class ReplayMarket:
    """What a replay starts from: ``market`` deployed with ``params`` (the simulation's "no expiry" made
    one the replay cannot reach), every robot in ``accounts`` registered with ``wealth`` units."""

    market: ChainMarket
    params: MarketParams
    accounts: list
    wealth: int
    expire: bool


def replay_market(*, robots: int, params: MarketParams, initial_wealth: float, rpc_url: str | None = None,
                  backend: str | None = None, seed: int = 0, chain=None) -> ReplayMarket:
    """Deploy a market for ``replay_on_chain`` and register ``robots`` accounts with their initial wealth,
    on ``chain`` (a backend) or else a new connection (``rpc_url``, ``backend``)."""
    if not params.stake_expiry:
        # The simulation's "no expiry" (0): the contract always has one, so pick one the replay cannot reach.
        params = replace(params, stake_expiry=REPLAY_NO_EXPIRY)
        expire = False
    else:
        expire = True
    chain = chain or connect(rpc_url, backend)
    market = ChainMarket.deploy(params, backend=chain, seed=seed)
    accounts = [derived_account("robot", i, seed) for i in range(robots)]
    chain.fund([a.address for a in accounts])
    wealth = to_units(initial_wealth)
    for a in accounts:
        market.grant_wealth(a, wealth)  # registers every robot, with or without wealth
    return ReplayMarket(market, params, accounts, wealth, expire)


def replay_on_chain(events: Iterable[Mapping] | object, *, robots: int, params: MarketParams,
                    initial_wealth: float, rpc_url: str | None = None, backend: str | None = None,
                    seed: int = 0, blocks_valid: int = 8, progress=None,
                    start: ReplayMarket | None = None) -> ReplayReport:
    """Deploy a market, give ``robots`` accounts their initial wealth, and replay ``events``.

    ``events`` are the simulator's event records (a DataFrame or mappings) with ``kind`` in
    ``purchase | refused | deposit``, ``step``, ``buyer``, ``seller``, ``site``, ``x``, ``y``, ``age``,
    ``seller_x``/``seller_y`` (the seller's position in the buyer's frame, which the buyer signs).
    Step ``s`` is replayed in block ``b0 + s`` (``b0``: the first block after the setup), every
    transaction of the step in that block when the backend sets its blocks (revm); a backend that
    mines one block per transaction (py-evm, a node) only needs ``stake_expiry == 0``. Before the
    first event of each step, the round trips that expire at that step are settled (``refundExpired``),
    as the simulation does at the start of its step. A deposit is ``buyItem`` followed by ``settle``
    until the round trip is settled. A purchase the chain refuses, or a refusal the chain would accept,
    is recorded in ``disagreements`` rather than stopping the replay. ``start``: the market to replay
    on, as ``replay_market`` deploys it with the same arguments (a caller replaying many event logs
    on one chain reverts to it), instead of deploying one.
    """
    records = events.to_dict("records") if hasattr(events, "to_dict") else list(events)
    start = start or replay_market(robots=robots, params=params, initial_wealth=initial_wealth, rpc_url=rpc_url,
                                   backend=backend, seed=seed)
    market, params, accounts, wealth, expire = start.market, start.params, start.accounts, start.wealth, start.expire
    if len(accounts) != robots:
        raise ArgumentError(f"the replay's market registers {len(accounts)} robots, not {robots}")
    chain = market.backend
    base = chain.block_number + 1
    chain.advance_to(base)

    report = ReplayReport(robots, first_block=chain.block_number, rounding_bound=[0] * robots,
                          minted=(wealth + market.bond) * robots)
    open_steps: list[list[tuple[int, int]]] = [[] for _ in range(robots)]  # (step, seller) per open record
    step = None
    for number, ev in enumerate(records):
        if progress is not None and number % 1000 == 0:
            progress(number)
        kind = ev["kind"]
        if kind not in ("purchase", "refused", "deposit"):
            raise ChainError(f"event {number}: unknown kind {kind!r}")
        ev_step = int(ev.get("step", 0))
        if step is None or ev_step > step:
            step = ev_step
            if expire and chain.block_number > base + step:
                raise ChainError("stake expiry needs one block per step: replay on the revm backend")
            chain.advance_to(base + step)
            if expire:
                _expire(market, accounts, open_steps, step, params, report)
        if kind == "deposit":
            buyer = int(ev["buyer"])
            results = market.deposit(accounts[buyer].address)
            report.buy_gas.append(sum(r.gas_used for r in results))
            report.largest_tx = max(report.largest_tx, *(r.gas_used for r in results))
            report.settle_calls += len(results) - 1
            report.minted += params.reward
            _count_rounding(report.rounding_bound, buyer, [s for _, s in open_steps[buyer]])
            open_steps[buyer] = []
            continue
        buyer, seller = int(ev["buyer"]), int(ev["seller"])
        info = PathInfo.from_floats(float(ev["x"]), float(ev["y"]))
        position = (float(ev.get("seller_x", 0.0)), float(ev.get("seller_y", 0.0)))
        lc = market.light_contract(accounts[seller], accounts[buyer], SITE_CODES[ev["site"]], int(ev["age"]),
                                   info, position, blocks_valid)
        if kind == "purchase":
            try:
                report.reveal_gas.append(market.reveal(accounts[seller], lc, info).gas_used)
            except ContractRevert as err:
                report.disagreements.append(f"event {number} (step {step}): purchase refused on chain: {err}")
                continue
            open_steps[buyer].append((step, seller))
        else:
            try:
                market.check_reveal(accounts[seller], lc, info)
            except ContractRevert as err:
                if err.name == "InfoMarketInsufficientStake":
                    report.refusals_confirmed += 1
                    continue
                raise
            margin = market.balance_of(accounts[seller].address) - params.stake
            report.disagreements.append(f"event {number} (step {step}): refused purchase accepted on chain "
                                        f"(seller {seller} has {margin} units above the stake)")

    report.last_block = chain.block_number
    report.balances = [market.balance_of(a.address) for a in accounts]
    report.pots = [market.locked_stake(a.address) for a in accounts]
    report.total_supply = market.total_supply()
    report.bonds = sum(market.bond_of(a.address) for a in accounts)
    report.backend = chain.name
    report.cold_storage = chain.cold_storage
    return report


def _expire(market, accounts, open_steps, step: int, params: MarketParams, report: ReplayReport) -> None:
    """Settle, on chain, every open round trip whose first record was opened at ``step - expiry`` or
    before (``refundExpired``, then ``settle`` until done; anyone may), buyers in id order as the
    simulated ledger settles them."""
    share = params.reward * params.information_share // 10**18
    for buyer, opened in enumerate(open_steps):
        if not opened or opened[0][0] + params.stake_expiry > step:
            continue
        results = market.expire(accounts[buyer].address)
        report.expired += len(opened)
        report.largest_tx = max(report.largest_tx, *(r.gas_used for r in results))
        (closed,) = results[0].of("RoundTripExpired")
        carried = report.rounding_bound[buyer] + 1 if closed["share"] < share else 0
        sellers = [s for _, s in opened]
        _count_rounding(report.rounding_bound, buyer, sellers)
        for s in sellers:  # a short share is the buyer's whole balance, rounded as the buyer's is
            report.rounding_bound[s] += carried
        opened.clear()


#: Why a scheme the simulator has is not on chain (the contract implements ``market.SCHEMES``).
OFF_CHAIN = {
    "consensus_slash": "consensus_slash is not on chain: it slashes by the angle between a record and its "
                       "site's medoid, and the contract compares vectors by exact integer dot products, with no "
                       "angles; an integer arctangent would not reproduce the simulated ledger's floating-point "
                       "angles bit for bit, so the two ledgers could not be checked against each other "
                       "(docs/chain.md, \"Which rules run where\")",
    "adaptive_outlier": "adaptive_outlier is not on chain: each seller's Theta follows its reputation, which the "
                        "simulated ledger keeps and the contract does not",
    "outcome_slash": "outcome_slash is not on chain: it slashes by the depositing buyer's own outcome records of "
                     "its sellers, robot state that the contract does not hold (a buyer would have to report "
                     "them with its deposit)",
    "trip_slash": "trip_slash is not on chain: it slashes by the depositing buyer's own outcome records of its "
                  "sellers (the failures since its last settlement), robot state that the contract does not hold",
}


def market_params(config) -> MarketParams:
    """The contract's parameters for an experiment's payment section (``config.payment``).

    The contract implements the built-in ``delayed``, ``outlier``, ``outlier_distinct`` and
    ``capped_outlier`` schemes; another scheme (``consensus_slash``, a plugin's), or a fuel cost (money the
    simulation burns, which the contract has no notion of), cannot be replayed on chain. The simulation's
    stake expiry 0 (never) becomes, in the replay, one longer than the replay itself (the contract always
    has one).
    """
    payment = config.payment
    if payment.scheme in OFF_CHAIN:
        raise ChainError(OFF_CHAIN[payment.scheme])
    if payment.scheme not in SCHEMES:
        raise ChainError(f"the contract implements the {', '.join(SCHEMES)} schemes, not {payment.scheme!r}")
    if config.robot.fuel_cost:
        raise ChainError("the contract has no fuel cost: replay a configuration with robot.fuel_cost = 0")
    params = config.payment_params()
    theta = params.get("theta", default_theta()) if payment.scheme != "delayed" else default_theta()
    return MarketParams.from_floats(payment.scheme, reward=payment.reward,
                                    information_share=payment.information_share, stake=payment.stake,
                                    theta_deg=theta, stake_expiry=int(getattr(payment, "stake_expiry", 0) or 0),
                                    cap=params.get("cap"))


def replay_result(result, *, rpc_url: str | None = None, backend: str | None = None,
                  progress=None) -> tuple[ReplayReport, list[BalanceRow]]:
    """Replay a simulation's events (``simulate(..., record_events=True)``) on a fresh market and
    compare every robot's on-chain balance with its final wealth in the simulation."""
    config = result.config
    report = replay_on_chain(result.events, robots=config.swarm.robots, params=market_params(config),
                             initial_wealth=config.payment.initial_wealth, rpc_url=rpc_url, backend=backend,
                             seed=result.seed, progress=progress)
    wealth = result.robots.sort_values("robot")["wealth"].to_numpy()
    return report, report.compare(wealth)


def _count_rounding(bound: list[int], buyer: int, sellers: list[int]) -> None:
    """A deposit with n records floors n shares: each seller may lose under a unit per share it
    receives, and the buyer keeps the dust, under a unit per share."""
    bound[buyer] += len(sellers)
    for s in sellers:
        bound[s] += 1
