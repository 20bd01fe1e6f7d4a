"""``Store.sql``'s query: DuckDB views over the verified part files, locked so that the query reads those
files only and writes none, run in a thread that Ctrl-C can interrupt (DuckDB does not look at signals)."""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from .. import interrupts
from .errors import SqlError


def run_sql(duckdb, root: Path, files: dict[str, list[str]], query: str) -> pd.DataFrame:
    """Run ``query`` over views named as the tables of ``files`` (table -> its part files); ``duckdb`` is the
    module, imported by the caller (its import must not be interrupted: ``interrupts.held``)."""
    con = duckdb.connect()
    try:
        allowed = []
        for t, paths in files.items():
            con.read_parquet(paths, union_by_name=True).create_view(t)
            allowed += paths
        # the query reads the verified parts and nothing else, and writes nothing (no COPY TO, no
        # ATTACH, no other file): the views' files are the only ones allowed, and that is locked
        con.execute("SET temp_directory = ''")  # no spill files (DuckDB's default is ./.tmp)
        con.execute("SET allowed_paths = ?", [allowed])
        con.execute("SET enable_external_access = false")
        con.execute("SET lock_configuration = true")
        try:
            # in a thread: DuckDB does not look at signals, so Ctrl-C interrupts the query (interrupts.wait_for)
            result = interrupts.wait_for(lambda: con.execute(query), con.interrupt)
            if result is None or result.description is None:  # only ';' or comments: no statement
                raise SqlError(f"the query {query.strip()[:60]!r} holds no SQL statement that returns rows; "
                               f"e.g. \"SELECT count(*) FROM robots\"")
            return result.df()
        except duckdb.Error as exc:
            raise SqlError(f"{root}: the query failed: {exc} (tables: "
                           f"{', '.join(r[0] for r in con.execute('SHOW TABLES').fetchall())})") from None
    finally:
        try:
            con.close()
        except duckdb.Error:  # still busy with a query that Ctrl-C interrupted (interrupts.wait_for)
            pass
