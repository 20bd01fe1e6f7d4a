"""The one-writer lock of a results store (``STORE/store.lock``)."""
from __future__ import annotations

import fcntl
import os
from pathlib import Path

from .errors import StoreError

_HELD: set[Path] = set()  # stores locked by this process (POSIX locks do not conflict within one)


class StoreLock:
    """An exclusive OS lock (``fcntl.lockf``) on ``STORE/store.lock``, refused at once if held.

    POSIX record locks belong to the process: the kernel drops them when it dies, even by SIGKILL (no
    stale lock), and forked workers do not inherit them."""

    def __init__(self, root: Path):
        self.path = root / "store.lock"
        self.fd: int | None = None

    def __enter__(self) -> StoreLock:
        key = self.path.resolve()
        if key in _HELD:
            raise StoreError(f"{self.path.parent}: this process is already writing this store")
        try:
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o666)
        except OSError as exc:
            raise StoreError(f"{self.path.parent}: cannot write there ({exc.strerror or exc})") from None
        try:
            fcntl.lockf(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            raise StoreError(f"{self.path.parent}: another infomarket process is writing this store (it holds "
                             f"{self.path.name}); wait for it to finish and run this command again (a run or sweep "
                             f"can also write a new store elsewhere)") from None
        self.fd = fd
        _HELD.add(key)
        return self

    def __exit__(self, *exc) -> None:
        _HELD.discard(self.path.resolve())
        if self.fd is not None:
            os.close(self.fd)  # closing drops the lock
            self.fd = None
