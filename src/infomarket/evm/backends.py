"""Where the contract runs: one small interface, three chains behind it.

``ChainMarket`` (market.py) never talks to a node itself; it hands ABI-encoded calldata to a backend:

- ``PyEvmBackend`` (the in-process py-evm through eth-tester, the reference EVM, nothing to install or
  run) and ``Web3Backend`` (any JSON-RPC node, ``--rpc``, through web3.py; its first unlocked account
  pays the robots' gas), in signed_chains.py. Every transaction is signed by its sender's own key, as
  on a real swarm; every block holds one transaction (automining), so ``advance_to`` can only move the
  chain forward.
- ``RevmBackend`` over pyrevm (revm, the Rust EVM, through its Python bindings): hundreds of times
  faster than py-evm, with blocks set explicitly (``advance_to(n)`` makes every following transaction
  land in block ``n`` until the next call), which is what the replay of a simulation needs: one block
  per simulated step, however many transactions the step holds. Transactions execute as their sender
  without an Ethereum transaction signature (the buyers' EIP-712 signatures inside the light contracts
  are still checked by the contract itself).

Both charge gas as a chain does (``cold_storage``): every transaction starts with cold accounts and
storage slots (EIP-2929), and each slot's "original value" (EIP-2200, and the refunds of EIP-3529) is
the value it had before the transaction. py-evm does so by itself. pyrevm 0.3.7 (the newest release)
does not: it keeps one journaled state for the EVM's life and never finalises it between
transactions, so whatever a transaction loaded would stay warm for the next, and a reveal would cost
about 20 000 gas less. So ``RevmBackend`` keeps the journal empty between transactions and the
chain's state in revm's database: each transaction runs inside a journal checkpoint; its changes
are read from the journal (``journal_str``, revm's print of the journaled state: every account and
slot the transaction loaded, with the value it was loaded with and its present one); the checkpoint
is reverted, which drops every loaded account and slot from the journal (cold again) and undoes the
changes; then the changes are written into the database (``insert_account_info`` and
``insert_account_storage``, which write the database only for an account out of the journal), where
the next transaction loads them cold, with these values as originals. A reverted transaction keeps
nothing and warms nothing. Views and dry runs run in a checkpoint that is reverted too. The
database writes are logged once ``snapshot`` is first called, so that ``revert`` can undo them.
``tests/evm/test_revm_gas.py`` sends the same transactions to both backends and finds the same gas
for each. The block's coinbase stays in the journal, as it is warm for every transaction (EIP-3651).

Both raise ``RevertedCall`` with the raw revert bytes (the market decodes them into ``ContractRevert``,
the custom error's name and arguments), and both return a ``Receipt`` whose logs are raw (address,
topics, data).
"""
from __future__ import annotations

import re
from typing import NamedTuple

from eth_utils import keccak

from .errors import ChainError
from .protocol import checksum
from .signed_chains import PyEvmBackend, Web3Backend
from .transactions import ETH_TESTER_CHAIN_ID, GAS_ALLOWANCE_WEI, Log, Receipt, RevertedCall

#: Block gas limit of the revm chain (Ethereum mainnet's in 2024).
REVM_BLOCK_GAS = 30_000_000
#: eth-tester's, so that both in-process chains sign alike
REVM_CHAIN_ID = ETH_TESTER_CHAIN_ID

_REVERT_OUTPUT = re.compile(r"output: 0x([0-9a-fA-F]*)")
#: The pyrevm whose journal print ``journal_accounts`` reads.
PYREVM_VERSION = "0.3.7"
#: In pyrevm's ``journal_str`` (revm's Debug print of the journaled state): what follows an account's
#: address in the state map, its info, and one storage slot with the value it was loaded with and the
#: value it holds now. (The print holds the contract's code too: found with str.find, not a regex scan.)
_STATE = "JournaledState { state: {"
_ACCOUNT = ": Account { info: AccountInfo { balance: "
_INFO = re.compile(r"(\d+), nonce: (\d+), code_hash: 0x([0-9a-f]{64})")
_SLOT = re.compile(r"[{ ](\d+): StorageSlot \{ previous_or_original_value: (\d+), present_value: (\d+) \}")
_EMPTY_CODE_HASH = keccak(b"")
#: (balance, nonce, code hash) of an account that was never written
_NO_ACCOUNT = (0, 0, _EMPTY_CODE_HASH)


class JournalAccount(NamedTuple):
    """One account of revm's journaled state: its (balance, nonce, code hash) and every storage slot
    the transaction loaded, as (key, value it was loaded with, value now)."""

    address: str
    info: tuple[int, int, bytes]
    slots: list[tuple[int, int, int]]


