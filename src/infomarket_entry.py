"""The ``infomarket`` command's entry point (``[project.scripts]``), outside the package on purpose.

Importing ``infomarket`` takes seconds (numpy, numba, LLVM, pandas, pydantic), and any entry inside the
package runs only after that import: a Ctrl-C during it ended the command with Python's traceback.  This
module imports nothing heavy.  Until the command's own handling takes over (``infomarket.interrupts``,
installed by ``infomarket.cli.main``), SIGINT and SIGTERM end the process at once with the one line and
the exit status of any other stop; nothing has run or been written by then, so nothing is to be kept,
and no exception is raised into a half-done import.
"""
from __future__ import annotations

import os
import signal
import sys

#: What ``infomarket.cli`` prints for a stop (``errors.report("interrupted")``).
MESSAGE = b"infomarket: error: interrupted\n"


def _leave(signum, frame) -> None:
    try:
        os.write(2, MESSAGE)
    finally:
        os._exit(128 + signum)


def main() -> int:
    """``infomarket.cli.main()``, with a stop during its imports ending the command cleanly."""
    for sig in (signal.SIGINT, signal.SIGTERM):  # also where the parent left them ignored, as handling() does
        signal.signal(sig, _leave)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})
    from infomarket.cli import main as run  # the heavy imports: a stop meanwhile ends the process in _leave

    return run()


if __name__ == "__main__":
    sys.exit(main())
