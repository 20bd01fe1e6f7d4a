"""The swarm's processes: the chain node and one agent per robot, each in a process group of its own.

Every child is started in its own process group (a terminal's Ctrl-C reaches only the swarm command,
which then ends them all) and dies with the swarm on Linux (``PR_SET_PDEATHSIG``), so that no agent or
node outlives a swarm killed outright. ``stop`` sends SIGKILL to each group: an agent's state is on disk
before it sends anything, so there is nothing for it to save.
"""
from __future__ import annotations

import contextlib
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

from ..errors import SimulationError, UsageError
from .. import interrupts
from . import env

NODE_TOOLS = Path(__file__).resolve().parents[3] / "tools" / "node"


def _detached() -> None:  # in the child, before exec
    interrupts.detach()


def start(argv: list[str], log: Path, cwd: Path | None = None) -> subprocess.Popen:
    """``argv`` in a process group of its own, its output appended to ``log``."""
    log.parent.mkdir(parents=True, exist_ok=True)
    with open(log, "ab") as out:
        return subprocess.Popen(argv, stdout=out, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                cwd=cwd, env=env.child_env(),
                                preexec_fn=_detached)


def stop(proc: subprocess.Popen | None) -> None:
    """SIGKILL ``proc``'s process group and reap it."""
    if proc is None:
        return
    interrupts.kill_group(proc.pid)
    with contextlib.suppress(subprocess.TimeoutExpired):
        proc.wait(timeout=5)


def agent_argv(robots: list[int], folder: Path, rpc: str, market: str, drop: float, seed: int,
               controller: bool = False, timeout: float | None = None) -> list[str]:
    """The command of one agent process: ``ros agent`` for one robot (its state in ``folder/robot_N``),
    ``ros host`` for several."""
    if len(robots) == 1:
        who = ["agent", "--robot", str(robots[0]), "--state", str(folder / f"robot_{robots[0]}")]
    else:
        who = ["host", "--robots", ",".join(map(str, robots)), "--state", str(folder)]
    return [sys.executable, "-m", "infomarket.cli", "ros", *who, "--rpc", rpc, "--market", market,
            "--drop", repr(drop), "--seed", str(seed), *(["--controller"] if controller else []),
            *(["--controller-timeout", repr(timeout)] if controller and timeout else [])]


def log_name(robots: list[int]) -> str:
    """An agent process's log: ``robot_N.log``, or ``robots_A-B.log`` for several robots in one process."""
    return f"robot_{robots[0]}.log" if len(robots) == 1 else f"robots_{robots[0]}-{robots[-1]}.log"


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def start_node(log: Path) -> tuple[subprocess.Popen, str]:
    """A Hardhat node (``make node`` installs it in tools/node) on a free port; its URL once it answers."""
    binary = NODE_TOOLS / "node_modules" / ".bin" / "hardhat"
    if not binary.exists() or shutil.which("node") is None:
        raise UsageError(f"no chain node: run `make node` (needs node and npm), or give --rpc URL "
                                f"(looked for {binary})")
    port = _free_port()
    url = f"http://127.0.0.1:{port}"
    proc = start([str(binary), "node", "--hostname", "127.0.0.1", "--port", str(port)], log, cwd=NODE_TOOLS)
    from web3 import Web3

    w3 = Web3(Web3.HTTPProvider(url))
    while not w3.is_connected():
        if proc.poll() is not None:
            raise SimulationError(f"the chain node exited (see {log})")
        time.sleep(0.2)
    return proc, url


def kill(proc: subprocess.Popen) -> None:
    """The ``kill`` fault: SIGKILL the agent, nothing else, and reap it."""
    with contextlib.suppress(ProcessLookupError):
        os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
