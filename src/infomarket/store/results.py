"""The results store: a folder of Parquet datasets that sweeps append to and analyses read (its layout,
columns and integrity checks: the package docstring, ``infomarket.store``)."""
from __future__ import annotations

from collections.abc import Iterable
import functools
import json
import os
import time
from contextlib import contextmanager
from pathlib import Path

import hashlib

import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from .. import interrupts
from .._version import __version__
from .errors import Inspection, Problem, RecordAltered, SqlError, StoreDamaged, StoreError  # noqa: F401 - re-exported: the store's errors, where callers import them
from . import integrity
from .tables import DATA_TABLES, OPTIONAL_TABLES, TABLES
from .lock import StoreLock
from .query import run_sql
from .dictionary import TABLES as TABLES_DICT
from .dictionary import annotate
from .files import sha256_file, write_atomic, write_text_atomic
from .read_cache import ReadCache, sort_rows
from ..config.load import validate
from ..userfiles import read_text

FORMAT = 1
OK, FAILED = "ok", "failed"


RECORD_SHA = b"infomarket_record_sha256"


def record_digest(table: pa.Table) -> str:
    """SHA-256 of a commit record's content: column names and values, in order (not the file's bytes)."""
    data = json.dumps([table.column_names, table.to_pydict()], default=str, allow_nan=True)
    return hashlib.sha256(data.encode()).hexdigest()


def write_table(table: str, df: pd.DataFrame, path: Path, keys: Iterable[str] = (), **options) -> None:
    """Write ``df`` as the store's ``table`` to ``path``, each column's unit and description in its field
    metadata (``store.dictionary.annotate``; a column it does not describe is an InternalError)."""
    pq.write_table(annotate(table, pa.Table.from_pandas(df, preserve_index=False), keys), path, **options)


def _declarations() -> dict:
    """Hashes of the files declaring questions and decision rules: a report flags any rule
    edited after the store's first run (``store.declarations``, read by ``analysis.declared``)."""
    from .declarations import fingerprint  # declarations reads the package's questions files: when a store is made

    return fingerprint()


def _rel(root: Path, path: Path) -> str:
    return str(path.relative_to(root))


