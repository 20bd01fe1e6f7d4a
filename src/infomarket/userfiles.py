"""Reading a file a user named, checked before it is trusted.

A path given on the command line or found in a store may be anything: a folder, a FIFO, a device that never
ends (``/dev/zero``), a file of gigabytes.  ``read_bytes`` reads only a regular file, and no more than a
limit: what is too big for its kind is refused by its size, before a byte of it is held in memory.
"""
from __future__ import annotations

import os
import stat
from pathlib import Path

#: The largest experiment file, store.json or declaration file read (real ones are a few KiB).
MAX_TEXT_BYTES = 4 * 2**20


def read_bytes(path: str | Path, error: type[Exception], what: str = "file", limit: int = MAX_TEXT_BYTES) -> bytes:
    """The bytes of the regular file ``path``, at most ``limit`` of them; anything else raises ``error`` with
    one message naming the path and the problem."""
    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))  # a FIFO with no writer must not block
    except OSError as exc:
        raise error(f"{path}: cannot read the {what} ({exc.strerror or exc})") from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            kind = "a directory" if stat.S_ISDIR(info.st_mode) else "not a regular file (a device, a pipe or a socket)"
            raise error(f"{path}: {kind}; the {what} must be a regular file")
        if info.st_size > limit:
            raise error(f"{path}: {info.st_size:,} bytes; a {what} is at most {limit:,} bytes")
        with os.fdopen(os.dup(fd), "rb") as fh:
            data = fh.read(limit + 1)  # a file that grew since fstat is cut off here, not read whole
    except OSError as exc:
        raise error(f"{path}: cannot read the {what} ({exc.strerror or exc})") from None
    finally:
        os.close(fd)
    if len(data) > limit:
        raise error(f"{path}: more than {limit:,} bytes; a {what} is at most {limit:,} bytes")
    return data


def read_text(path: str | Path, error: type[Exception], what: str = "file", limit: int = MAX_TEXT_BYTES) -> str:
    """``read_bytes`` decoded as UTF-8 (a byte-order mark dropped); bytes that are not UTF-8 raise ``error``."""
    try:
        return read_bytes(path, error, what, limit).decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise error(f"{path}: the {what} is not UTF-8 text ({exc.reason} at byte {exc.start})") from None
