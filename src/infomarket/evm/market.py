"""A deployed ``InformationMarket`` and the accounts that use it.

Every robot is an account with its own secp256k1 key. The market node is one more account (admin,
depositor and pauser); registrars approve registrations, a nest acknowledges deposits (docs/chain.md,
"Trust model"); the client holds all their keys, as a simulation's single operator does. Where the
contract runs is a backend (backends.py): revm
in process (the default, fast), py-evm in process (the reference EVM), or a JSON-RPC node.
``ChainMarket`` only encodes calls with the contract's ABI, hands them to the backend and decodes what
comes back, so the same client and the same tests run on every backend.

Refusals come back as ``ContractRevert`` with the custom error's name and decoded arguments, on every
backend.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from functools import cached_property
from importlib import resources
from typing import Any, NamedTuple

from eth_abi import encode as abi_encode
from eth_account import Account
from eth_account.signers.local import LocalAccount
from eth_utils import keccak
from eth_utils.abi import get_abi_input_types

from ..errors import ConfigError
from ..payments import default_theta
from ..registry import get_payment
from .backends import Receipt, RevertedCall, make_backend
from .codec import Codec, Event
from .errors import ChainError
from .protocol import (Domain, LightContract, Offer, PathInfo, ProtocolError, accept_offer, checksum, sign_deposit,
                       sign_offer)
from .units import COS_SCALE, share_to_wad, to_units

#: The simulator's payment schemes the contract implements, by their number in its ``Scheme`` enum.
SCHEMES = {"delayed": 0, "outlier": 1, "outlier_distinct": 2, "capped_outlier": 3}
#: The contract's roles (docs/chain.md, "Trust model"), by name.
ROLES = {"admin": bytes(32), **{name: keccak(text=f"{name.upper()}_ROLE")
                                for name in ("registrar", "depositor", "nest", "pauser")}}
#: Most records one seller may sell one buyer per round trip: above what the paper's runs reach
#: (docs/chain.md), well below the round trip's bound, so that it takes ceil(512 / 96) = 6 sellers to
#: fill a round trip.
DEFAULT_MAX_RECORDS_PER_SELLER = 96
#: Most live records one round trip may hold (the contract's hard bound, at which the declared gas
#: bound is measured).
DEFAULT_MAX_RECORDS_PER_TRIP = 512
#: Most offers a buyer's client accepts (signs) per round trip, and per seller in it: 8 times the
#: contract's bounds, because an accepted offer whose seller cannot lock the stake never lands.
DEFAULT_MAX_ACCEPTANCES_PER_TRIP = 8 * DEFAULT_MAX_RECORDS_PER_TRIP
DEFAULT_MAX_ACCEPTANCES_PER_SELLER = 8 * DEFAULT_MAX_RECORDS_PER_SELLER
#: Furthest a light contract's last block may lie ahead of its reveal.
DEFAULT_MAX_VALIDITY = 256
#: Blocks after which an undeposited record's stake goes back to its seller (on by default; the
#: contract refuses 0): about 17 hours of 12-second blocks.
DEFAULT_STAKE_EXPIRY = 5_000
#: Blocks after a deposit from which unfinished weighing stops and the live records are paid equally.
DEFAULT_SETTLEMENT_DEADLINE = 1_000
#: Most initial wealth the registrars may grant one robot, 1e-9 units (1 000 tokens).
DEFAULT_MAX_GRANT = 1_000 * 10**9
#: Work units of one ``buyItem``/``settle``/``refundExpired`` call (the contract's maximum).
DEFAULT_SETTLE_BATCH = 48
SETTLE_BATCH = 48
#: The registration policy: registrar keys, approvals that register a robot, and how many robots one
#: registrar may approve per period of blocks (a swarm of 25 registers well within one period).
DEFAULT_REGISTRARS = 3
DEFAULT_REGISTRAR_THRESHOLD = 2
DEFAULT_REGISTRAR_QUOTA = 32
DEFAULT_REGISTRAR_PERIOD = 5_000
#: The bond every registration locks out of the robot's grant, 1e-9 units (one token: a robot's whole
#: initial wealth in the paper's runs), and the blocks between a robot's exit and the bond's return
#: (a registrar period: the registrars' window to revoke it, which burns the bond). docs/chain.md,
#: "Trust model", states what 8 bonded identities cost a cartel against what it takes.
DEFAULT_REGISTRATION_BOND = 10**9
DEFAULT_BOND_DELAY = 5_000
#: The settlement bounty per unit of work is the reward's share divided by this: the bounty of the
#: largest settlement (512 records, 7 680 units) is at most 15 % of the share.
SETTLE_BOUNTY_DIVISOR = 50_000
#: The most gas any one call of the contract may take, measured with cold storage at the largest round
#: trip (512 live records of 512 distinct sellers, every pair similar, every scheme), docs/gas.md.
DECLARED_MAX_TX_GAS = 6_000_000


def load_artifact() -> dict:
    """ABI and bytecode compiled by tools/solc/compile.js and shipped inside the package."""
    text = resources.files(__package__).joinpath("artifacts/InformationMarket.json").read_text()
    return json.loads(text)


def cos_theta(theta_deg: float) -> int:
    """cos(theta) in the contract's fixed point (1e-9), nearest."""
    if not 0.0 <= theta_deg <= 180.0:
        raise ConfigError(f"theta must be in [0, 180] degrees, not {theta_deg}")
    return round(math.cos(math.radians(theta_deg)) * COS_SCALE)


