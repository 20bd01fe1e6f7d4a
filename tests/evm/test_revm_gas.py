"""revm charges gas as a chain does: the same transactions cost the same gas on revm as on py-evm.

py-evm (through web3.py's EthereumTesterProvider) is the reference: every transaction starts with
cold accounts and storage (EIP-2929) and each slot's original value (EIP-2200) is the one it had
before the transaction. Each test deploys one market on each backend from the same account and
drives both in lockstep: the same calldata (every light contract signed once and sent to both, the
signatures are not deterministic), landing in the same block (revm's blocks are set to py-evm's
before each transaction), and compares the gas of every transaction, which must be equal, and the
state (balances, locked stakes, pending settlements), which must be identical. The revm backend that
kept storage warm across transactions fails these tests: a reveal cost it about 20 000 gas less.
"""
from __future__ import annotations

import math

import pytest
from eth_abi import encode as abi_encode
from eth_utils.abi import get_abi_input_types

from infomarket.evm.errors import ContractRevert
from infomarket.evm.market import ChainMarket, MarketParams, connect, derived_account, load_artifact
from infomarket.evm.protocol import FOOD, NEST, PathInfo
from infomarket.evm.units import to_units

SELLERS = 6


class Twin:
    """One market on py-evm and one on revm, deployed by the same fresh account, driven in lockstep."""

    def __init__(self, label: str, scheme: str, stake: float, wealth: list[float], **options):
        self.ref, self.fast = connect(backend="py-evm"), connect(backend="revm")
        owner = derived_account(f"twin-market-{label}", 0)
        self.sellers = [derived_account(f"twin-seller-{label}", i) for i in range(SELLERS)]
        self.buyers = [derived_account(f"twin-buyer-{label}", i) for i in range(2)]
        self.outsider = derived_account(f"twin-outsider-{label}", 0)  # never registered
        everyone = [owner] + self.sellers + self.buyers + [self.outsider]
        for backend in (self.ref, self.fast):
            backend.fund([a.address for a in everyone])
        artifact = load_artifact()
        ctor = next(e for e in artifact["abi"] if e["type"] == "constructor")
        # the owner is every role's one key: one approval registers a robot
        params = MarketParams.from_floats(scheme, stake=stake, registrars=1, registrar_threshold=1, **options)
        code = bytes.fromhex(artifact["bytecode"].removeprefix("0x")) + abi_encode(
            get_abi_input_types(ctor), list(params.constructor_args(owner.address, [owner.address], owner.address)))
        #: (what, gas on py-evm, gas on revm) of every transaction, in order
        self.gas: list[tuple[str, int, int]] = []
        self._align()
        (ref_address, ref_receipt), (fast_address, fast_receipt) = (b.deploy(owner, code)
                                                                    for b in (self.ref, self.fast))
        assert ref_address == fast_address  # same deployer, same nonce: the light contracts sign alike
        self.gas.append(("deploy", ref_receipt.gas_used, fast_receipt.gas_used))
        self.owner = owner
        self.markets = [ChainMarket(b, ref_address, owner, artifact["abi"], registrars=[owner], nest=owner)
                        for b in (self.ref, self.fast)]
        for account, amount in zip(self.sellers + self.buyers, wealth):
            self.tx("grantWealth", None, account.address, to_units(amount) + params.registration_bond)

    def _align(self) -> None:
        self.fast.advance_to(self.ref.block_number)
        assert self.fast.block_number == self.ref.block_number

    def tx(self, fn: str, sender, *args, label: str | None = None):
        """Send ``fn(*args)`` on both chains in the same block; both succeed alike or refuse alike."""
        self._align()
        outcomes = []
        for market in self.markets:
            try:
                outcomes.append(market.transact(sender or market.market, fn, *args))
            except ContractRevert as refusal:
                outcomes.append(refusal)
        ref, fast = outcomes
        if isinstance(ref, ContractRevert) or isinstance(fast, ContractRevert):
            assert (type(ref), getattr(ref, "name", None), getattr(ref, "args_by_name", None)) == \
                   (type(fast), getattr(fast, "name", None), getattr(fast, "args_by_name", None))
            return ref
        assert ref.events == fast.events
        self.gas.append((label or fn, ref.gas_used, fast.gas_used))
        return ref

    def sell(self, seller, buyer, age: int, direction_deg: float = 10.0, site: int = FOOD):
        """A light contract signed once (on py-evm's domain, the same contract address) and revealed on both."""
        angle = math.radians(direction_deg)
        info = PathInfo.from_floats(30 * math.cos(angle), 30 * math.sin(angle))
        self._align()
        lc = self.markets[0].light_contract(seller, buyer, site, age, info, (0.5, -0.5))
        return self.tx("revealInformation", seller, lc.as_abi(), info.as_abi(), label="reveal")

    def deposit(self, buyer, label: str) -> None:
        """buyItem, then settle until the round trip is settled (on py-evm's word, checked on revm's)."""
        self.tx("buyItem", None, buyer.address, self.evidence(buyer), label=f"buyItem {label}")
        while self.markets[0].pending_settlement(buyer.address)[0]:
            self.tx("settle", None, buyer.address, 48, label=f"settle {label}")

    def evidence(self, robot) -> tuple:
        """The deposit's signatures (robot and nest), made once and sent to both chains."""
        return self.markets[0].deposit_evidence(robot, self.owner, self.markets[0].round_trip(robot.address))

    def advance(self, blocks: int) -> None:
        self.ref.advance_to(self.ref.block_number + blocks)
        self._align()

    def assert_same_state(self) -> None:
        everyone = [a.address for a in self.sellers + self.buyers]
        ref, fast = ([(m.balance_of(a), m.locked_stake(a), m.pending_settlement(a)) for a in everyone]
                     + [m.total_supply()] for m in self.markets)
        assert fast == ref

    def assert_same_gas(self) -> None:
        differ = [(what, ref, fast) for what, ref, fast in self.gas if ref != fast]
        assert not differ, f"{len(differ)} of {len(self.gas)} transactions cost other gas on revm: {differ[:8]}"


