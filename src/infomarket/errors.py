"""Exception hierarchy, and the one way the command line reports an error.

One root, ``InfomarketError``, so callers can catch everything the package raises on purpose.  Errors that
are the user's to fix (a configuration, an option, a store) are also ``ValueError``s: the command line
prints them with ``report`` (one line ``infomarket: error: ...`` on stderr, no traceback) and exits 2.
"""
from __future__ import annotations

import sys

EXIT_USAGE = 2
EXIT_FAILED = 1


class InfomarketError(Exception):
    """Root of every error infomarket raises deliberately."""


class ConfigError(InfomarketError, ValueError):
    """An experiment file or configuration is malformed; the message names the key and what is allowed."""


class UsageError(InfomarketError, ValueError):
    """A command-line option is wrong (the CLI prints it and exits with code 2)."""


class SimulationError(InfomarketError, RuntimeError):
    """The compiled kernel reported a condition it cannot recover from (see state.flags)."""


def exit_code(exc: BaseException) -> int:
    """2 for bad input (an InfomarketError that is a ValueError), 1 for anything else."""
    return EXIT_USAGE if isinstance(exc, InfomarketError) and isinstance(exc, ValueError) else EXIT_FAILED


def report(error: str | BaseException, code: int | None = None) -> int:
    """Print ``infomarket: error: MESSAGE`` on stderr and return the exit status to use: ``code``, or for
    an exception ``exit_code(error)``, or 2 for a message.  Every command-line error goes through here."""
    if code is None:
        code = exit_code(error) if isinstance(error, BaseException) else EXIT_USAGE
    print(f"infomarket: error: {error}", file=sys.stderr, flush=True)
    return code
