"""A robot's own state on disk: its key (a file only it may read) and its open sales.

The agent writes its state before every message it sends that commits it (an offer, an acceptance, a
deposit signature), so that an agent killed at any moment and started again finds the same key, the
same offers (same salt, hence the same committed hash) and every light contract it signed or received
but had not yet revealed. Writes are atomic (a temporary file, flushed, then renamed).
"""
from __future__ import annotations

import json
import os
import secrets
from pathlib import Path

from eth_account import Account

from ..errors import UsageError

KEY_FILE = "key"
STATE_FILE = "state.json"


def load_or_create_key(folder: Path) -> bytes:
    """The robot's private key: read from ``folder/key``, or created there with mode 0600 (never
    readable by another user; an existing key file readable by others is refused)."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / KEY_FILE
    try:
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    except FileExistsError:
        if path.stat().st_mode & 0o077:
            raise UsageError(f"{path} is readable by other users: chmod 600 it") from None
        key = bytes.fromhex(path.read_text().strip())
        Account.from_key(key)  # a corrupt key file fails here, named
        return key
    key = secrets.token_bytes(32)
    with os.fdopen(fd, "w") as f:
        f.write(key.hex())
        f.flush()
        os.fsync(f.fileno())
    return key


class AgentState:
    """``tasks``: task id -> what this robot did for it (JSON-able dicts), kept across restarts."""

    def __init__(self, folder: Path):
        self.path = folder / STATE_FILE
        self.tasks: dict[str, dict] = {}
        if self.path.exists():
            self.tasks = json.loads(self.path.read_text()).get("tasks", {})

    def get(self, task_id: int) -> dict | None:
        return self.tasks.get(str(task_id))

    def put(self, task_id: int, record: dict) -> None:
        """Store ``record`` for ``task_id`` and write the whole state to disk before returning."""
        self.tasks[str(task_id)] = record
        tmp = self.path.with_suffix(".tmp")
        with open(tmp, "w") as f:
            json.dump({"tasks": self.tasks}, f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, self.path)

    def unrevealed(self) -> list[tuple[int, dict]]:
        """Sales whose light contract this robot holds but whose reveal it has not seen land."""
        return [(int(k), r) for k, r in self.tasks.items() if r.get("kind") == "sell" and r.get("lc")
                and "result" not in r]
