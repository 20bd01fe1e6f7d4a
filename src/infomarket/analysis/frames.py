"""The three tables an analysis reads (robots, history, runs), from a results store or from DataFrames.

Every analysis function takes plain DataFrames so that notebooks can pass their own; ``Frames.of``
accepts a ``Store``, a path to one, a ``Frames``, a dict of tables, or a robots DataFrame alone, so the
report code and a notebook load data the same way.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from ..errors import InfomarketError, InputTypeError
from ..store import Store, StoreError


class MissingDataError(InfomarketError, LookupError):
    """The tables hold no data for what was asked (e.g. a figure whose experiments were never run)."""


@dataclass(frozen=True)
class Frames:
    """The robots, history and runs tables of one store (empty DataFrames where absent)."""

    robots: pd.DataFrame = field(default_factory=pd.DataFrame)
    history: pd.DataFrame = field(default_factory=pd.DataFrame)
    runs: pd.DataFrame = field(default_factory=pd.DataFrame)
    meta: dict = field(default_factory=dict)  # store.json: format, package version, creation time

    @classmethod
    def of(cls, source) -> Frames:
        """The tables from any source an analysis accepts.

        Args:
            source (Frames | pandas.DataFrame | dict | Store | str | pathlib.Path): a ``Frames`` (returned
                as is), a robots DataFrame, a dict of tables (robots, history, runs, meta), a ``Store`` or the
                path of one.

        Raises:
            InputTypeError: ``source`` is none of these, or the dict names an unknown table.
            StoreError: the path or store is not a readable results store.
        """
        if isinstance(source, Frames):
            return source
        if isinstance(source, pd.DataFrame):
            return cls(robots=source)
        if isinstance(source, dict):
            unknown = set(source) - {"robots", "history", "runs", "meta"}
            if unknown:
                raise InputTypeError(f"unknown tables {sorted(unknown)}; expected robots, history, runs")
            return cls(**{k: v for k, v in source.items() if v is not None})
        if isinstance(source, (str, Path)):
            source = Store(source)
        if isinstance(source, Store):
            return cls.from_store(source)
        raise InputTypeError(f"cannot read tables from a {type(source).__name__}")

    @classmethod
    def from_store(cls, store: Store) -> Frames:
        """The robots, history and runs tables and the ``store.json`` of a results store.

        Raises:
            StoreError: the folder is missing, is not a store, or its ``store.json`` is unreadable.
        """
        meta = store_meta(store)
        return cls(robots=store.robots(), history=store.history(), runs=store.runs(), meta=meta)


def store_meta(store: Store) -> dict:
    """The store's ``store.json``, read before its tables: the quick check that the folder is a readable
    store, so a command names a wrong path before it checks its other arguments or reads the tables.

    Raises:
        StoreError: the folder is missing, is not a store, or its ``store.json`` is unreadable.
    """
    if not store.root.exists():
        raise StoreError(f"{store.root}: no such folder")
    if not store.exists():
        raise StoreError(f"{store.root}: not an infomarket results store (no store.json)")
    try:
        return json.loads(store.meta_path.read_text())
    except (OSError, ValueError) as exc:
        raise StoreError(f"{store.meta_path}: unreadable ({exc})") from None


def experiment(table: pd.DataFrame, name: str) -> pd.DataFrame:
    """The rows of one experiment (e.g. ``fig3A``); empty if the table has none or no such column."""
    if table.empty or "experiment" not in table.columns:
        return table.iloc[0:0]
    return table[table["experiment"] == name]


def require(table: pd.DataFrame, name: str, columns: tuple[str, ...] = ()) -> pd.DataFrame:
    """Like ``experiment`` but raises ``MissingDataError`` when there are no rows or a column is absent.

    A column that is all missing values counts as absent: tables concatenated from several experiments
    carry every experiment's columns, filled with NaN where an experiment has none."""
    rows = experiment(table, name)
    if rows.empty:
        raise MissingDataError(f"no {name} rows in the store")
    missing = [c for c in columns if c not in rows.columns or rows[c].isna().all()]
    if missing:
        raise MissingDataError(f"{name}: missing columns {', '.join(missing)}")
    return rows


def composition(robots: pd.DataFrame) -> str:
    """The swarm of a panel as the paper writes it under each box plot, e.g. ``24 naive + 1 saboteur``.

    Counts are per run (the median over runs, as every run of a panel has the same swarm); honest
    behaviours come first; Byzantine behaviour names take a plural (``3 scaboteurs``)."""
    run = [c for c in ("condition", "run") if c in robots.columns]
    per_run = robots.groupby([*run, "behaviour"], observed=True).size().groupby("behaviour").median()
    honest = robots.groupby("behaviour", observed=True)["honest"].first()
    order = sorted(per_run.index, key=lambda b: (not bool(honest[b]), b))

    def term(b: str) -> str:
        n = int(per_run[b])
        return f"{n} {b}{'s' if n > 1 and not honest[b] else ''}"

    return " + ".join(term(b) for b in order)
