"""The one way tests start a process (the ``procs`` fixture, or ``Procs`` as a context manager).

Each process starts in a session of its own (``start_new_session``), with Python's default Ctrl-C even
where the test runner's parent left SIGINT ignored, and with ``PYTHONPATH`` leading to the infomarket
under test.  When the fixture ends, passed or failed, every process still alive in each of those
sessions is killed with SIGKILL (the session, not just the process group: infomarket's pool workers
and compile children move into process groups of their own) and reaped, so no test leaves a process
behind.  ``leftovers`` lists what is still alive in a process's session, for tests that check that
a command ended its workers itself.

``HANG`` bounds every wait: it is a guard against a hung process, far above any run time, never a
measure of speed.  tests/test_procs.py checks that no other test file starts a process itself.
"""
from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
from pathlib import Path

import infomarket as im

#: Seconds after which a wait for a process gives up: the process is hung, not slow.
HANG = 1800.0
SRC = str(Path(im.__file__).resolve().parents[1])


def child_env(env: dict | None = None) -> dict:
    """``os.environ`` with ``env`` over it and this checkout's ``src`` first on ``PYTHONPATH``."""
    out = {**os.environ, **(env or {})}
    out["PYTHONPATH"] = os.pathsep.join(p for p in (SRC, out.get("PYTHONPATH", "")) if p)
    return out


def _default_ctrl_c() -> None:  # in the child, before exec: SIGINT as a terminal's shell would leave it
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _ignore_ctrl_c() -> None:  # in the child, before exec: what a script's background job inherits
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def session_members(sid: int) -> list[int]:
    """Live (not zombie) processes whose session is ``sid``."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:  # gone meanwhile
            continue
        fields = stat[stat.rindex(")") + 2:].split()  # state ppid pgrp session ...
        if int(fields[3]) == sid and fields[0] != "Z":
            found.append(int(entry.name))
    return found


def catches(pid: int, sig: int) -> bool:
    """Whether process ``pid`` has a handler for ``sig`` now (Linux: ``SigCgt`` in /proc/PID/status); an
    infomarket command catches SIGTERM once it has started (``interrupts.handling``)."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    mask = int(next(line.split()[1] for line in status.splitlines() if line.startswith("SigCgt:")), 16)
    return bool(mask >> (sig - 1) & 1)


class Procs:
    """Processes started for one test; all killed (their sessions) at ``close``."""

    def __init__(self):
        self.started: list[subprocess.Popen] = []

    def start(self, argv, *, env: dict | None = None, ignore_ctrl_c: bool = False, **popen) -> subprocess.Popen:
        """``subprocess.Popen(argv)`` in a new session; ``env`` is added to ``child_env``;
        ``ignore_ctrl_c``: the child inherits SIGINT ignored (as a script's background job does)."""
        if ignore_ctrl_c:
            popen["preexec_fn"] = _ignore_ctrl_c
        elif signal.getsignal(signal.SIGINT) == signal.SIG_IGN:  # do not pass our parent's choice on
            popen["preexec_fn"] = _default_ctrl_c
        proc = subprocess.Popen([str(a) for a in argv], env=child_env(env), start_new_session=True, **popen)
        self.started.append(proc)
        return proc

    def run(self, argv, *, input: str | None = None, check: bool = False, **popen) -> subprocess.CompletedProcess:
        """Like ``subprocess.run(argv, capture_output=True, text=True)`` (``HANG`` as a hang guard)."""
        popen.setdefault("stdout", subprocess.PIPE)
        popen.setdefault("stderr", subprocess.PIPE)
        popen.setdefault("text", True)
        if input is not None:
            popen["stdin"] = subprocess.PIPE
        proc = self.start(argv, **popen)
        out, err = proc.communicate(input, timeout=HANG)
        done = subprocess.CompletedProcess(proc.args, proc.returncode, out, err)
        if check:
            done.check_returncode()
        return done

    def cli(self, *words, **popen) -> subprocess.Popen:
        """``python -m infomarket.cli WORDS`` started (not waited for)."""
        return self.start([sys.executable, "-m", "infomarket.cli", *words], **popen)

    def leftovers(self, proc: subprocess.Popen) -> list[int]:
        """The processes still alive in ``proc``'s session (its workers, its children), ``proc`` included."""
        return session_members(proc.pid)

    def close(self) -> None:
        for proc in self.started:
            for pid in {proc.pid, *session_members(proc.pid)}:
                for kill in (os.killpg, os.kill):
                    with contextlib.suppress(ProcessLookupError, PermissionError):
                        kill(pid, signal.SIGKILL)
        for proc in self.started:
            with contextlib.suppress(subprocess.TimeoutExpired):
                proc.wait(timeout=HANG)
            for pipe in (proc.stdin, proc.stdout, proc.stderr):
                if pipe is not None:
                    with contextlib.suppress(OSError):
                        pipe.close()
        self.started.clear()

    def __enter__(self) -> Procs:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