class Store:
    """A results store rooted at ``root`` (created on first write).

    ``cache=True``: remember what this object has read, verified and written (commit records, checksums
    of data parts, data frames, each table's rows), keyed by each file's signature (``store.read_cache``),
    so a long-lived reader of a growing store (the attack search sweeps into its store every generation)
    reads each part once instead of the whole store each time.  A file replaced or changed on disk is read
    and verified again; a same-size edit within one clock tick would go unseen, hence off by default."""

    def __init__(self, root: str | Path, *, cache: bool = False):
        self.root = Path(root)
        self._cache: ReadCache | None = ReadCache() if cache else None
        self._paths: dict[tuple[str, str], Path] = {}

    def _cached(self, kind: str, path: Path, compute):
        """``compute()``, remembered under (kind, path, the file's signature) when caching."""
        return compute() if self._cache is None else self._cache.get(kind, path, compute)

    # ------------------------------------------------------------------ creation and checks
    @property
    def meta_path(self) -> Path:
        """The store's ``store.json``: format, package version, seeds claimed and declarations recorded."""
        return self.root / "store.json"

    def exists(self) -> bool:
        """Whether a store has been created here (its ``store.json`` exists).

        Example:
            >>> import tempfile
            >>> from infomarket.store import Store
            >>> tmp = tempfile.TemporaryDirectory()
            >>> store = Store(tmp.name + "/results")
            >>> store.exists()
            False
            >>> store.create().exists(), store.committed()
            (True, [])
            >>> tmp.cleanup()
        """
        return self.meta_path.exists()

    def meta(self) -> dict:
        """The parsed ``store.json``.

        Raises:
            StoreError: it cannot be read or is not a JSON object.
        """
        text = read_text(self.meta_path, StoreError, "store.json")  # a regular file of a sane size only
        try:
            meta = json.loads(text)
        except ValueError as exc:
            raise StoreError(f"{self.meta_path}: unreadable ({exc})") from None
        if not isinstance(meta, dict):
            raise StoreError(f"{self.meta_path}: not an infomarket store.json (a JSON object is expected, found "
                             f"{type(meta).__name__})")
        return meta

    def create(self) -> Store:
        """Create the folder layout (idempotent); refuse a folder that holds something else."""
        if self.exists():
            meta = self.meta()
            if meta.get("format") != FORMAT:
                raise StoreError(f"{self.root}: store format {meta.get('format')} is not {FORMAT}")
            for t in TABLES:
                if t not in OPTIONAL_TABLES:
                    (self.root / t).mkdir(exist_ok=True)
            return self
        self.refuse_foreign()
        self.root.mkdir(parents=True, exist_ok=True)
        # store.json first: a folder holding only it (and the lock) reads as a store being created, so a
        # second writer racing this one is refused by the lock, not taken for a foreign folder
        self._write_meta({"format": FORMAT, "package_version": __version__,
                          "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "seeds": {},
                          "record_checksums": True, "declarations": _declarations()})
        for t in TABLES:  # an optional table's folder appears with its first part: a store of runs
            if t not in OPTIONAL_TABLES:  # without the chain looks as it always did
                (self.root / t).mkdir(exist_ok=True)
        return self

    def foreign(self) -> list[Path]:
        """What the folder holds that is not a store's (empty for a store, a new or an empty folder)."""
        if self.exists() or not self.root.is_dir():
            return []
        return sorted(p for p in self.root.iterdir() if p.name != "store.lock")

    def refuse_foreign(self) -> None:
        """StoreError if the folder exists and holds anything but a results store (writes nothing)."""
        if self.root.exists() and not self.root.is_dir():
            raise StoreError(f"{self.root}: exists and is not a directory")
        if self.foreign():
            raise StoreError(f"{self.root}: exists, is not empty and is not an infomarket results store")

    @contextmanager
    def writing(self):
        """``with store.writing(): ...``: refuse a folder holding something else (before writing anything),
        take the store's lock (a second writer gets StoreError at once, having written nothing), then
        create the layout if new.  Everything written under it comes from the one lock holder."""
        self.refuse_foreign()
        try:
            self.root.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise StoreError(f"{self.root}: cannot write there ({exc.strerror or exc})") from None
        with self.lock():
            self.create()
            yield self

    def declarations(self) -> dict | None:
        """The fingerprint of the question and decision-rule files recorded when the store was created
        (before its first run; ``analysis.declared``), or None for a store made before it was recorded."""
        return self.meta().get("declarations") if self.exists() else None

    def _write_meta(self, meta: dict) -> None:
        write_text_atomic(json.dumps(meta, indent=2) + "\n", self.meta_path)

    def lock(self) -> StoreLock:
        """``with store.lock(): ...`` while writing; a second writer gets StoreError at once."""
        return StoreLock(self.root)

    def claim_seeds(self, seeds: dict[str, int], record: bool = True) -> None:
        """Record each experiment's master seed (unless ``record`` is false); refuse one the store already
        holds with another seed.  Call with the lock held."""
        meta = self.meta()
        known = meta.setdefault("seeds", {})
        for name, seed in seeds.items():
            if name in known and int(known[name]) != int(seed):
                raise StoreError(
                    f"{self.root}: holds runs of {name} made with master seed {known[name]}; this sweep asks "
                    f"for seed {seed}. Runs of two seeds would mix in one condition: start a new store "
                    f"(another --out) for seed {seed}, or leave --seed out to resume this one")
        new = {n: int(s) for n, s in seeds.items() if n not in known}
        if new and record:
            known.update(new)
            self._write_meta(meta)

    def seeds(self) -> dict[str, int]:
        """The base seed claimed for each experiment name (empty for a store not yet created)."""
        return {k: int(v) for k, v in self.meta().get("seeds", {}).items()} if self.exists() else {}

    def _part_ids(self, table: str) -> set[str]:
        """The ids of the ``table`` folder's part files (one listing: no file is looked at)."""
        try:
            names = os.listdir(self.root / table)
        except FileNotFoundError:
            return set()
        return {n[5:-8] for n in names if n.startswith("part-") and n.endswith(".parquet")}

    def _parts(self, table: str) -> dict[str, Path]:
        return {pid: self.part_path(table, pid) for pid in self._part_ids(table)}

    def part_path(self, table: str, part_id: str) -> Path:
        """Where the part ``part_id`` of ``table`` lives (whether or not it exists yet)."""
        path = self._paths.get((table, part_id))
        if path is None:  # remembered: a store's checks name every part of every table each time
            path = self._paths[(table, part_id)] = self.root / table / f"part-{part_id}.parquet"
        return path

    def committed(self) -> list[str]:
        """The ids of the committed parts: a part counts once its runs part is written, which is the last write of
        a part."""
        return sorted(self._part_ids("runs"))

    def remove_orphans(self) -> int:
        """Delete data parts (robots, history, events, payments) without a runs part (left by a crash); returns
        how many."""
        done = self._part_ids("runs")
        removed = 0
        for t in DATA_TABLES:
            for pid in self._part_ids(t) - done:
                self.part_path(t, pid).unlink(missing_ok=True)
                removed += 1
        for tmp in self.root.glob("*/.part-*.tmp"):
            tmp.unlink(missing_ok=True)
        return removed

    # ------------------------------------------------------------------ writing
    def write_part(self, part_id: str, robots: pd.DataFrame | None, runs: pd.DataFrame,
                   history: pd.DataFrame | None = None, events: pd.DataFrame | None = None,
                   payments: pd.DataFrame | None = None, sites: pd.DataFrame | None = None,
                   configs: pd.DataFrame | None = None, chain: pd.DataFrame | None = None,
                   keys: Iterable[str] = ()) -> None:
        """Write one part: the data tables (robots, history, events, payments, sites, configs, chain) first, then
        the runs record with their checksums and row counts, last.  ``keys``: the condition keys' columns.
        Every column's unit and description (``store.dictionary``) go into the Parquet field metadata."""
        keys = list(keys)
        if self.part_path("runs", part_id).exists():
            raise StoreError(f"{self.root}: part {part_id} is already committed")
        tables = {"robots": robots, "history": history, "events": events, "payments": payments,
                  "sites": sites, "configs": configs, "chain": chain}
        sums: dict[str, str | int] = {}
        for t in DATA_TABLES:
            df = tables[t]
            if t in OPTIONAL_TABLES and (df is None or not len(df)):
                continue
            sha, rows = "", 0
            if df is not None and len(df):
                path = self.part_path(t, part_id)
                path.parent.mkdir(exist_ok=True)
                write_atomic(path, functools.partial(write_table, t, df, keys=keys))
                sha, rows = sha256_file(path), len(df)
                if self._cache is not None:  # the bytes it hashed are the file's: no need to read them again
                    self._cache.put("sha256", path, sha)
            sums[f"{t}_sha256"], sums[f"{t}_rows"] = sha, rows
        columns = pd.DataFrame({name: [value] * len(runs) for name, value in sums.items()}, index=runs.index)
        self._write_runs(part_id, pd.concat([runs, columns], axis=1), keys)  # at once: assign inserts one by one

    def _write_runs(self, part_id: str, runs: pd.DataFrame, keys: Iterable[str]) -> None:
        """The commit record, its content's digest in its metadata: the digest of the table written, which is
        the table a reader gets back (the file keeps the Arrow schema; every read checks the digest)."""
        table = annotate("runs", pa.Table.from_pandas(runs, preserve_index=False), keys)
        table = table.replace_schema_metadata({**(table.schema.metadata or {}),
                                               RECORD_SHA: record_digest(table).encode()})
        path = write_atomic(self.part_path("runs", part_id),
                            lambda tmp: pq.write_table(table, tmp, write_page_checksum=True))
        if self._cache is not None:  # the record as a reader gets it back, verified: what was just written
            self._cache.put("record", path, table.to_pandas())

    # ------------------------------------------------------------------ integrity
    def _repair_hint(self) -> str:
        return f"run `infomarket store repair {self.root}` to move damaged parts aside (their runs are then rerun)"

    def _read_runs_part(self, path: Path) -> pd.DataFrame:
        """A verified commit record (when caching, the cached frame itself: callers must not modify it)."""
        return self._cached("record", path, lambda: self._read_runs_part_now(path))

    def _read_runs_part_now(self, path: Path) -> pd.DataFrame:
        table = pq.read_table(path, page_checksum_verification=True)
        stored = (table.schema.metadata or {}).get(RECORD_SHA)
        if stored is None:
            if self._record_checksums():
                raise RecordAltered("its checksum is missing (rewritten by something other than infomarket)")
        elif stored.decode() != record_digest(table):
            raise RecordAltered("checksum mismatch: a value was altered after it was committed")
        return table.to_pandas()

    def _record_checksums(self) -> bool:
        if not hasattr(self, "_sums"):
            try:
                self._sums = bool(self.meta().get("record_checksums", False))
            except StoreError:
                self._sums = False
        return self._sums

    def _check_data_part(self, table: str, part_id: str, record: pd.DataFrame,
                         present: bool | None = None) -> str | None:
        """Why the ``table`` part of ``part_id`` does not match its commit record, or None.  ``present``:
        whether its file exists, where the caller listed the folder (a part that is not there needs no
        look).  When caching, a verdict stands while the record is the same object and the file the same."""
        path, known = self.part_path(table, part_id), (False if present is False else None)
        if self._cache is None:
            return integrity.data_part_problem(self, table, path, record, exists=known)
        return self._cache.verdict(path, record, lambda exists: integrity.data_part_problem(
            self, table, path, record, exists=exists), exists=known)

    def verify(self) -> Inspection:
        """Check every committed part against its commit record; list damaged and orphan parts."""
        return integrity.inspect(self)

    def check(self) -> None:
        """Raise StoreDamaged naming the first damaged part (and how many more) and the repair command."""
        found = self.verify()
        if found.damaged:
            first = found.damaged[0]
            more = f" (and {len(found.damaged) - 1} more damaged part(s))" if len(found.damaged) > 1 else ""
            raise StoreDamaged(f"{self.root}: part {first.path} is damaged: {first.why}{more}; "
                               f"{self._repair_hint()}")

    def repair(self) -> tuple[Inspection, list[str]]:
        """Move every damaged part (all its files, the commit record included) and every orphan into
        ``damaged/``; returns the inspection and the paths moved (relative to the store).  Call with the
        lock held.  Nothing is deleted."""
        return integrity.move_aside(self)

    # ------------------------------------------------------------------ reading
    def _require(self) -> None:
        """StoreError unless the folder holds a store: a mistyped path must not read as an empty store."""
        if not self.exists():
            raise StoreError(f"{self.root}: not an infomarket results store (no store.json)")

    def _records(self) -> dict[str, pd.DataFrame]:
        """Every commit record by part id; StoreError for a missing store, StoreDamaged if a record cannot
        be read."""
        self._require()
        out = {}
        for pid, path in sorted(self._parts("runs").items()):
            try:
                out[pid] = self._read_runs_part(path)
            except RecordAltered as exc:
                raise StoreDamaged(f"{self.root}: part {_rel(self.root, path)} is damaged: commit record {exc}; "
                                   f"{self._repair_hint()}") from None
            except Exception as exc:  # noqa: BLE001 - any reader error means damage
                raise StoreDamaged(f"{self.root}: part {_rel(self.root, path)} is damaged: unreadable commit "
                                   f"record ({type(exc).__name__}); {self._repair_hint()}") from None
        return out

    def _read(self, table: str) -> pd.DataFrame:
        records = self._records()
        frames = []
        present = self._part_ids(table) if table != "runs" else set()
        for pid, record in records.items():
            if table == "runs":
                frames.append((pid, record))
                continue
            why = self._check_data_part(table, pid, record, present=pid in present)
            if why:
                raise StoreDamaged(f"{self.root}: part {_rel(self.root, self.part_path(table, pid))} is damaged: "
                                   f"{why}; {self._repair_hint()}")
            path = self.part_path(table, pid)
            if pid in present:
                frames.append((pid, self._cached("frame", path, lambda path=path: pd.read_parquet(path))))
        frames = [(pid, f) for pid, f in frames if len(f)]
        if not frames:
            return pd.DataFrame()
        if self._cache is not None:
            return self._cache.table(table, frames)
        return sort_rows(pd.concat([f for _, f in frames], ignore_index=True))

    def sql(self, query: str, *, skip_damaged: bool = False) -> pd.DataFrame:
        """Run a DuckDB SQL ``query`` over the store's verified parts; returns a pandas DataFrame.

        The tables are views named as in the store (``robots``, ``history``, ``events``, ``payments``,
        ``sites``, ``configs``, ``chain``, ``runs``; docs/data.md) over the committed parts that pass ``verify`` now:
        orphans of an interrupted sweep are never read, and a damaged part raises ``StoreDamaged`` like
        every read (``skip_damaged=True``: leave the damaged parts out and read the others).  The query can
        read those parts' files only and write no file (DuckDB's external access is switched off).  A table
        with no rows in the store has no view.  Needs DuckDB: ``pip install 'infomarket[sql]'``."""
        if not isinstance(query, str):
            raise SqlError(f"Store.sql: the query must be a string of SQL, not {type(query).__name__}")
        if not query.strip():
            raise SqlError("the query is empty; e.g. \"SELECT count(*) FROM robots\"")
        try:
            with interrupts.held():  # DuckDB's import breaks (an abort) when a KeyboardInterrupt lands in it
                import duckdb
        except ImportError:
            raise StoreError("Store.sql needs DuckDB: pip install 'infomarket[sql]'") from None
        self._require()
        self.meta()  # readable, or a StoreError
        found = self.verify()
        if found.damaged and not skip_damaged:
            self.check()
        bad = {p.part for p in found.damaged}
        good = [pid for pid in self.committed() if pid not in bad]
        files = {t: [str(self.part_path(t, pid).resolve()) for pid in good if self.part_path(t, pid).exists()]
                 for t in TABLES}
        return run_sql(duckdb, self.root, {t: f for t, f in files.items() if f}, query)

    def runs(self) -> pd.DataFrame:
        """One row per committed run, ``status`` ``ok`` or ``failed`` (then ``error`` says why)."""
        return self._read("runs")

    def robots(self) -> pd.DataFrame:
        """One row per robot per completed run."""
        return self._read("robots")

    def history(self) -> pd.DataFrame:
        """Wealth every K steps, for the runs that recorded it."""
        return self._read("history")

    def events(self) -> pd.DataFrame:
        """The ledger's event log of the runs swept with ``--events``."""
        return self._read("events")

    def payments(self) -> pd.DataFrame:
        """What each seller received at each deposit (one row per settled transaction), ``--events`` runs."""
        return self._read("payments")

    def sites(self) -> pd.DataFrame:
        """Items per site per run (setups with terrain: food sites and nests, docs/terrain.md)."""
        return self._read("sites")

    def chain(self) -> pd.DataFrame:
        """The chain model's measures, one row per run (runs with ``[chain] consensus = "poa"``)."""
        return self._read("chain")

    def configs(self) -> pd.DataFrame:
        """One row per (experiment, condition, config_hash): the configuration its runs used, as JSON."""
        df = self._read("configs")
        return df.drop_duplicates(["experiment", "condition", "config_hash"]).reset_index(drop=True) if len(df) else df

    def config(self, experiment: str, condition: str = "base"):
        """The configuration (an ``Experiment``) the runs of ``experiment`` [``condition``] used, steps and
        all: ``simulate(store.config(name), seed=row.seed)`` gives exactly the rows of the run ``row`` of
        the runs table."""

        df = self.configs()
        rows = df[(df.experiment == experiment) & (df.condition == condition)] if len(df) else df
        if rows.empty:
            raise StoreError(f"{self.root}: no recorded configuration of {experiment} [{condition}]")
        return validate(json.loads(rows.config.iloc[-1]), f"{self.root}: {experiment} [{condition}]")

    def drop_experiment(self, name: str) -> int:
        """Remove every part holding runs of experiment ``name`` (commit record first, so a crash leaves
        orphans, not damage) and its recorded master seed; other experiments are kept.  Returns how many
        parts were removed.  Call with the lock held."""
        n = 0
        for pid, record in self._records().items():
            if "experiment" not in record.columns or not (record.experiment == name).any():
                continue
            self.part_path("runs", pid).unlink()
            for t in DATA_TABLES:
                self.part_path(t, pid).unlink(missing_ok=True)
            n += 1
        meta = self.meta()
        if name in meta.get("seeds", {}):
            del meta["seeds"][name]
            self._write_meta(meta)
        return n

    def failed(self) -> pd.DataFrame:
        """The committed runs that raised, with their error text."""
        runs = self.runs()
        if runs.empty or "status" not in runs.columns:
            return runs.iloc[0:0]
        return runs[runs.status == FAILED].reset_index(drop=True)

    def completed_runs(self) -> set[tuple[str, str, int]]:
        """Keys of every committed run, failed ones included (a sweep does not rerun them unasked)."""
        runs = self.runs()
        if runs.empty:
            return set()
        return set(zip(runs.experiment.tolist(), runs.condition.tolist(), runs.run.astype(int).tolist()))

    def uncommit_failed(self) -> int:
        """Remove failed runs from their commit records (their parts hold no rows of them), so the next
        sweep reruns them; returns how many.  Call with the lock held."""
        n = 0
        for pid, record in self._records().items():
            if "status" not in record.columns or not (record.status == FAILED).any():
                continue
            keep = record[record.status != FAILED]
            n += len(record) - len(keep)
            if len(keep):  # the condition keys: the columns the dictionary does not list
                keys = [c for c in keep.columns if TABLES_DICT["runs"].column(c) is None]
                self._write_runs(pid, keep.reset_index(drop=True), keys)
            else:  # nothing of this part succeeded: no data part exists, drop the record
                self.part_path("runs", pid).unlink()
        return n
