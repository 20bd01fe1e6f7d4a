"""The contract's ABI, worked out once: calldata encoding, and the decoding of results, events and refusals.

Each function's selector and types, and each event's layout, are computed when a market is made; a replay
encodes and decodes tens of thousands of calls.
"""
from __future__ import annotations

from typing import Any, NamedTuple

from eth_abi import decode as abi_decode
from eth_abi import encode as abi_encode
from eth_utils import keccak
from eth_utils.abi import (event_abi_to_log_topic, function_abi_to_4byte_selector, get_abi_input_types,
                           get_abi_output_types)

from .errors import ContractRevert
from .protocol import checksum


class Event(NamedTuple):
    """A decoded event log."""

    name: str
    args: dict


class Codec:
    """The contract's ABI: calldata encoding, result, event and error decoding."""

    def __init__(self, abi: list):
        self.abi = abi
        self.functions = {e["name"]: (function_abi_to_4byte_selector(e), get_abi_input_types(e),
                                      get_abi_output_types(e)) for e in abi if e["type"] == "function"}
        self.events = {event_abi_to_log_topic(e): _EventLayout.of(e) for e in abi if e["type"] == "event"}
        self.errors = _error_table(abi)

    def calldata(self, name: str, args: tuple) -> bytes:
        """The calldata of a call to function ``name`` with ``args``: its selector and the ABI-encoded arguments."""
        selector, inputs, _ = self.functions[name]
        return selector + abi_encode(inputs, list(args))

    def result(self, name: str, data: bytes) -> Any:
        """The decoded return value of function ``name`` (a tuple when it returns several values)."""
        values = abi_decode(self.functions[name][2], data)
        return values[0] if len(values) == 1 else values

    def decode_event(self, topics: list[bytes], data: bytes) -> Event | None:
        """The contract's event in a log (``topics``, ``data``), with addresses checksummed; None for another
        contract's event."""
        layout = self.events.get(topics[0]) if topics else None
        if layout is None:
            return None
        # each topic is one 32-byte word: together, the encoding of the indexed inputs as one static tuple
        args = dict(zip(layout.indexed_names, abi_decode(layout.indexed_types, b"".join(topics[1:]))))
        args.update(zip(layout.plain_names, abi_decode(layout.plain_types, data)))
        return Event(layout.name, {k: _checksum(args[k]) for k in layout.names})

    def refusal(self, data: bytes) -> ContractRevert | None:
        """The contract's custom error in revert ``data``, with its arguments; None for a revert that is not one of
        its errors."""
        if len(data) < 4 or data[:4] not in self.errors:
            return None
        name, names, types = self.errors[data[:4]]
        values = [_checksum(v) for v in abi_decode(types, data[4:])]
        return ContractRevert(name, dict(zip(names, values)), data)


class _EventLayout(NamedTuple):
    """An event's name, its indexed and its other inputs' names and types, and the order of all its
    inputs.  The contract indexes value types only, each a topic word as it is."""

    name: str
    indexed_names: list[str]
    indexed_types: list[str]
    plain_names: list[str]
    plain_types: list[str]
    names: list[str]

    @classmethod
    def of(cls, abi: dict) -> _EventLayout:
        plain = [i for i in abi["inputs"] if not i["indexed"]]
        indexed = [i for i in abi["inputs"] if i["indexed"]]
        return cls(abi["name"], [i["name"] for i in indexed], [i["type"] for i in indexed],
                   [i["name"] for i in plain], [i["type"] for i in plain], [i["name"] for i in abi["inputs"]])


def _checksum(value):
    return checksum(value) if isinstance(value, str) and value.startswith("0x") and len(value) == 42 else value


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