def journal_accounts(text: str) -> list[JournalAccount]:
    """The accounts in pyrevm's ``journal_str``, revm's Debug print of its journaled state: the only
    place that reads the print (pyrevm has no call that returns a transaction's changes), so a pyrevm
    whose print differs stops here with an error rather than losing a write."""
    end = text.find(", transient_storage: ")
    if not text.startswith(_STATE) or end < 0:
        raise ChainError(f"revm: unexpected journal print {text[:80]!r} (is pyrevm newer than {PYREVM_VERSION}?)")
    if text.find("SelfDestructed", 0, end) >= 0:  # the market's contract never self-destructs
        raise ChainError("revm backend: a transaction that self-destructs an account is not supported")
    accounts = []
    at = text.find(_ACCOUNT, 0, end)
    while at >= 0:
        address = text[at - 42:at]
        found = _INFO.match(text, at + len(_ACCOUNT))
        begin = text.find("storage: {", found.end()) if found else -1
        stop = text.find(", status: AccountStatus", begin) if begin >= 0 else -1
        if not address.startswith("0x") or stop < 0:
            raise ChainError(f"revm: unexpected journal print at {text[at - 42:at + 80]!r} (is pyrevm newer "
                             f"than {PYREVM_VERSION}?)")
        info = (int(found.group(1)), int(found.group(2)), bytes.fromhex(found.group(3)))
        storage = text[begin + len("storage: ") - 1:stop]
        slots = [(int(m.group(1)), int(m.group(2)), int(m.group(3))) for m in _SLOT.finditer(storage)]
        if _SLOT.sub("", storage).strip("{}, "):  # something in the map that is not a slot as printed
            raise ChainError(f"revm: unexpected storage slot print in {storage[:160]!r} (is pyrevm newer than "
                             f"{PYREVM_VERSION}?)")
        accounts.append(JournalAccount(address, info, slots))
        at = text.find(_ACCOUNT, stop, end)
    if len(accounts) != text.count("Account { info:", 0, end) or (not accounts and text[len(_STATE)] != "}"):
        raise ChainError(f"revm: unexpected account print in {text[:160]!r} (is pyrevm newer than {PYREVM_VERSION}?)")
    return accounts


