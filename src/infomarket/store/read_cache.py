"""What a caching ``Store`` remembers between reads, so that reading a growing store costs what it grew by.

The attack search and the defence search sweep into one store generation after generation, and every
sweep reads the store's runs table (which runs are done, which configuration made them) and checks every
part.  Read from scratch, a store of P parts costs P file reads and a concatenation of P frames per sweep:
a search's store work grew with the square of its length.  Here each file's frame, checksum and verdict is
kept under the file's signature (``signature``: a committed part is written once, through a rename, so a
rewritten or altered file has another), and each table's concatenation is extended by the parts added
since the last read instead of being made again.
"""
from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import pandas as pd

KEY = ["experiment", "condition", "run"]


def signature(path: str | os.PathLike) -> tuple[int, int, int, int] | None:
    """What identifies a file's content for the cache (inode, size, change times), or None if it is absent."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns


def sort_rows(df: pd.DataFrame) -> pd.DataFrame:
    """A table's rows in the store's order: by run, then step and robot where the table has them."""
    by = [c for c in KEY + ["step", "robot"] if c in df.columns]
    return df.sort_values(by, kind="stable").reset_index(drop=True)


def _run_keys(frame: pd.DataFrame) -> set[tuple] | None:
    """The runs a part's frame holds rows of, or None when it lacks a key column."""
    if any(c not in frame.columns for c in KEY):
        return None
    return set(frame[KEY].drop_duplicates().itertuples(index=False, name=None))


@dataclass
class _Table:
    """One table as last read: its parts' frames (kept alive: they are compared by identity), the runs they
    hold (None: two parts hold rows of one run, so the table is always concatenated whole), and their rows
    concatenated and sorted."""

    frames: dict[str, pd.DataFrame]
    runs: set[tuple] | None
    result: pd.DataFrame = field(repr=False)


def _columns(parts: Sequence[tuple[str, pd.DataFrame]]) -> list[str]:
    """The columns of ``pd.concat`` of the parts' frames, in its order: as they first appear, in part order."""
    order: dict[str, None] = {}
    seen: set[tuple] = set()
    for _, frame in parts:
        cols = tuple(frame.columns)
        if cols not in seen:  # a column list met before adds no column
            seen.add(cols)
            order.update(dict.fromkeys(cols))
    return list(order)


def _held_runs(frames: Sequence[pd.DataFrame], known: set[tuple] | None) -> set[tuple] | None:
    """``known`` with the runs of ``frames`` added, or None if a run is held by two of the parts."""
    if known is None:
        return None
    held = set(known)
    for frame in frames:
        keys = _run_keys(frame)
        if keys is None or not held.isdisjoint(keys):
            return None
        held |= keys
    return held


class ReadCache:
    """Files' frames, checksums and verdicts under their signatures, and each table's sorted rows."""

    def __init__(self):
        self.entries: dict[tuple[str, str], tuple] = {}
        self.tables: dict[str, _Table] = {}

    def get(self, kind: str, path: str | os.PathLike, compute: Callable):
        """``compute()``, remembered under (kind, path, the file's signature)."""
        sig = signature(path)
        if sig is None:
            return compute()
        key = (kind, os.fspath(path))
        hit = self.entries.get(key)
        if hit is None or hit[0] != sig:
            hit = self.entries[key] = (sig, compute())
        return hit[1]

    def put(self, kind: str, path: str | os.PathLike, value) -> None:
        """Remember ``value`` for the file as it is now: what its writer knows of it, so it is not read back."""
        sig = signature(path)
        if sig is not None:
            self.entries[(kind, os.fspath(path))] = (sig, value)

    def verdict(self, path: str | os.PathLike, record: pd.DataFrame, compute: Callable, exists: bool | None = None):
        """A data part's verdict against its commit record: it stands while the record is the same object
        and the part's file the same file (or absent still: ``exists=False`` where the caller knows)."""
        key, sig = ("verdict", os.fspath(path)), (id(record), None if exists is False else signature(path))
        hit = self.entries.get(key)
        if hit is None or hit[0] != sig:
            hit = self.entries[key] = (sig, compute(sig[1] is not None), record)
        return hit[1]

    def table(self, name: str, parts: Sequence[tuple[str, pd.DataFrame]]) -> pd.DataFrame:
        """The rows of ``parts`` ((part id, frame) in part order, none empty) concatenated and sorted, as
        ``sort_rows(pd.concat(frames))`` gives them: extended by the new parts when every part read last
        time is still there unchanged.  The rows of one run are in one part, so rows that sort equal come
        from one part, in its order, whichever order the parts were concatenated in; the columns are put in
        the order the whole concatenation gives them."""
        last = self.tables.get(name)
        now = dict(parts)
        if last is not None and last.runs is not None and all(now.get(p) is f for p, f in last.frames.items()):
            new = [(p, f) for p, f in parts if p not in last.frames]
            if not new:
                return last.result.copy()
            runs = _held_runs([f for _, f in new], last.runs)
            if runs is not None:
                rows = sort_rows(pd.concat([last.result] + [f for _, f in new], ignore_index=True))
                columns = _columns(parts)
                if list(rows.columns) != columns:  # a new part sorts before the one that brought a column
                    rows = rows[columns]
                self.tables[name] = _Table({**last.frames, **dict(new)}, runs, rows)
                return rows.copy()
        frames = [f for _, f in parts]
        rows = sort_rows(pd.concat(frames, ignore_index=True))
        self.tables[name] = _Table(now, _held_runs(frames, set()), rows)
        return rows.copy()
