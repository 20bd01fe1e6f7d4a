"""What every chain backend (backends.py, signed_chains.py) hands back: a mined transaction's receipt and
raw logs, and ``RevertedCall`` for a refusal, with the revert bytes the market decodes."""
from __future__ import annotations

from typing import NamedTuple

from .errors import ChainError

#: Gas money given to every robot and to the market account (wei); far above what a demo spends.
GAS_ALLOWANCE_WEI = 10**20
#: The chain id of eth-tester's chain (py-evm in process).
ETH_TESTER_CHAIN_ID = 131_277_322_940_537


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
