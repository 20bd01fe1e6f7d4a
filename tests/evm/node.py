"""A real JSON-RPC node for the tests: Hardhat Network, pinned in tools/node (package.json and
package-lock.json, installed by `make node`, which CI runs), started on a free port and stopped after.

``running_node()`` installs it with ``npm ci`` when tools/node/node_modules is missing and skips the
calling test only when node or npm is absent from the machine.
"""
from __future__ import annotations

import contextlib
import fcntl
import shutil
import socket
import subprocess
import time
from pathlib import Path

import pytest

from ..procs import HANG, Procs

TOOLS = Path(__file__).resolve().parents[2] / "tools" / "node"


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def _install(procs: Procs, npm: str, binary: Path) -> None:
    """``npm ci`` once when the node is missing.  Under a file lock: two test processes (pytest -n 2) that
    both found it missing would otherwise run ``npm ci`` in the same folder at once, and ``npm ci`` first
    deletes the other's node_modules."""
    with open(TOOLS / ".install.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
        if not binary.exists():
            procs.run([npm, "ci", "--no-audit", "--no-fund"], cwd=TOOLS, check=True)


@contextlib.contextmanager
def running_node():
    """Yield the URL of a fresh Hardhat node; stop it afterwards."""
    node, npm = shutil.which("node"), shutil.which("npm")
    if node is None or npm is None:
        pytest.skip("node and npm are not installed: cannot start the JSON-RPC node")
    binary = TOOLS / "node_modules" / ".bin" / "hardhat"
    with Procs() as procs:  # the node, and whatever it started, killed on leaving
        _install(procs, npm, binary)
        port = _free_port()
        url = f"http://127.0.0.1:{port}"
        proc = procs.start([binary, "node", "--hostname", "127.0.0.1", "--port", str(port)], cwd=TOOLS,
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        from web3 import Web3

        w3 = Web3(Web3.HTTPProvider(url))
        deadline = time.monotonic() + HANG
        while not w3.is_connected():
            if proc.poll() is not None:
                raise RuntimeError(f"the node exited: {proc.stderr.read().decode()[-2000:]}")
            if time.monotonic() > deadline:
                raise RuntimeError(f"the node did not answer at {url} within {HANG:.0f} s: it hangs")
            time.sleep(0.2)
        yield url
