"""Errors of the on-chain market, under the package's root ``InfomarketError``.

A refusal by the contract carries the custom error's name and its decoded arguments, so callers and
tests check *which* rule refused and with what values, not a message string.
"""
from __future__ import annotations

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
