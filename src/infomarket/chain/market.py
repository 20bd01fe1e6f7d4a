"""A deployed ``InformationMarket`` and the accounts that use it.

Every robot is an account with its own secp256k1 key and signs its own transactions locally, as it
would on a real swarm; the market node is one more account, the only one allowed to grant wealth and
buy items. The chain is either an in-process EVM (web3.py's ``EthereumTesterProvider`` over py-evm,
the default: nothing to install or run) or any JSON-RPC node (``rpc_url``), whose first unlocked
account pays the robots' gas (a development node such as anvil or ``geth --dev`` has one).

Refusals come back as ``ContractRevert`` with the custom error's name and decoded arguments, on both
backends: every transaction is dry-run first (``eth_call``), which surfaces the revert data before
anything is mined.
"""
from __future__ import annotations

import ast
import json
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cached_property
from importlib import resources
from typing import Any, NamedTuple

from eth_abi import decode as abi_decode
from eth_account import Account
from eth_account.signers.local import LocalAccount
from eth_utils import keccak, to_checksum_address
from web3 import Web3

from .errors import ChainError, ContractRevert
from .protocol import Domain, LightContract, Offer, PathInfo, accept_offer, sign_offer
from .units import share_to_wad, to_microdegrees, to_units

SCHEMES = {"delayed": 0, "outlier": 1}
#: Gas money given to every robot and to the market account (wei); far above what a demo spends.
GAS_ALLOWANCE_WEI = 10**20
#: Default cap on records per buyer: keeps the O(n^2) outlier weighting of ``buyItem`` inside a 30M
#: block (16.3M gas measured at 256 records; docs/gas.md has the curve up to 64).
DEFAULT_MAX_CONTRIBUTORS = 256


def load_artifact() -> dict:
    """ABI and bytecode compiled by tools/solc/compile.js and shipped inside the package."""
    text = resources.files(__package__).joinpath("artifacts/InformationMarket.json").read_text()
    return json.loads(text)


@dataclass(frozen=True)
class MarketParams:
    """The contract's constructor arguments, already in fixed point (see ``units``)."""

    scheme: str
    reward: int
    information_share: int
    stake: int
    theta: int
    max_contributors: int = DEFAULT_MAX_CONTRIBUTORS

    @classmethod
    def from_floats(cls, scheme: str, *, reward: float = 1.0, information_share: float = 0.5,
                    stake: float = 0.0, theta_deg: float = 30.0,
                    max_contributors: int = DEFAULT_MAX_CONTRIBUTORS) -> MarketParams:
        if scheme not in SCHEMES:
            raise ValueError(f"scheme must be one of {sorted(SCHEMES)}, not {scheme!r}")
        return cls(scheme, to_units(reward), share_to_wad(information_share), to_units(stake),
                   to_microdegrees(theta_deg), max_contributors)

    def constructor_args(self, market: str) -> tuple:
        return (market, SCHEMES[self.scheme], self.reward, self.information_share, self.stake,
                self.theta, self.max_contributors)


class TxResult(NamedTuple):
    """What a mined transaction cost and where it landed."""

    gas_used: int
    block_number: int
    receipt: Any


def derived_account(label: str, index: int, seed: int = 0) -> LocalAccount:
    """A deterministic account, so that a replay with the same seed uses the same addresses.

    For simulations only: anyone who knows the label and seed knows the key.
    """
    return Account.from_key(keccak(f"infomarket/{label}/{seed}/{index}".encode()))


def connect(rpc_url: str | None = None) -> Web3:
    """An in-process EVM, or the JSON-RPC node at ``rpc_url``."""
    if rpc_url is None:
        from web3 import EthereumTesterProvider

        return Web3(EthereumTesterProvider())
    w3 = Web3(Web3.HTTPProvider(rpc_url))
    if not w3.is_connected():
        raise ChainError(f"no JSON-RPC node answers at {rpc_url}")
    return w3


