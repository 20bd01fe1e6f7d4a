"""The chains whose every transaction is signed by its sender's key and mined in a block of its own:
py-evm in process (the reference EVM, through eth-tester) and any JSON-RPC node (through web3.py).
``backends.make_backend`` picks one; revm, which executes as the sender without a signature, is in
backends.py."""
from __future__ import annotations

from typing import NamedTuple

from .errors import ChainError, revert_data
from .protocol import checksum
from .transactions import ETH_TESTER_CHAIN_ID, GAS_ALLOWANCE_WEI, Log, Receipt, RevertedCall


class _SignedChain:
    """What py-evm in process and a JSON-RPC node share: every transaction signed by its sender's key
    and sent with the block's gas limit (an estimate would cost a dozen executions on py-evm), mined in
    a block of its own.  A subclass gives the chain's own operations (the ``_``-methods)."""

    #: gas as a chain charges it: every transaction starts with cold accounts and storage (EIP-2929)
    cold_storage = True
    #: a node is sent a call of each transaction first, whose revert carries the error; where this is
    #: False, a failed transaction is undone (back to the block before it) and then called for it
    dry_run_first = True

    @property
    def block_number(self) -> int:
        """The block the next transaction lands in."""
        return self._latest() + 1

    def advance_to(self, block: int) -> None:
        """Mine empty blocks until the next transaction lands in ``block`` or later."""
        missing = block - self.block_number
        if missing > 0:
            self._mine(missing)

    def fund(self, addresses: list[str], amount: int = GAS_ALLOWANCE_WEI) -> None:
        """Top each address up to ``amount`` wei from the chain's first unlocked account (an address
        that holds as much already costs no transaction: a market redeployed on the same chain funds
        the same accounts again)."""
        payer = self._payer()
        for address in addresses:
            if (value := amount - self._balance(address)) > 0:
                self._send_value(payer, address, value)

    def call(self, sender: str, to: str | None, data: bytes, static: bool = False) -> bytes:
        """Execute without keeping anything (``to=None``: ``data`` is code to deploy); a revert is raised
        as ``RevertedCall`` with its data."""
        message = {"from": sender, "data": data, "gas": self.gas_limit}
        if to is not None:
            message["to"] = to
        return self._execute(message)

    def transact(self, sender, to: str | None, data: bytes) -> Receipt:
        """Send ``data`` to ``to`` (``None``: deploy it) from ``sender``; a refusal spends no block and no
        nonce, and is raised as ``RevertedCall``."""
        if self.dry_run_first:
            self.call(sender.address, to, data)
        before = None if self.dry_run_first else self._undo_point()
        tx = {"data": data, "chainId": self.chain_id, "gas": self.gas_limit, "nonce": self._nonce(sender.address),
              "gasPrice": self._gas_price()}
        if to is not None:
            tx["to"] = to
        mined = self._send_signed(sender.sign_transaction(tx).raw_transaction)
        if mined.status != 1:
            if before is not None:
                self._undo_to(before)
                self.call(sender.address, to, data)  # raises RevertedCall, with the data
            raise ChainError(f"transaction {mined.hash} failed where a call of it did not")
        self.last_address = mined.contract
        return mined.receipt

    def deploy(self, sender, code: bytes) -> tuple[str, Receipt]:
        receipt = self.transact(sender, None, code)
        return checksum(self.last_address), receipt

    def snapshot(self):
        """A handle to the current state for ``revert`` (a node lets one be reverted to once, dropping
        every later one)."""
        return self._snapshot()

    def revert(self, snapshot) -> None:
        self._revert(snapshot)


class _Mined(NamedTuple):
    """A mined transaction as a chain reports it."""

    hash: str
    status: int
    contract: str | None
    receipt: Receipt


def _raw(value: str | bytes) -> bytes:
    return bytes.fromhex(value[2:]) if isinstance(value, str) else bytes(value)


