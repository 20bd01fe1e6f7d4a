"""The results store: a folder of Parquet datasets that sweeps append to and analyses read.

Layout (each part file written atomically, see ``files``)::

    STORE/store.json               format version, package version, creation time
    STORE/robots/part-ID.parquet   one row per robot per run
    STORE/history/part-ID.parquet  wealth of every robot every K steps (when asked)
    STORE/runs/part-ID.parquet     one row per run: the commit record of its part

Columns common to the three tables: ``experiment`` (e.g. ``fig2A``), ``condition`` (a stable id such as
``byzantines=3,market=staking,rotation_angle=40``; ``base`` without a sweep), ``run``, ``seed``, and one
column per condition key (e.g. ``rotation_angle``).  A part counts only once its ``runs`` part exists:
the runs part is written last, so a crash leaves at most an orphan robots/history part, which readers
ignore and the next sweep deletes.  Query with pandas (``Store(path).robots()``) or DuckDB::

    SELECT r.* FROM 'STORE/robots/*.parquet' r JOIN 'STORE/runs/*.parquet' USING (experiment, condition, run)
"""
from __future__ import annotations

import json
import time
from pathlib import Path

import pandas as pd

from .. import __version__
from ..errors import InfomarketError
from .files import write_parquet_atomic

FORMAT = 1
TABLES = ("robots", "history", "runs")
KEY = ["experiment", "condition", "run"]


class StoreError(InfomarketError, ValueError):
    """The folder is not a usable results store (wrong format, incompatible contents)."""


class Store:
    """A results store rooted at ``root`` (created on first write)."""

    def __init__(self, root: str | Path):
        self.root = Path(root)

    # ------------------------------------------------------------------ creation and checks
    @property
    def meta_path(self) -> Path:
        return self.root / "store.json"

    def exists(self) -> bool:
        return self.meta_path.exists()

    def create(self) -> "Store":
        """Create the folder layout (idempotent); refuse a folder that holds something else."""
        if self.exists():
            meta = json.loads(self.meta_path.read_text())
            if meta.get("format") != FORMAT:
                raise StoreError(f"{self.root}: store format {meta.get('format')} is not {FORMAT}")
            return self
        if self.root.exists() and any(self.root.iterdir()):
            raise StoreError(f"{self.root}: exists, is not empty and is not an infomarket results store")
        for t in TABLES:
            (self.root / t).mkdir(parents=True, exist_ok=True)
        tmp = self.meta_path.with_suffix(".tmp")
        tmp.write_text(json.dumps({"format": FORMAT, "package_version": __version__,
                                   "created": time.strftime("%Y-%m-%dT%H:%M:%S%z")}, indent=2))
        tmp.replace(self.meta_path)
        return self

    def _parts(self, table: str) -> dict[str, Path]:
        folder = self.root / table
        if not folder.exists():
            return {}
        return {p.stem.removeprefix("part-"): p for p in folder.glob("part-*.parquet")}

    def committed(self) -> list[str]:
        return sorted(self._parts("runs"))

    def remove_orphans(self) -> int:
        """Delete robots/history parts without a runs part (left by a crash); returns how many."""
        done = set(self._parts("runs"))
        removed = 0
        for t in ("robots", "history"):
            for pid, path in self._parts(t).items():
                if pid not in done:
                    path.unlink(missing_ok=True)
                    removed += 1
        for tmp in self.root.glob("*/.part-*.tmp"):
            tmp.unlink(missing_ok=True)
        return removed

    # ------------------------------------------------------------------ writing
    def write_part(self, part_id: str, robots: pd.DataFrame, runs: pd.DataFrame,
                   history: pd.DataFrame | None = None) -> None:
        """Write one part: robots (and history) first, the runs record last."""
        write_parquet_atomic(robots, self.root / "robots" / f"part-{part_id}.parquet")
        if history is not None and len(history):
            write_parquet_atomic(history, self.root / "history" / f"part-{part_id}.parquet")
        write_parquet_atomic(runs, self.root / "runs" / f"part-{part_id}.parquet")

    # ------------------------------------------------------------------ reading
    def _read(self, table: str) -> pd.DataFrame:
        done = set(self._parts("runs"))
        paths = [p for pid, p in sorted(self._parts(table).items()) if pid in done]
        if not paths:
            return pd.DataFrame()
        df = pd.concat([pd.read_parquet(p) for p in paths], ignore_index=True)
        sort = [c for c in KEY + ["step", "robot"] if c in df.columns]
        return df.sort_values(sort, kind="stable").reset_index(drop=True)

    def runs(self) -> pd.DataFrame:
        """One row per completed run."""
        return self._read("runs")

    def robots(self) -> pd.DataFrame:
        """One row per robot per completed run."""
        return self._read("robots")

    def history(self) -> pd.DataFrame:
        """Wealth every K steps, for the runs that recorded it."""
        return self._read("history")

    def completed_runs(self) -> set[tuple[str, str, int]]:
        runs = self.runs()
        if runs.empty:
            return set()
        return set(zip(runs.experiment, runs.condition, runs.run.astype(int)))
