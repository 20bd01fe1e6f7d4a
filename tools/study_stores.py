"""A digest of a study's store: every table's rows, sorted, without what describes a part rather than a run.

Two stores of one study made by two versions of the code (or by one version with other workers) hold the
same runs when their digests are equal: the rows of robots, history, configs and runs, sorted by
experiment, condition and run, hashed as CSV text.  Left out are ``duration_s`` (a timing) and each
table's ``*_sha256`` / ``*_rows`` (the checksum and row count of the part a run is in, which change with
how runs were grouped into parts).

    python tools/study_stores.py STORE [STORE ...]     # one digest per store, and whether they agree
"""
from __future__ import annotations

import hashlib
import sys

import pandas as pd

from infomarket.store import Store

KEYS = ["experiment", "condition", "run", "robot", "step"]


def digest(root) -> str:
    store = Store(root)
    h = hashlib.sha256()
    for name in ("runs", "robots", "history", "configs"):
        df = getattr(store, name)()
        drop = [c for c in df.columns if c == "duration_s" or c.endswith("_sha256") or c.endswith("_rows")]
        df = df.drop(columns=drop)
        by = [k for k in KEYS if k in df.columns]
        df = df.sort_values(by, kind="stable").reset_index(drop=True)[sorted(df.columns)]
        h.update(name.encode())
        h.update(df.to_csv(index=False, float_format="%.17g").encode())
    return h.hexdigest()


def part_names(root) -> str:
    """The store's part files, one per line, sorted (how its runs were grouped into parts)."""
    from pathlib import Path

    return "\n".join(sorted(str(p.relative_to(root)) for p in Path(root).rglob("part-*.parquet")))


def main(argv: list[str]) -> int:
    digests = [digest(p) for p in argv]
    for p, d in zip(argv, digests):
        print(d, p)
    return 0 if len(set(digests)) <= 1 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