def record_cap(scheme: str, cap: float | None) -> int:
    """The contract's cap for ``scheme``: 0 unless ``capped_outlier``; there the rule's ``cap`` (its
    default when None) rounded up, which counts the same records (the rule counts a record while fewer
    than ``cap`` of its seller's came before it), and no more than any round trip can hold."""
    if scheme != "capped_outlier":
        if cap is not None:
            raise ConfigError(f"cap is a parameter of the capped_outlier scheme, not of {scheme!r}")
        return 0
    value = get_payment("capped_outlier").defaults["cap"] if cap is None else cap
    if not value >= 1:
        raise ConfigError(f"cap must be at least 1, not {value}")
    return DEFAULT_MAX_RECORDS_PER_TRIP if value > DEFAULT_MAX_RECORDS_PER_TRIP else math.ceil(value)


@dataclass(frozen=True)
class MarketParams:
    """The contract's constructor arguments, already in fixed point (see ``units``)."""

    scheme: str
    reward: int
    information_share: int
    stake: int
    cos_theta: int
    stake_expiry: int = DEFAULT_STAKE_EXPIRY
    max_records_per_seller: int = DEFAULT_MAX_RECORDS_PER_SELLER
    max_records_per_trip: int = DEFAULT_MAX_RECORDS_PER_TRIP
    max_validity: int = DEFAULT_MAX_VALIDITY
    settle_batch: int = DEFAULT_SETTLE_BATCH
    settlement_deadline: int = DEFAULT_SETTLEMENT_DEADLINE
    max_grant: int = DEFAULT_MAX_GRANT
    registrars: int = DEFAULT_REGISTRARS
    registrar_threshold: int = DEFAULT_REGISTRAR_THRESHOLD
    registrar_quota: int = DEFAULT_REGISTRAR_QUOTA
    registrar_period: int = DEFAULT_REGISTRAR_PERIOD
    #: per unit of settlement work, 1e-9 units; None: the share over ``SETTLE_BOUNTY_DIVISOR``
    settle_bounty: int | None = None
    registration_bond: int = DEFAULT_REGISTRATION_BOND
    bond_delay: int = DEFAULT_BOND_DELAY
    #: under ``capped_outlier``, most records per seller that count in a round trip; 0 otherwise
    cap: int = 0

    @property
    def bounty(self) -> int:
        """The settlement bounty per unit of work, 1e-9 units."""
        if self.settle_bounty is not None:
            return self.settle_bounty
        return self.reward * self.information_share // 10**18 // SETTLE_BOUNTY_DIVISOR

    @classmethod
    def from_floats(cls, scheme: str, *, reward: float = 1.0, information_share: float = 0.5,
                    stake: float = 0.0, theta_deg: float | None = None, stake_expiry: int = DEFAULT_STAKE_EXPIRY,
                    max_records_per_seller: int = DEFAULT_MAX_RECORDS_PER_SELLER,
                    max_records_per_trip: int = DEFAULT_MAX_RECORDS_PER_TRIP,
                    max_validity: int = DEFAULT_MAX_VALIDITY, settle_batch: int = DEFAULT_SETTLE_BATCH,
                    settlement_deadline: int = DEFAULT_SETTLEMENT_DEADLINE,
                    max_grant: float | None = None, cap: float | None = None, **policy) -> MarketParams:
        """``cap``: under ``capped_outlier`` (default: the rule's own), most records per seller that count."""
        if scheme not in SCHEMES:
            raise ConfigError(f"scheme must be one of {sorted(SCHEMES)}, not {scheme!r}")
        theta = default_theta() if theta_deg is None else theta_deg  # the outlier rule's own default
        grant = DEFAULT_MAX_GRANT if max_grant is None else to_units(max_grant)
        return cls(scheme, to_units(reward), share_to_wad(information_share), to_units(stake),
                   cos_theta(theta), stake_expiry, max_records_per_seller, max_records_per_trip, max_validity,
                   settle_batch, settlement_deadline, grant, **policy, cap=record_cap(scheme, cap))

    def constructor_args(self, market: str, registrars: list[str], nest: str) -> tuple:
        """The contract's constructor arguments, in its order, for these parameters and the given market,
        registrars and nest."""
        return (market, SCHEMES[self.scheme], self.reward, self.information_share, self.stake,
                self.cos_theta, self.stake_expiry, self.max_records_per_seller, self.max_records_per_trip,
                self.max_validity, self.settle_batch, self.settlement_deadline, self.max_grant, registrars,
                self.registrar_threshold, self.registrar_quota, self.registrar_period, nest, self.bounty,
                self.registration_bond, self.bond_delay, self.cap)


