"""The store's errors and what ``Store.verify`` reports: ``StoreError`` (a ValueError: bad input, exit 2)
and its kinds, kept apart so the lock and the query modules raise them without importing the store."""
from __future__ import annotations

from dataclasses import dataclass, field

from ..errors import InfomarketError


class RecordAltered(InfomarketError):
    """A commit record's content does not match the checksum it was written with (internal signal)."""


class StoreError(InfomarketError, ValueError):
    """The folder is not a usable results store (wrong format, incompatible contents, locked)."""


class SqlError(StoreError):
    """A query given to ``Store.sql`` is not valid SQL or names what the store does not hold."""


class StoreDamaged(StoreError):
    """A committed part does not match its commit record (truncated, altered, missing, unreadable)."""


@dataclass(frozen=True)
class Problem:
    """One damaged part: ``path`` (relative to the store), and why."""

    part: str
    path: str
    why: str


@dataclass
class Inspection:
    """What ``Store.verify`` found."""

    parts: int = 0
    damaged: list[Problem] = field(default_factory=list)
    orphans: list[str] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """True when the inspection found nothing damaged."""
        return not self.damaged