class ChainMarket:
    """One deployed market and the account of its market node."""

    def __init__(self, w3: Web3, address: str, market: LocalAccount, abi: list | None = None):
        self.w3 = w3
        self.market = market
        self.contract = w3.eth.contract(address=to_checksum_address(address), abi=abi or load_artifact()["abi"])
        self._errors = _error_table(self.contract.abi)
        self._chain_id = w3.eth.chain_id
        self._gas_limit = w3.eth.get_block("latest")["gasLimit"]

    @classmethod
    def deploy(cls, params: MarketParams, *, w3: Web3 | None = None, market: LocalAccount | None = None,
               artifact: dict | None = None, seed: int = 0) -> ChainMarket:
        """Deploy a fresh market from ``market`` (funded with gas money first)."""
        w3 = w3 or connect()
        artifact = artifact or load_artifact()
        market = market or derived_account("market", 0, seed)
        fund_gas(w3, [market.address])
        factory = w3.eth.contract(abi=artifact["abi"], bytecode=artifact["bytecode"])
        with _refusals_decoded(_error_table(artifact["abi"])):
            tx = factory.constructor(*params.constructor_args(market.address)).build_transaction(
                {"from": market.address, "nonce": w3.eth.get_transaction_count(market.address, "pending"),
                 "chainId": w3.eth.chain_id})
        receipt = _send(w3, market, tx)
        return cls(w3, receipt.contractAddress, market, artifact["abi"])

    # -- transactions -------------------------------------------------------------------------------

    def grant_wealth(self, robot: str, amount: int) -> TxResult:
        """Market mints ``amount`` units to ``robot`` (initial wealth)."""
        return self.transact(self.market, self.contract.functions.grantWealth(robot, amount))

    def buy_item(self, robot: str, sender: LocalAccount | None = None) -> TxResult:
        """Market buys ``robot``'s deposited item (``sender`` only to test who may call it)."""
        return self.transact(sender or self.market, self.contract.functions.buyItem(robot))

    def reveal(self, sender: LocalAccount, lc: LightContract, info: PathInfo) -> TxResult:
        """Submit a light contract and its path information (normally ``sender`` is the seller)."""
        return self.transact(sender, self.contract.functions.revealInformation(lc.as_abi(), info.as_abi()))

    def check_reveal(self, sender: LocalAccount, lc: LightContract, info: PathInfo) -> None:
        """Dry-run a reveal against the current state; raises ``ContractRevert`` if it would fail."""
        self._dry_run(sender, self.contract.functions.revealInformation(lc.as_abi(), info.as_abi()))

    def transact(self, sender: LocalAccount, fn) -> TxResult:
        """Sign ``fn`` with ``sender``'s own key and wait for it to be mined.

        The call is dry-run first (one EVM execution, which also yields the revert data on every
        backend), then sent with the block's gas limit as its limit: a gas estimate would cost a
        dozen executions on py-evm, and the limit does not change the gas used.
        """
        self._dry_run(sender, fn)
        # The nonce is asked for every time: several markets (and tests) may share one account.
        nonce = self.w3.eth.get_transaction_count(sender.address, "pending")
        tx = fn.build_transaction({"from": sender.address, "nonce": nonce, "chainId": self._chain_id,
                                   "gas": self._gas_limit})
        receipt = _send(self.w3, sender, tx)
        return TxResult(receipt.gasUsed, receipt.blockNumber, receipt)

    def _dry_run(self, sender: LocalAccount, fn) -> None:
        with _refusals_decoded(self._errors):
            fn.call({"from": sender.address, "gas": self._gas_limit}, block_identifier="pending")

    # -- the light-contract protocol, both sides ----------------------------------------------------

    @cached_property
    def domain(self) -> Domain:
        """This market's EIP-712 domain, read from the contract itself (EIP-5267)."""
        _, name, version, chain_id, contract, _, _ = self.contract.functions.eip712Domain().call()
        return Domain(chain_id, contract, name, version)

    def light_contract(self, seller: LocalAccount, buyer: LocalAccount, site: int, age: int, info: PathInfo,
                       seller_position: tuple[float, float] = (0.0, 0.0), blocks_valid: int = 8,
                       domain: Domain | None = None) -> LightContract:
        """Run steps 1-2 of the protocol: the seller offers (valid ``blocks_valid`` blocks from now),
        the buyer verifies and accepts."""
        domain = domain or self.domain
        offer = Offer(seller.address, site, age, self.w3.eth.block_number + blocks_valid, info.digest())
        signature = sign_offer(seller.key, domain, offer)
        return accept_offer(buyer.key, domain, offer, signature, seller_position)

    # -- views --------------------------------------------------------------------------------------

    def balance_of(self, robot: str) -> int:
        return self.contract.functions.balanceOf(robot).call()

    def locked_stake(self, buyer: str) -> int:
        return self.contract.functions.lockedStake(buyer).call()

    def total_supply(self) -> int:
        return self.contract.functions.totalSupply().call()

    def contributors(self, buyer: str) -> list[tuple[str, int, int]]:
        return [tuple(x) for x in self.contract.functions.contributors(buyer).call()]

    # -- internals ----------------------------------------------------------------------------------


