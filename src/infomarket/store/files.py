"""Atomic file writes: a crash or a kill never leaves a half-written results file behind.

Files are created with mode 0666 minus the umask, like any other file a user's program writes (the
temporary-file helpers of the standard library create 0600 files, which other users of a shared machine
cannot read).  ``sha256_file`` is the checksum the results store records for every part it commits.
"""
from __future__ import annotations

import hashlib
import os
import secrets
from collections.abc import Callable
from pathlib import Path

import pandas as pd


def write_atomic(path: str | Path, write: Callable[[Path], object], keep_suffix: bool = False) -> Path:
    """Call ``write(tmp)`` on a fresh temporary file next to ``path``, then rename it to ``path``.

    The temporary file is created (empty) with the umask's permissions before ``write`` replaces its
    contents, so the result has them too; on any error the temporary file is removed.  ``keep_suffix``:
    the temporary name ends in ``path``'s suffix too, for a writer that picks its format by it (a figure's
    ``savefig``)."""
    path = Path(path)
    tmp = path.parent / f".{path.name}.{secrets.token_hex(6)}.tmp{path.suffix if keep_suffix else ''}"
    os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path


def write_parquet_atomic(df: pd.DataFrame, path: str | Path) -> Path:
    """Write ``df`` to ``path`` through a temporary file in the same folder and an atomic rename."""
    return write_atomic(path, lambda tmp: df.to_parquet(tmp, index=False))


def write_text_atomic(text: str, path: str | Path, encoding: str | None = None) -> Path:
    """Write ``text`` to ``path`` atomically (a temporary file, then a rename): a reader sees the old or the new
    file, never part of one.  ``encoding``: as ``Path.write_text``'s (None: the locale's)."""
    return write_atomic(path, lambda tmp: tmp.write_text(text, encoding=encoding))


def sha256_file(path: str | Path) -> str:
    """Hex SHA-256 of a file's bytes."""
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()