class TxResult(NamedTuple):
    """What a mined transaction cost, where it landed, and its decoded events."""

    gas_used: int
    block_number: int
    events: list[Event]

    def of(self, name: str) -> list[dict]:
        """The arguments of this transaction's ``name`` events, in order."""
        return [e.args for e in self.events if e.name == name]


def derived_account(label: str, index: int, seed: int = 0) -> LocalAccount:
    """A deterministic account, so that a replay with the same seed uses the same addresses.

    For simulations only: anyone who knows the label and seed knows the key.
    """
    return Account.from_key(keccak(f"infomarket/{label}/{seed}/{index}".encode()))


def connect(rpc_url: str | None = None, backend: str | None = None):
    """A chain: revm in process (default), ``backend="py-evm"``, or the JSON-RPC node at ``rpc_url``."""
    return make_backend(backend, rpc_url)


Robot = LocalAccount | str


class ChainMarket:
    """One deployed market, the keys of its market node, registrars and nest, and the robots' clients."""

    def __init__(self, backend, address: str, market: LocalAccount, abi: list | None = None, *,
                 registrars: list[LocalAccount] = (), threshold: int = 1, nest: LocalAccount | None = None,
                 bond: int = 0, max_acceptances_per_trip: int = DEFAULT_MAX_ACCEPTANCES_PER_TRIP,
                 max_acceptances_per_seller: int = DEFAULT_MAX_ACCEPTANCES_PER_SELLER):
        self.backend = backend
        self.market = market
        self.registrars = list(registrars) or [market]
        self.threshold = threshold
        #: the bond a registration locks (``grant_wealth`` grants it on top of the wealth it gives)
        self.bond = bond
        self.nest = nest or market
        self.address = checksum(address)
        self.codec = Codec(abi or load_artifact()["abi"])
        #: the buyers' clients: acceptances signed per (buyer, round trip) and per (buyer, seller, round
        #: trip), capped
        self.max_acceptances_per_trip = max_acceptances_per_trip
        self.max_acceptances_per_seller = max_acceptances_per_seller
        self._accepted: dict[str, tuple[int, int]] = {}
        self._accepted_from: dict[tuple[str, str], tuple[int, int]] = {}
        #: robots' keys, to sign their deposits (every account this client has seen)
        self._keys: dict[str, LocalAccount] = {}

    @classmethod
    def deploy(cls, params: MarketParams, *, backend=None, market: LocalAccount | None = None,
               artifact: dict | None = None, seed: int = 0) -> ChainMarket:
        """Deploy a fresh market from ``market``, with ``params.registrars`` registrar keys and a nest
        key derived from ``seed`` (all funded with gas money first)."""
        backend = backend or connect()
        artifact = artifact or load_artifact()
        market = market or derived_account("market", 0, seed)
        registrars = [derived_account("registrar", i, seed) for i in range(params.registrars)]
        nest = derived_account("nest", 0, seed)
        backend.fund([market.address, nest.address] + [r.address for r in registrars])
        codec = Codec(artifact["abi"])
        ctor = next(e for e in artifact["abi"] if e["type"] == "constructor")
        args = params.constructor_args(market.address, [r.address for r in registrars], nest.address)
        code = (bytes.fromhex(artifact["bytecode"].removeprefix("0x"))
                + abi_encode(get_abi_input_types(ctor), list(args)))
        try:
            address, _ = backend.deploy(market, code)
        except RevertedCall as exc:
            raise codec.refusal(exc.data) or exc from exc
        return cls(backend, address, market, artifact["abi"], registrars=registrars,
                   threshold=params.registrar_threshold, nest=nest, bond=params.registration_bond,
                   max_acceptances_per_seller=8 * params.max_records_per_seller)

    # -- transactions -------------------------------------------------------------------------------

    def grant_wealth(self, robot: Robot, amount: int) -> TxResult:
        """Register ``robot`` with ``amount`` units of initial (free) wealth: the first ``threshold``
        registrars approve a grant of ``amount`` plus the bond, which the registration locks; the last
        approval's result (which registers it) is returned."""
        address = self._remember(robot)
        grant = amount + self.bond
        results = [self.approve(registrar, address, grant) for registrar in self.registrars[:self.threshold]]
        return results[-1]

    def exit(self, robot: LocalAccount) -> TxResult:
        """``robot`` leaves the market; its bond comes back after the bond delay (``withdraw_bond``)."""
        return self.transact(robot, "exit")

    def withdraw_bond(self, robot: str, sender: LocalAccount | None = None) -> TxResult:
        """Send ``withdrawBond`` for ``robot`` (from ``sender``, default the market), returning its registration
        bond once its exit delay has passed."""
        return self.transact(sender or self.market, "withdrawBond", robot)

    def revoke(self, robot: str, registrars: list[LocalAccount] | None = None) -> TxResult:
        """The first ``threshold`` registrars (or ``registrars``) revoke ``robot``: its bond is burned."""
        results = [self.transact(r, "revokeRegistration", robot)
                   for r in (registrars if registrars is not None else self.registrars[:self.threshold])]
        return results[-1]

    def approve(self, registrar: LocalAccount, robot: str, amount: int) -> TxResult:
        """One registrar's approval of registering ``robot`` with ``amount``."""
        return self.transact(registrar, "grantWealth", robot, amount)

    def cancel_approval(self, registrar: LocalAccount, robot: str, amount: int | None = None) -> TxResult:
        """``registrar`` withdraws its standing approval of registering ``robot`` with ``amount``, or, with
        no amount, of revoking ``robot``."""
        if amount is None:
            return self.transact(registrar, "cancelRevocation", robot)
        return self.transact(registrar, "cancelApproval", robot, amount)

    def buy_item(self, robot: Robot, sender: LocalAccount | None = None, evidence: tuple | None = None) -> TxResult:
        """The depositor buys ``robot``'s deposited item, with the robot's signed round trip and the
        nest's acknowledgement, and settles what fits in one batch (``sender`` and ``evidence`` only to
        test who may call it and what it must carry)."""
        address = self._remember(robot)
        if evidence is None:
            evidence = self.deposit_evidence(self._key(address), self.nest, self.round_trip(address))
        return self.transact(sender or self.market, "buyItem", address, evidence)

    def deposit_evidence(self, robot: LocalAccount, nest: LocalAccount, trip: int) -> tuple:
        """``buyItem``'s evidence: ``robot``'s and ``nest``'s signatures over ``Deposit(robot, trip)``."""
        return (*sign_deposit(robot.key, self.domain, robot.address, trip),
                *sign_deposit(nest.key, self.domain, robot.address, trip))

    def _remember(self, robot: Robot) -> str:
        if isinstance(robot, str):
            return checksum(robot)
        self._keys[robot.address] = robot
        return robot.address

    def _key(self, address: str) -> LocalAccount:
        try:
            return self._keys[address]
        except KeyError:
            raise ChainError(f"no key for robot {address}: pass its account to sign its deposit") from None

    def settle(self, robot: str, max_records: int = SETTLE_BATCH, sender: LocalAccount | None = None) -> TxResult:
        """Continue ``robot``'s pending settlement (anyone may; the market by default)."""
        return self.transact(sender or self.market, "settle", robot, max_records)

    def deposit(self, robot: Robot, batch: int = SETTLE_BATCH) -> list[TxResult]:
        """``buyItem`` and as many ``settle`` calls as the round trip needs: a whole deposit."""
        address = self._remember(robot)
        results = [self.buy_item(address)]
        while self.pending_settlement(address)[0]:
            results.append(self.settle(address, batch))
        return results

    def grant_role(self, role: str, account: str, sender: LocalAccount | None = None) -> TxResult:
        """The admin gives ``role`` (a key of ``ROLES``) to ``account``."""
        return self.transact(sender or self.market, "grantRole", ROLES[role], account)

    def revoke_role(self, role: str, account: str, sender: LocalAccount | None = None) -> TxResult:
        """The admin takes ``role`` from ``account``."""
        return self.transact(sender or self.market, "revokeRole", ROLES[role], account)

    def set_paused(self, paused: bool, sender: LocalAccount | None = None) -> TxResult:
        """A pauser stops or resumes registrations, reveals and deposits."""
        return self.transact(sender or self.market, "setPaused", paused)

    def refund_expired(self, buyer: str, max_records: int = 2**32, sender: LocalAccount | None = None) -> TxResult:
        """Close ``buyer``'s expired round trip and settle it as a deposit would, for at most ``max_records``
        units of work (anyone may; ``expire`` finishes it). Nothing happens when it has not expired."""
        return self.transact(sender or self.market, "refundExpired", buyer, max_records)

    def expire(self, buyer: str, batch: int = SETTLE_BATCH, sender: LocalAccount | None = None) -> list[TxResult]:
        """``refundExpired`` and as many ``settle`` calls as the expired round trip needs (anyone may)."""
        results = [self.refund_expired(buyer, batch, sender=sender)]
        while self.pending_settlement(buyer)[0]:
            results.append(self.settle(buyer, batch, sender=sender))
        return results

    def reveal(self, sender: LocalAccount, lc: LightContract, info: PathInfo) -> TxResult:
        """Submit a light contract and its path information (normally ``sender`` is the seller)."""
        return self.transact(sender, "revealInformation", lc.as_abi(), info.as_abi())

    def check_reveal(self, sender: LocalAccount, lc: LightContract, info: PathInfo) -> None:
        """Dry-run a reveal against the current state; raises ``ContractRevert`` if it would fail."""
        self._call(sender.address, "revealInformation", lc.as_abi(), info.as_abi(), static=False)

    def transact(self, sender: LocalAccount, fn: str, *args) -> TxResult:
        """Send ``fn(*args)`` from ``sender`` and wait for it to be mined."""
        try:
            receipt = self.backend.transact(sender, self.address, self.codec.calldata(fn, args))
        except RevertedCall as exc:
            raise self.codec.refusal(exc.data) or exc from exc
        return self._result(receipt)

    def _call(self, sender: str, fn: str, *args, static: bool = True) -> Any:
        try:
            out = self.backend.call(sender, self.address, self.codec.calldata(fn, args), static=static)
        except RevertedCall as exc:
            raise self.codec.refusal(exc.data) or exc from exc
        return self.codec.result(fn, out)

    def _result(self, receipt: Receipt) -> TxResult:
        events = [self.codec.decode_event(lg.topics, lg.data) for lg in receipt.logs
                  if checksum(lg.address) == self.address]
        return TxResult(receipt.gas_used, receipt.block_number, [e for e in events if e is not None])

    # -- the light-contract protocol, both sides ----------------------------------------------------

    @cached_property
    def domain(self) -> Domain:
        """This market's EIP-712 domain, read from the contract itself (EIP-5267)."""
        _, name, version, chain_id, contract, _, _ = self._call(self.market.address, "eip712Domain")
        return Domain(chain_id, checksum(contract), name, version)

    def light_contract(self, seller: LocalAccount, buyer: LocalAccount, site: int, age: int, info: PathInfo,
                       seller_position: tuple[float, float], blocks_valid: int = 8,
                       domain: Domain | None = None, trip: int | None = None) -> LightContract:
        """Run steps 1-2 of the protocol: the seller offers (valid for ``blocks_valid`` blocks, the
        block the next transaction lands in being the first), the buyer verifies and accepts for its
        open round trip (``trip``, read from the contract when not given).

        ``seller_position`` (the seller's position in the buyer's frame, as the buyer senses it) has no
        default: the weight of the sale is computed from the vector minus this position, so a client
        that left it out would weigh the purchased vector instead. The buyer's client signs at most
        ``max_acceptances_per_trip`` acceptances per round trip, and ``max_acceptances_per_seller`` per
        seller in it (``ProtocolError`` beyond)."""
        if seller_position is None or len(seller_position) != 2:
            raise ProtocolError("seller_position (the seller's position in the buyer's frame) is required")
        domain = domain or self.domain
        trip = self.round_trip(buyer.address) if trip is None else trip
        seen_trip, count = self._accepted.get(buyer.address, (trip, 0))
        count = count if seen_trip == trip else 0
        if count >= self.max_acceptances_per_trip:
            raise ProtocolError(f"buyer {buyer.address} already accepted {count} offers in round trip {trip}: "
                                f"its client accepts at most {self.max_acceptances_per_trip} per round trip")
        pair = (buyer.address, seller.address)
        seen_trip, from_seller = self._accepted_from.get(pair, (trip, 0))
        from_seller = from_seller if seen_trip == trip else 0
        if from_seller >= self.max_acceptances_per_seller:
            raise ProtocolError(f"buyer {buyer.address} already accepted {from_seller} offers of seller "
                                f"{seller.address} in round trip {trip}: its client accepts at most "
                                f"{self.max_acceptances_per_seller} per seller and round trip")
        self._keys[buyer.address], self._keys[seller.address] = buyer, seller
        offer = Offer(seller.address, site, age, self.backend.block_number - 1 + blocks_valid, info.digest())
        signature = sign_offer(seller.key, domain, offer)
        lc = accept_offer(buyer.key, domain, offer, signature, seller_position, trip)
        self._accepted[buyer.address] = (trip, count + 1)
        self._accepted_from[pair] = (trip, from_seller + 1)
        return lc

    # -- views --------------------------------------------------------------------------------------

    def view(self, fn: str, *args) -> Any:
        """Any view function, called by the market account."""
        return self._call(self.market.address, fn, *args)

    def has_role(self, role: str, account: str) -> bool:
        """Whether ``account`` holds the contract role ``role`` (a name of ``ROLES``)."""
        return self.view("hasRole", ROLES[role], account)

    def balance_of(self, robot: str) -> int:
        """``robot``'s token balance, in base units (``TOKEN_UNIT`` per token)."""
        return self.view("balanceOf", robot)

    def locked_stake(self, buyer: str) -> int:
        """The stake ``buyer`` has locked: its open pot plus what waits in escrow for settlement."""
        return self.view("lockedStake", buyer)

    def total_supply(self) -> int:
        """The token's total supply, in base units (conservation checks compare it with the balances)."""
        return self.view("totalSupply")

    def bond_of(self, robot: str) -> int:
        """The registration bond ``robot`` has posted (0 when it is not registered nor exiting)."""
        return self.view("bondOf", robot)

    def round_trip(self, buyer: str) -> int:
        """The buyer's open round trip (what its acceptances name)."""
        return self.view("roundTrip", buyer)

    def pending_settlement(self, robot: str) -> tuple[bool, int, int]:
        """Whether ``robot`` has a deposited round trip still to settle, its phase and the records remaining."""
        return tuple(self.view("pendingSettlement", robot))

    def contributors(self, buyer: str) -> list[tuple]:
        """The open round trip's records: (seller, openedAt, site, dx, dy, weight, prevGap)."""
        return [(checksum(r[0]),) + tuple(r[1:]) for r in self.view("contributors", buyer)]