SCHEMES = [("delayed", 0.0), ("outlier", 0.0), ("outlier", 0.04), ("outlier_distinct", 0.04)]


@pytest.mark.parametrize(("scheme", "stake"), SCHEMES, ids=[f"{s}-{k}" for s, k in SCHEMES])
def test_every_kind_of_transaction_costs_the_same_gas_on_revm_as_on_py_evm(scheme, stake):
    """Grants (and a grant of nothing, which only registers), reveals of both sites and of outliers,
    refused reveals, and deposits of 1, 3 and 12 records (buyItem and settle calls of 8 units of work),
    twice per buyer so that later round trips reuse the settled slots."""
    twin = Twin(f"{scheme}-{stake}", scheme, stake, [1.0] * (SELLERS - 1) + [0.0, 1.0, 0.0], settle_batch=8)
    poor, (buyer, other) = twin.sellers[-1], twin.buyers
    age = 0
    for _trip in range(2):
        for m, who in ((1, buyer), (3, other), (12, buyer)):
            for k in range(m):
                direction = 100.0 if k == 2 else 10.0 + k  # one outlier in the larger trips
                twin.sell(twin.sellers[k % (SELLERS - 1)], who, age, direction, NEST if k % 4 == 3 else FOOD)
                age += 1
            twin.assert_same_state()  # views between transactions must leave nothing warm on revm
            twin.deposit(who, f"m={m}")
        # refused reveals change nothing and warm nothing: the next reveal costs what it costs on py-evm
        outsider = twin.sell(twin.outsider, buyer, age)
        assert isinstance(outsider, ContractRevert) and outsider.name == "InfoMarketUnregistered"
        refused = twin.sell(poor, buyer, age + 1)
        if stake:
            assert isinstance(refused, ContractRevert) and refused.name == "InfoMarketInsufficientStake"
        twin.sell(twin.sellers[0], buyer, age + 2)
        twin.deposit(buyer, "after refusals")
        age += 3
    twin.assert_same_state()
    twin.assert_same_gas()
    kinds = {what.split()[0] for what, *_ in twin.gas}
    assert kinds == {"deploy", "grantWealth", "reveal", "buyItem", "settle"}


def test_a_large_round_trip_settles_at_the_same_gas_on_revm():
    """A round trip of 120 records, every pair similar (the weighing's worst case): buyItem and every
    settle call load all live records; their gas grows with the cold loads, which revm must charge."""
    twin = Twin("large", "outlier_distinct", 0.04, [100.0] * SELLERS + [0.0, 0.0])
    buyer = twin.buyers[0]
    for k in range(120):
        twin.sell(twin.sellers[k % SELLERS], buyer, k, 5.0 + (k % 7))
    twin.deposit(buyer, "m=120")
    twin.assert_same_state()
    twin.assert_same_gas()
    settles = [fast for what, _, fast in twin.gas if what.startswith(("buyItem", "settle"))]
    assert len(settles) > 3 and max(settles) > 1_000_000


