"""The revm backend reads each transaction's changes from pyrevm's print of its journaled state
(``backends.journal_accounts``). These tests pin that print: if a pyrevm upgrade changes it, they fail
here, naming what was not found, before any gas figure or balance can go wrong."""
from __future__ import annotations

import pytest

from infomarket.evm.backends import RevmBackend, journal_accounts
from infomarket.evm.errors import ChainError
from infomarket.evm.market import derived_account

#: Runtime code PUSH1 7, PUSH1 1, SSTORE, STOP (slot 1 := 7), and init code that returns it.
RUNTIME = bytes.fromhex("600760015500")
INIT = bytes.fromhex("65" + RUNTIME.hex() + "600052" + "6006" + "601a" + "f3")


def _journal_of_a_store():
    """pyrevm's journal print right after a call that stores 7 in slot 1 of a fresh contract."""
    backend = RevmBackend()
    sender = derived_account("journal", 0)
    backend.fund([sender.address])
    contract, _ = backend.deploy(sender, INIT)
    evm = backend.evm
    checkpoint = evm.snapshot()
    try:
        evm.message_call(sender.address, contract, b"", gas=100_000)
        return contract, sender.address, evm.journal_str
    finally:
        evm.revert(checkpoint)


def test_the_journal_print_gives_each_loaded_slot_and_account():
    contract, sender, text = _journal_of_a_store()
    accounts = {a.address.lower(): a for a in journal_accounts(text)}
    assert accounts[contract.lower()].slots == [(1, 0, 7)]  # (key, loaded, now)
    assert accounts[sender.lower()].info[:2] == (10**20, 1)  # its allowance (gas price 0); one deployment


@pytest.mark.parametrize("change", [
    ("present_value", "value"), ("StorageSlot {", "Slot {"), ("AccountInfo { balance: ", "Info { balance: "),
    (", status: AccountStatus", ", state: AccountStatus"), (", transient_storage: ", ", transient: "),
    ("JournaledState { state:", "Journal { state:"), ("Account { info:", "Acct { info:")])
def test_a_changed_journal_print_is_an_error_not_a_lost_write(change):
    contract, _, text = _journal_of_a_store()
    old, new = change
    assert old in text
    changed = text.replace(old, new)
    try:
        accounts = journal_accounts(changed)
    except ChainError as err:
        assert "unexpected" in str(err) and "pyrevm" in str(err)
    else:  # a print the parser still reads must still give the store
        assert [a.slots for a in accounts if a.address.lower() == contract.lower()] == [[(1, 0, 7)]]
