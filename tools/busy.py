"""Run a command while N processes spin, as on a loaded machine; the spinners end with it, whatever happens.

    python tools/busy.py N COMMAND...      (make test-busy: two spinners while `make test` runs)

Each spinner is a Python busy loop in a session of its own that dies with this process (Linux
PR_SET_PDEATHSIG), so that none outlives it even if it is killed outright; on a normal end, an error,
Ctrl-C or SIGTERM they are killed here.  The exit status is the command's.
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys

SPIN = """
import ctypes, os, signal, sys
if sys.platform.startswith("linux"):
    ctypes.CDLL(None).prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG: die with tools/busy.py
if os.getppid() != int(sys.argv[1]):
    sys.exit()
while True:
    pass
"""


def _stop(signum, frame):  # SIGTERM: leave through the finally below
    raise SystemExit(128 + signum)


def main(argv: list[str]) -> int:
    if len(argv) < 2 or not argv[0].isdigit():
        print("usage: busy.py N COMMAND...", file=sys.stderr)
        return 2
    signal.signal(signal.SIGTERM, _stop)
    spinners = []
    command = None
    try:
        for _ in range(int(argv[0])):
            spinners.append(subprocess.Popen([sys.executable, "-c", SPIN, str(os.getpid())], start_new_session=True))
        command = subprocess.Popen(argv[1:])
        return command.wait()
    except KeyboardInterrupt:
        return 130
    finally:
        if command is not None and command.poll() is None:
            command.terminate()
            command.wait()
        for s in spinners:
            s.kill()
            s.wait()


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
