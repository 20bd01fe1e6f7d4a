"""Where the contract runs: one small interface, three chains behind it.

``ChainMarket`` (market.py) never talks to a node itself; it hands ABI-encoded calldata to a backend:

- ``Web3Backend`` over web3.py: the in-process py-evm (``EthereumTesterProvider``, the reference EVM,
  nothing to install or run) or any JSON-RPC node (``--rpc``; its first unlocked account pays the
  robots' gas). Every transaction is signed by its sender's own key, as on a real swarm; every block
  holds one transaction (automining), so ``advance_to`` can only move the chain forward.
- ``RevmBackend`` over pyrevm (revm, the Rust EVM, through its Python bindings): hundreds of times
  faster than py-evm, with blocks set explicitly (``advance_to(n)`` makes every following transaction
  land in block ``n`` until the next call), which is what the replay of a simulation needs: one block
  per simulated step, however many transactions the step holds. Transactions execute as their sender
  without an Ethereum transaction signature (the buyers' EIP-712 signatures inside the light contracts
  are still checked by the contract itself). **Its gas is not a chain's**: pyrevm 0.3.7 keeps one
  journal for the life of the EVM (its ``commit`` does not finalise it and storage it inserts goes
  into the journal too), so accounts and storage slots stay warm from one transaction to the next and
  each slot's "original value" is the one it had when first loaded. A reveal costs about 20 000 gas
  less than on py-evm and a large settlement a third of it. ``cold_storage`` says which backends
  charge gas as a chain does; gas figures (docs/gas.md, the declared bound) come from py-evm.

Both raise ``ContractRevert`` (with the custom error's name and arguments) through
``market.decode_revert``, and both return a ``Receipt`` whose logs are raw (address, topics, data).
"""
from __future__ import annotations

import re
from typing import NamedTuple

from eth_utils import to_checksum_address

from .errors import ChainError

#: Gas money given to every robot and to the market account (wei); far above what a demo spends.
GAS_ALLOWANCE_WEI = 10**20
#: Block gas limit of the revm chain (Ethereum mainnet's in 2024).
REVM_BLOCK_GAS = 30_000_000
REVM_CHAIN_ID = 131_277_322_940_537  # eth-tester's, so that both in-process chains sign alike


class Log(NamedTuple):
    """One raw event log."""

    address: str
    topics: list[bytes]
    data: bytes


class Receipt(NamedTuple):
    """What a mined transaction cost, where it landed, and what it logged."""

    gas_used: int
    block_number: int
    logs: list[Log]


class RevertedCall(ChainError):
    """A call or transaction reverted with ``data`` (the revert bytes; decoded by the market)."""

    def __init__(self, data: bytes):
        self.data = data
        super().__init__(f"reverted with 0x{data.hex()}")


class Web3Backend:
    """py-evm in process (``rpc_url=None``) or a JSON-RPC node, through web3.py."""

    name = "py-evm"
    #: gas as a chain charges it: every transaction starts with cold accounts and storage (EIP-2929)
    cold_storage = True

    def __init__(self, rpc_url: str | None = None):
        from web3 import Web3

        if rpc_url is None:
            from web3 import EthereumTesterProvider

            self.w3 = Web3(EthereumTesterProvider())
        else:
            self.w3 = Web3(Web3.HTTPProvider(rpc_url))
            if not self.w3.is_connected():
                raise ChainError(f"no JSON-RPC node answers at {rpc_url}")
            self.name = rpc_url
        self.chain_id = self.w3.eth.chain_id
        self.gas_limit = self.w3.eth.get_block("latest")["gasLimit"]

    @property
    def block_number(self) -> int:
        """The block the next transaction lands in."""
        return self.w3.eth.block_number + 1

    def advance_to(self, block: int) -> None:
        """Mine empty blocks until the next transaction lands in ``block`` or later."""
        missing = block - self.block_number
        if missing > 0:
            tester = getattr(self.w3.provider, "ethereum_tester", None)
            if tester is not None:
                tester.mine_blocks(missing)
            else:
                for _ in range(missing):
                    self.w3.provider.make_request("evm_mine", [])

    def fund(self, addresses: list[str], amount: int = GAS_ALLOWANCE_WEI) -> None:
        accounts = self.w3.eth.accounts
        if not accounts:
            raise ChainError("the node has no unlocked account to pay the robots' gas")
        hashes = [self.w3.eth.send_transaction({"from": accounts[0], "to": a, "value": amount}) for a in addresses]
        for h in hashes:
            self.w3.eth.wait_for_transaction_receipt(h)

    def call(self, sender: str, to: str, data: bytes, static: bool = False) -> bytes:
        from .market import revert_data

        try:
            return bytes(self.w3.eth.call({"from": sender, "to": to, "data": data, "gas": self.gas_limit}, "pending"))
        except Exception as exc:  # noqa: BLE001 - anything that is not a revert is re-raised as it came
            raw = revert_data(exc)
            if raw is None:
                raise
            raise RevertedCall(raw) from exc

    def transact(self, sender, to: str | None, data: bytes) -> Receipt:
        """Dry-run (which yields the revert data on every backend), then sign with ``sender``'s key
        and send with the block's gas limit: an estimate would cost a dozen executions on py-evm."""
        if to is not None:
            self.call(sender.address, to, data)
        tx = {"from": sender.address, "data": data, "chainId": self.chain_id, "gas": self.gas_limit,
              "nonce": self.w3.eth.get_transaction_count(sender.address, "pending"),
              "gasPrice": self.w3.eth.gas_price}
        if to is not None:
            tx["to"] = to
        signed = sender.sign_transaction(tx)
        receipt = self.w3.eth.wait_for_transaction_receipt(self.w3.eth.send_raw_transaction(signed.raw_transaction))
        if receipt.status != 1:
            raise ChainError(f"transaction {receipt.transactionHash.hex()} failed after a successful dry run")
        self.last_address = receipt.contractAddress
        logs = [Log(lg.address, [bytes(t) for t in lg.topics], bytes(lg.data)) for lg in receipt.logs]
        return Receipt(receipt.gasUsed, receipt.blockNumber, logs)

    def deploy(self, sender, code: bytes) -> tuple[str, Receipt]:
        from .market import revert_data

        try:
            self.w3.eth.call({"from": sender.address, "data": code, "gas": self.gas_limit}, "pending")
        except Exception as exc:  # noqa: BLE001
            raw = revert_data(exc)
            if raw is None:
                raise
            raise RevertedCall(raw) from exc
        receipt = self.transact(sender, None, code)
        return to_checksum_address(self.last_address), receipt

    def snapshot(self):
        return self.w3.provider.ethereum_tester.take_snapshot()

    def revert(self, snapshot) -> None:
        self.w3.provider.ethereum_tester.revert_to_snapshot(snapshot)