class RevmBackend:
    """revm through pyrevm: an in-process chain whose blocks the caller sets, with cold storage per
    transaction (see the module docstring: every transaction runs in a checkpoint of an empty journal,
    its changes are read from the journal, the checkpoint is reverted and the changes are written to
    the database, from which the next transaction loads them cold, as a chain's would)."""

    name = "revm"
    #: gas as a chain charges it: every transaction starts with cold accounts and storage (EIP-2929)
    cold_storage = True
    #: when True, number blocks as py-evm and a node do: each transaction, and each funding (a
    #: transaction there), lands in a block of its own (the gas report uses it, so that block numbers
    #: written to storage and calldata are those of py-evm); the replay sets its blocks itself
    automine = False

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
        #: what the database holds for every account written so far: (balance, nonce, code hash), and
        #: the code of the accounts that have some (the database's account info is replaced whole)
        self._accounts: dict[str, tuple[int, int, bytes]] = {}
        self._code: dict[str, bytes] = {}
        #: undo log of the database writes, kept from the first ``snapshot`` on: ("info", address, old)
        #: or ("slot", address, key, old)
        self._undo: list[tuple] | None = None

    @property
    def block_number(self) -> int:
        """The current block number (with ``automine``, each transaction mines one block)."""
        return self._block

    def advance_to(self, block: int) -> None:
        """Move the chain forward to block ``block`` (never back), so deadlines and delays measured in blocks
        elapse."""
        if block > self._block:
            self._block = block
            self.evm.set_block_env(self._pyrevm.BlockEnv(number=block, timestamp=block,
                                                         gas_limit=REVM_BLOCK_GAS))

    def fund(self, addresses: list[str], amount: int = GAS_ALLOWANCE_WEI) -> None:
        """Give each address ``amount`` wei, written straight into the database (nothing warmed)."""
        for a in addresses:
            key = a.lower()
            _, nonce, code_hash = self._accounts.get(key, _NO_ACCOUNT)
            self._write_info(key, (amount, nonce, code_hash))
            self._mined()

    def call(self, sender: str, to: str, data: bytes, static: bool = False) -> bytes:
        """Execute without keeping any change (a view runs static), inside a checkpoint that is
        reverted, so that nothing it loads stays warm."""
        return bytes(self._isolated(lambda: self.evm.message_call(sender, to, data, gas=self.gas_limit,
                                                                  is_static=static)))

    def transact(self, sender, to: str, data: bytes) -> Receipt:
        """Execute and keep: a reverted call changes nothing (and warms nothing), so no dry run is needed."""
        self._isolated(lambda: self.evm.message_call(sender.address, to, data, gas=self.gas_limit), keep=True)
        receipt = self._receipt()
        self._mined()
        return receipt

    def deploy(self, sender, code: bytes) -> tuple[str, Receipt]:
        """Deploy ``code`` from ``sender``; returns the new contract's checksummed address and the receipt."""
        address = self._isolated(lambda: self.evm.deploy(sender.address, code, gas=self.gas_limit), keep=True)
        receipt = self._receipt()
        self._mined()
        return checksum(address), receipt

    def _mined(self) -> None:
        if self.automine:
            self.advance_to(self._block + 1)

    def snapshot(self) -> list:
        """A handle to the current state that ``revert`` can go back to any number of times: the
        length of the undo log of database writes, which is kept from the first snapshot on."""
        if self._undo is None:
            self._undo = []
        return [len(self._undo), self._block]

    def revert(self, snapshot: list) -> None:
        """Go back to the state of ``snapshot``: undo every database write made since, and the block number."""
        mark, block = snapshot
        slots = []
        while len(self._undo) > mark:
            entry = self._undo.pop()
            if entry[0] == "info":
                _, address, old = entry
                self._write_info(address, old or _NO_ACCOUNT, undo=False)
                if old is None:
                    del self._accounts[address]
            else:
                slots.append(entry[1:])
        self._write_slots(slots, undo=False)
        self._block = 0
        self.advance_to(block)

    # -- one transaction, cold ----------------------------------------------------------------------

    def _isolated(self, execute, keep: bool = False):
        """Run ``execute`` in a checkpoint of the (empty) journal and revert it, so that every account
        and slot it loaded is cold again; with ``keep``, write what it changed into the database."""
        checkpoint = self.evm.snapshot()
        try:
            out = self._run(execute)
            changes = self._changes() if keep else None
        finally:
            self.evm.revert(checkpoint)
            if self.evm.journal_depth != 0:  # pragma: no cover - would mean pyrevm left a frame open
                raise ChainError(f"revm: the journal was left at depth {self.evm.journal_depth}")
        if changes is not None:
            infos, slots = changes
            for address, (info, code) in infos.items():
                if code is not None:
                    self._code[address] = code
                self._write_info(address, info)
            self._write_slots(slots)
        return out

    def _changes(self) -> tuple[dict, list]:
        """What the transaction just executed changed: accounts whose (balance, nonce, code hash)
        differ from the database's, and slots whose present value differs from the value they were
        loaded with."""
        infos, slots = {}, []
        for address, info, loaded in journal_accounts(self.evm.journal_str):
            old = self._accounts.get(address, _NO_ACCOUNT)
            if info != old:
                code = self._deployed_code(address, info[2]) if info[2] != old[2] else None
                infos[address] = (info, code)
            slots += [(address, key, now, was) for key, was, now in loaded if was != now]
        return infos, slots

    def _deployed_code(self, address: str, code_hash: bytes) -> bytes:
        """The code an account was just given: revm pads it with zeros, the hash tells how many."""
        code = bytes(self.evm.get_code(address) or b"")
        for end in range(len(code), max(-1, len(code) - 64), -1):
            if keccak(code[:end]) == code_hash:
                return code[:end]
        raise ChainError(f"revm: the code of {address} does not match its hash")

    def _write_info(self, address: str, info: tuple[int, int, bytes], undo: bool = True) -> None:
        """Write an account into the database: it must be cold (out of the journal), as it is between
        transactions, or revm would write into the journal instead."""
        if undo and self._undo is not None:
            self._undo.append(("info", address, self._accounts.get(address)))
        balance, nonce, code_hash = info
        code = self._code.get(address) if code_hash != _EMPTY_CODE_HASH else None
        self.evm.insert_account_info(address, self._pyrevm.AccountInfo(balance=balance, nonce=nonce, code=code))
        self._accounts[address] = info

    def _write_slots(self, slots: list[tuple], undo: bool = True) -> None:
        """Write (address, key, value, old value) slots into the database. pyrevm's
        ``insert_account_storage`` writes the database only when the account is out of the journal,
        and loads it into the journal as it does; so each write runs in a checkpoint of its own, reverted."""
        if undo and self._undo is not None:
            self._undo += [("slot", address, key, old) for address, key, _, old in slots]
        evm = self.evm
        for address, key, value, *_ in slots:
            checkpoint = evm.snapshot()
            evm.insert_account_storage(address, key, value)
            evm.revert(checkpoint)

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
        logs = [Log(checksum(lg.address), [bytes.fromhex(t.removeprefix("0x")) for t in lg.topics],
                    bytes(lg.data[1])) for lg in result.logs]
        return Receipt(result.gas_used, self._block, logs)


def make_backend(name: str | None = None, rpc_url: str | None = None):
    """``revm`` (the default: fast), ``py-evm`` (the reference), or the JSON-RPC node at ``rpc_url``."""
    if rpc_url is not None:
        return Web3Backend(rpc_url)
    if name in (None, "revm"):
        return RevmBackend()
    if name == "py-evm":
        return PyEvmBackend()
    raise ChainError(f"unknown chain backend {name!r}: choose revm or py-evm")