def fund_gas(w3: Web3, addresses: list[str], amount: int = GAS_ALLOWANCE_WEI) -> None:
    """Give each address gas money from the node's first unlocked account."""
    accounts = w3.eth.accounts
    if not accounts:
        raise ChainError("the node has no unlocked account to pay the robots' gas")
    hashes = [w3.eth.send_transaction({"from": accounts[0], "to": a, "value": amount}) for a in addresses]
    for h in hashes:
        w3.eth.wait_for_transaction_receipt(h)


def _send(w3: Web3, sender: LocalAccount, tx: dict):
    signed = sender.sign_transaction(tx)
    receipt = w3.eth.wait_for_transaction_receipt(w3.eth.send_raw_transaction(signed.raw_transaction))
    if receipt.status != 1:
        raise ChainError(f"transaction {receipt.transactionHash.hex()} failed after a successful estimate")
    return receipt


@contextmanager
def _refusals_decoded(errors: dict):
    """Turn a contract refusal raised inside the block into ``ContractRevert``; let the rest through."""
    try:
        yield
    except Exception as exc:  # noqa: BLE001 - anything that is not a refusal is re-raised as it came
        revert = decode_revert(errors, exc)
        if revert is None:
            raise
        raise revert from exc


def decode_revert(errors: dict, exc: Exception) -> ContractRevert | None:
    """The contract refusal inside ``exc`` (an error of ``errors``, see ``_error_table``), if any."""
    data = _revert_data(exc)
    if data is None or len(data) < 4 or data[:4] not in errors:
        return None
    name, names, types = errors[data[:4]]
    values = [to_checksum_address(v) if t == "address" else v for t, v in zip(types, abi_decode(types, data[4:]))]
    return ContractRevert(name, dict(zip(names, values)), data)


def _error_table(abi: list) -> dict[bytes, tuple[str, list[str], list[str]]]:
    """Selector -> (name, argument names, argument types) for the ABI's errors and Solidity's own."""
    entries = [e for e in abi if e["type"] == "error"]
    entries += [{"name": "Error", "inputs": [{"name": "message", "type": "string"}]},
                {"name": "Panic", "inputs": [{"name": "code", "type": "uint256"}]}]
    table = {}
    for e in entries:
        types = [i["type"] for i in e["inputs"]]
        table[keccak(text=f"{e['name']}({','.join(types)})")[:4]] = (e["name"], [i["name"] for i in e["inputs"]], types)
    return table


def _revert_data(exc: BaseException) -> bytes | None:
    """The raw revert bytes, wherever the backend put them.

    A JSON-RPC node's answer reaches us as web3's ``ContractCustomError``/``ContractLogicError`` with a
    hex ``data``. eth-tester raises ``TransactionFailed`` whose message is the bytes' repr, and web3
    re-raises it with a message of its own (sometimes a string it guessed out of the bytes), so the
    repr is looked for along the exception's cause/context chain.
    """
    pending: list[BaseException | None] = [exc]
    seen: set[int] = set()
    while pending:
        e = pending.pop(0)
        if e is None or id(e) in seen:
            continue
        seen.add(id(e))
        data = getattr(e, "data", None)
        if isinstance(data, str) and data.startswith("0x"):
            return bytes.fromhex(data[2:])
        first = e.args[0] if e.args else None
        if isinstance(first, str):
            first = _bytes_literal(first.removeprefix("execution reverted: "))
        if isinstance(first, bytes):
            return first
        if isinstance(first, BaseException):
            pending.append(first)
        pending += [e.__cause__, e.__context__]
    return None


def _bytes_literal(text: str) -> bytes | None:
    if text[:2] not in ("b'", 'b"'):
        return None
    try:
        value = ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return None
    return value if isinstance(value, bytes) else None