class PyEvmBackend(_SignedChain):
    """py-evm in process, through eth-tester's own interface (web3.py's provider around it cost nearly as
    much per call as py-evm's execution of a short one).  Each transaction runs once: one that fails is
    undone (the chain's head set back to the block before it), so it spends no block and no nonce, and
    then called for its error."""

    name = "py-evm"
    dry_run_first = False
    #: what eth-tester's chain is identified by, and the gas price web3.py's provider for it quoted
    CHAIN_ID = ETH_TESTER_CHAIN_ID
    GAS_PRICE = 10**9

    def __init__(self):
        from eth_tester import EthereumTester

        self.tester = EthereumTester()
        self.chain_id = self.CHAIN_ID
        self.gas_limit = self.tester.get_block_by_number("latest")["gas_limit"]

    def balance(self, address: str) -> int:
        """The ether balance of ``address`` in wei (what pays the gas)."""
        return self.tester.get_balance(address)

    def _latest(self) -> int:
        return self.tester.get_block_by_number("latest")["number"]

    def _mine(self, blocks: int) -> None:
        self.tester.mine_blocks(blocks)

    def _payer(self) -> str:
        return self.tester.get_accounts()[0]

    _balance = balance

    def _send_value(self, payer: str, to: str, value: int) -> None:
        self.tester.send_transaction({"from": payer, "to": to, "value": value, "gas": 21_000})

    def _nonce(self, address: str) -> int:
        return self.tester.get_nonce(address, "pending")

    def _gas_price(self) -> int:
        return self.GAS_PRICE

    def _execute(self, message: dict) -> bytes:
        from eth_tester.exceptions import TransactionFailed

        try:
            return _raw(self.tester.call({**message, "data": "0x" + message["data"].hex()}, "pending"))
        except TransactionFailed as exc:
            raw = revert_data(exc)
            if raw is None:
                raise
            raise RevertedCall(raw) from exc

    def _send_signed(self, raw: bytes) -> _Mined:
        tx_hash = self.tester.send_raw_transaction("0x" + raw.hex())
        r = self.tester.get_transaction_receipt(tx_hash)
        logs = [Log(checksum(lg["address"]), [_raw(t) for t in lg["topics"]], _raw(lg["data"])) for lg in r["logs"]]
        return _Mined(tx_hash, r["status"], r["contract_address"], Receipt(r["gas_used"], r["block_number"], logs))

    def _snapshot(self):
        return self.tester.take_snapshot()

    def _revert(self, snapshot) -> None:
        self.tester.revert_to_snapshot(snapshot)

    def _undo_point(self):
        """The chain's head (its backend's snapshot, a block hash): eth-tester keeps every snapshot id it
        hands out, one per transaction here, for good."""
        return self.tester.backend.take_snapshot()

    def _undo_to(self, head) -> None:
        self.tester.backend.revert_to_snapshot(head)


class Web3Backend(_SignedChain):
    """A JSON-RPC node through web3.py; its first unlocked account pays the robots' gas."""

    def __init__(self, rpc_url: str):
        from web3 import Web3

        self.w3 = Web3(Web3.HTTPProvider(rpc_url))
        if not self.w3.is_connected():
            raise ChainError(f"no JSON-RPC node answers at {rpc_url}")
        self.name = rpc_url
        self.chain_id = self.w3.eth.chain_id
        self.gas_limit = self.w3.eth.get_block("latest")["gasLimit"]

    def _latest(self) -> int:
        return self.w3.eth.block_number

    def _mine(self, blocks: int) -> None:
        for _ in range(blocks):
            self.w3.provider.make_request("evm_mine", [])

    def _payer(self) -> str:
        accounts = self.w3.eth.accounts
        if not accounts:
            raise ChainError("the node has no unlocked account to pay the robots' gas")
        return accounts[0]

    def _balance(self, address: str) -> int:
        return self.w3.eth.get_balance(address)

    def _send_value(self, payer: str, to: str, value: int) -> None:
        sent = self.w3.eth.send_transaction({"from": payer, "to": to, "value": value})
        self.w3.eth.wait_for_transaction_receipt(sent)

    def _nonce(self, address: str) -> int:
        return self.w3.eth.get_transaction_count(address, "pending")

    def _gas_price(self) -> int:
        return self.w3.eth.gas_price

    def _execute(self, message: dict) -> bytes:
        try:
            return bytes(self.w3.eth.call(message, "pending"))
        except Exception as exc:  # anything that is not a revert is re-raised as it came
            raw = revert_data(exc)
            if raw is None:
                raise
            raise RevertedCall(raw) from exc

    def _send_signed(self, raw: bytes) -> _Mined:
        r = self.w3.eth.wait_for_transaction_receipt(self.w3.eth.send_raw_transaction(raw))
        logs = [Log(lg.address, [bytes(t) for t in lg.topics], bytes(lg.data)) for lg in r.logs]
        return _Mined(r.transactionHash.hex(), r.status, r.contractAddress,
                      Receipt(r.gasUsed, r.blockNumber, logs))

    def _snapshot(self):
        return self.w3.provider.make_request("evm_snapshot", [])["result"]

    def _revert(self, snapshot) -> None:
        if not self.w3.provider.make_request("evm_revert", [snapshot]).get("result"):
            raise ChainError(f"the node could not go back to its snapshot {snapshot}")
