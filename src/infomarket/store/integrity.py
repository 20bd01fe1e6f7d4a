"""Checking a store's committed parts against their commit records, and moving damaged ones aside: a
part is damaged when its file is missing, unreadable, or not the bytes its record's SHA-256 names."""
from __future__ import annotations

import shutil
import time
from pathlib import Path

import pandas as pd
import pyarrow.parquet as pq

from .errors import Inspection, Problem, RecordAltered
from .files import sha256_file
from .tables import DATA_TABLES, OPTIONAL_TABLES


def _rel(root: Path, path: Path) -> str:
    return str(path.relative_to(root))


def data_part_problem(store, table: str, path: Path, record: pd.DataFrame, exists: bool | None = None) -> str | None:
    """Why the ``table`` part at ``path`` does not match its commit record ``record``, or None.  ``exists``:
    whether the file exists, where the caller knows (None: look)."""
    if exists is None:
        exists = path.exists()
    sha_col, rows_col = f"{table}_sha256", f"{table}_rows"
    if sha_col not in record.columns:  # a store written before checksums: readable is all we know
        if not exists:
            return None
        if table in OPTIONAL_TABLES and store._record_checksums():
            return "exists but its commit record does not list it"
        try:
            pq.read_metadata(path)
        except Exception as exc:  # noqa: BLE001 - any reader error means damage
            return f"unreadable ({type(exc).__name__}: {exc})"
        return None
    sha, rows = str(record[sha_col].iloc[0]), int(record[rows_col].iloc[0])
    if not sha:
        return "exists but its commit record says it has no rows" if exists else None
    if not exists:
        return f"missing (the commit record says {rows} rows)"
    if store._cached("sha256", path, lambda: sha256_file(path)) != sha:
        return f"checksum mismatch: truncated or altered (the commit record says {rows} rows)"
    return None


def inspect(store) -> Inspection:
    """``Store.verify``: every committed part checked against its commit record; damaged and orphan parts."""
    found = Inspection()
    if store.exists():
        store.meta()  # an unreadable store.json is a StoreError, not a store of no parts
    runs_parts = store._parts("runs")
    present = {t: store._part_ids(t) for t in DATA_TABLES}
    for pid, path in sorted(runs_parts.items()):
        found.parts += 1
        try:
            record = store._read_runs_part(path)
        except RecordAltered as exc:
            found.damaged.append(Problem(pid, _rel(store.root, path), f"commit record {exc}"))
            continue
        except Exception as exc:  # noqa: BLE001 - any reader error means damage
            found.damaged.append(Problem(pid, _rel(store.root, path),
                                         f"unreadable commit record ({type(exc).__name__}: {exc})"))
            continue
        for t in DATA_TABLES:
            why = store._check_data_part(t, pid, record, present=pid in present[t])
            if why:
                found.damaged.append(Problem(pid, _rel(store.root, store.part_path(t, pid)), why))
    for t in DATA_TABLES:
        found.orphans += [_rel(store.root, store.part_path(t, pid)) for pid in sorted(present[t])
                          if pid not in runs_parts]
    found.orphans += sorted(_rel(store.root, p) for p in store.root.glob("*/.part-*.tmp"))
    return found


def move_aside(store) -> tuple[Inspection, list[str]]:
    """Move every damaged part (all its files, the commit record included) and every orphan into
    ``damaged/``; returns the inspection and the paths moved (relative to the store).  Call with the
    lock held.  Nothing is deleted."""
    found = store.verify()
    moved = []
    stamp = time.strftime("%Y%m%dT%H%M%S")
    aside = store.root / "damaged" / stamp

    def move(path: Path) -> None:
        dest = aside / _rel(store.root, path)
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.move(path, dest)
        moved.append(_rel(store.root, path))

    for pid in sorted({p.part for p in found.damaged}):
        for t in ("runs",) + DATA_TABLES:  # the commit record first: its runs are then not done
            path = store.part_path(t, pid)
            if path.exists():
                move(path)
    for rel in found.orphans:
        if (store.root / rel).exists():
            move(store.root / rel)
    return found, moved