def test_expired_stakes_and_a_missed_settlement_deadline_refund_at_the_same_gas_on_revm():
    """refundExpired after the stake expiry (it closes the round trip and weighs it, settle finishes it),
    and settle calls after the settlement deadline, in small batches."""
    twin = Twin("refunds", "outlier", 0.04, [1.0] * SELLERS + [0.0, 0.0], stake_expiry=4, settle_batch=2,
                settlement_deadline=3)
    buyer, other = twin.buyers
    for k in range(3):
        twin.sell(twin.sellers[k], buyer, k)
    twin.advance(6)
    twin.tx("refundExpired", None, buyer.address, 2, label="refundExpired")
    while twin.markets[0].pending_settlement(buyer.address)[0]:
        twin.tx("settle", None, buyer.address, 2, label="settle an expired round trip")
    for k in range(4):
        twin.sell(twin.sellers[k], other, 10 + k)
    twin.tx("buyItem", None, other.address, twin.evidence(other), label="buyItem")
    twin.advance(3)
    while twin.markets[0].pending_settlement(other.address)[0]:
        twin.tx("settle", None, other.address, 2, label="settle after the deadline")
    twin.assert_same_state()
    twin.assert_same_gas()
    assert [what for what, *_ in twin.gas].count("settle after the deadline") >= 2
    assert twin.markets[1].locked_stake(buyer.address) == twin.markets[1].locked_stake(other.address) == 0


def test_reads_and_refusals_leave_no_account_or_slot_warm_on_revm():
    """Between transactions revm's journal holds no account but the block's coinbase (warm for every
    transaction since EIP-3651), whatever was read or refused."""
    twin = Twin("journal", "outlier", 0.04, [1.0] * (SELLERS - 1) + [0.0, 0.0, 0.0])
    twin.sell(twin.sellers[0], twin.buyers[0], 0)
    twin.sell(twin.sellers[-1], twin.buyers[0], 1)  # refused: no stake
    twin.assert_same_state()
    coinbase = "0x" + "00" * 20
    assert set(twin.fast.evm.journal_state) <= {coinbase}
    assert twin.fast.evm.journal_depth == 0


@pytest.mark.parametrize("backend", ["py-evm", "revm"])
def test_transient_storage_does_not_outlive_its_transaction(backend):
    """EIP-1153: transient storage is cleared after every transaction. A contract that logs its
    transient slot 0 and then sets it to 1 logs 0 every time (the market's contract uses none; pyrevm
    never clears it by itself, the checkpoint each transaction runs in undoes it)."""
    runtime = bytes.fromhex("60005c600052" "600160005d" "60206000a000")  # log0(tload(0)); tstore(0, 1)
    size = len(runtime)  # init code: mstore(0, push<size>(runtime)); return(32 - size, size)
    init = bytes([0x60 + size - 1]) + runtime + bytes.fromhex(f"60005260{size:02x}60{32 - size:02x}f3")
    chain = connect(backend=backend)
    deployer = derived_account("transient", 0)
    chain.fund([deployer.address])
    address, _ = chain.deploy(deployer, init)
    logged = [chain.transact(deployer, address, b"").logs for _ in range(3)]
    assert [[int.from_bytes(lg.data, "big") for lg in logs] for logs in logged] == [[0], [0], [0]]


def test_an_exit_a_bond_withdrawal_and_a_revocation_cost_the_same_gas_on_revm():
    twin = Twin("bond", "outlier", 0.04, [1.0] * SELLERS + [0.0, 0.0], bond_delay=3)
    leaving, revoked = twin.sellers[:2]
    twin.tx("exit", leaving, label="exit")
    twin.advance(3)
    twin.tx("withdrawBond", None, leaving.address, label="withdrawBond")
    twin.tx("revokeRegistration", None, revoked.address, label="revokeRegistration")  # the one registrar
    twin.assert_same_state()
    twin.assert_same_gas()
    assert [what for what, *_ in twin.gas][-3:] == ["exit", "withdrawBond", "revokeRegistration"]
    assert twin.markets[1].total_supply() == twin.markets[0].total_supply()