_REVERT_OUTPUT = re.compile(r"output: 0x([0-9a-fA-F]*)")


class RevmBackend:
    """revm through pyrevm: an in-process chain whose blocks the caller sets. Its state and results
    are exact; its gas is not (storage stays warm across transactions, see the module docstring)."""

    name = "revm"
    cold_storage = False

    def __init__(self):
        try:
            import pyrevm
        except ImportError as exc:  # pragma: no cover - the chain extra installs it
            raise ChainError("the revm backend needs pyrevm (pip install 'infomarket[chain]')") from exc
        self._pyrevm = pyrevm
        self.chain_id = REVM_CHAIN_ID
        self.gas_limit = REVM_BLOCK_GAS
        env = pyrevm.Env(cfg=pyrevm.CfgEnv(chain_id=REVM_CHAIN_ID),
                         block=pyrevm.BlockEnv(number=1, timestamp=1, gas_limit=REVM_BLOCK_GAS))
        self.evm = pyrevm.EVM(env=env, spec_id="CANCUN", gas_limit=REVM_BLOCK_GAS)
        self._block = 1

    @property
    def block_number(self) -> int:
        return self._block

    def advance_to(self, block: int) -> None:
        if block > self._block:
            self._block = block
            self.evm.set_block_env(self._pyrevm.BlockEnv(number=block, timestamp=block,
                                                         gas_limit=REVM_BLOCK_GAS))

    def fund(self, addresses: list[str], amount: int = GAS_ALLOWANCE_WEI) -> None:
        for a in addresses:
            self.evm.set_balance(a, amount)

    def call(self, sender: str, to: str, data: bytes, static: bool = False) -> bytes:
        """Execute without keeping any change: a view runs static; a dry run of a transaction runs
        inside a checkpoint that is reverted."""
        if static:
            return bytes(self._run(lambda: self.evm.message_call(sender, to, data, gas=self.gas_limit,
                                                                 is_static=True)))
        checkpoint = self.evm.snapshot()
        try:
            return bytes(self._run(lambda: self.evm.message_call(sender, to, data, gas=self.gas_limit)))
        finally:
            self.evm.revert(checkpoint)

    def transact(self, sender, to: str, data: bytes) -> Receipt:
        """Execute and keep: a reverted call changes nothing, so no dry run is needed."""
        self._run(lambda: self.evm.message_call(sender.address, to, data, gas=self.gas_limit))
        return self._receipt()

    def deploy(self, sender, code: bytes) -> tuple[str, Receipt]:
        address = self._run(lambda: self.evm.deploy(sender.address, code, gas=self.gas_limit))
        return to_checksum_address(address), self._receipt()

    def snapshot(self) -> list:
        """A handle to the current state that ``revert`` can go back to any number of times (revm's
        checkpoints are single-use, so each revert takes a fresh one at the same point)."""
        return [self.evm.snapshot(), self._block]

    def revert(self, snapshot: list) -> None:
        checkpoint, block = snapshot
        self.evm.revert(checkpoint)
        snapshot[0] = self.evm.snapshot()
        self._block = 0
        self.advance_to(block)

    def _run(self, execute):
        try:
            return execute()
        except RuntimeError as exc:
            found = _REVERT_OUTPUT.search(str(exc))
            if found is None:
                raise ChainError(f"revm: {exc}") from exc
            raise RevertedCall(bytes.fromhex(found.group(1))) from exc

    def _receipt(self) -> Receipt:
        result = self.evm.result
        logs = [Log(to_checksum_address(lg.address), [bytes.fromhex(t.removeprefix("0x")) for t in lg.topics],
                    bytes(lg.data[1])) for lg in result.logs]
        return Receipt(result.gas_used, self._block, logs)


def make_backend(name: str | None = None, rpc_url: str | None = None):
    """``revm`` (the default: fast), ``py-evm`` (the reference), or the JSON-RPC node at ``rpc_url``."""
    if rpc_url is not None:
        return Web3Backend(rpc_url)
    if name in (None, "revm"):
        return RevmBackend()
    if name == "py-evm":
        return Web3Backend()
    raise ChainError(f"unknown chain backend {name!r}: choose revm or py-evm")
