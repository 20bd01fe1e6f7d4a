"""Errors of the on-chain market, under the package's root ``InfomarketError``.

A refusal by the contract carries the custom error's name and its decoded arguments, so callers and
tests check *which* rule refused and with what values, not a message string.
"""
from __future__ import annotations

import ast
from typing import Any

from ..errors import InfomarketError


class ChainError(InfomarketError, RuntimeError):
    """Something went wrong talking to the chain (no node, no funded account, bad artifact...)."""


class UnitsError(ChainError, ValueError):
    """A value does not fit the contract's fixed-point integer units (e.g. a coordinate beyond int64)."""


class ContractRevert(ChainError):
    """The contract refused a call with one of its custom errors (``name``, ``args``)."""

    def __init__(self, name: str, args: dict[str, Any], data: bytes):
        self.name = name
        self.args_by_name = args
        self.data = data
        shown = ", ".join(f"{k}={_show(v)}" for k, v in args.items())
        super().__init__(f"{name}({shown})")


def _show(value: Any) -> str:
    return "0x" + value.hex() if isinstance(value, bytes) else str(value)


def revert_data(exc: BaseException) -> bytes | None:
    """The raw revert bytes, wherever the backend put them.

    A JSON-RPC node's answer reaches us as web3's ``ContractCustomError``/``ContractLogicError`` with a
    hex ``data`` (Hardhat Network nests it: ``{"message": ..., "data": "0x..."}``). eth-tester raises
    ``TransactionFailed`` whose message is the bytes' repr, and web3
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
        if isinstance(data, dict):  # Hardhat Network: {"message": ..., "data": "0x..."}
            data = data.get("data")
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
