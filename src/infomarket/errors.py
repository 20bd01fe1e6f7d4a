"""Exception hierarchy, and the one way the command line reports an error.

One root, ``InfomarketError``, so callers can catch everything the package raises on purpose.  Errors that
are the user's to fix (a configuration, an option, a store) are also ``ValueError``s: the command line
prints them with ``report`` (one line ``infomarket: error: ...`` on stderr, no traceback) and exits 2.
"""
from __future__ import annotations

import errno
import sys
import warnings
from typing import TextIO

EXIT_USAGE = 2
EXIT_FAILED = 1


class InfomarketError(Exception):
    """Root of every error infomarket raises deliberately."""


class ConfigError(InfomarketError, ValueError):
    """An experiment file or configuration is malformed; the message names the key and what is allowed."""


class UsageError(InfomarketError, ValueError):
    """A command-line option is wrong (the CLI prints it and exits with code 2)."""


class SimulationError(InfomarketError, RuntimeError):
    """The compiled kernel reported a condition it cannot recover from (see state.flags), or a run in
    another process failed."""


class ArgumentError(InfomarketError, ValueError):
    """A function of the Python API was called with a value it cannot take (out of range, wrong length)."""


class InputTypeError(InfomarketError, TypeError):
    """A function of the Python API was given an object of a kind it cannot read."""


class RuleError(InfomarketError, TypeError):
    """A function handed to the registration API cannot be a rule (not a function, wrong arguments)."""


class RuleRunError(InfomarketError, ValueError):
    """A user's rule raised while it ran, or cannot be compiled into the step: the message names the rule,
    its file and line, and the step (``checks.explain_failure``); the user's to fix, so exit 2."""


class RegistrationError(InfomarketError, ValueError):
    """A registration clashes with what is registered (a name taken, rules disagreeing on a default)."""


class PluginError(InfomarketError, ImportError):
    """A plugin (a module or a ``.py`` file of rules) cannot be imported."""


class FormatError(InfomarketError, ValueError):
    """Bytes do not have the layout infomarket writes (e.g. a viewer frame of the wrong size)."""


class ConfigWarning(InfomarketError, UserWarning):
    """A configuration value that is valid but cannot act in this run (e.g. a chain partition after the
    run's end); issued with ``warnings.warn``, and printed by the command line as one line."""


class InternalError(InfomarketError, RuntimeError):
    """A defect of infomarket itself (a damaged package, an impossible state), never the user's to fix."""


def exit_code(exc: BaseException) -> int:
    """2 for bad input (an InfomarketError that is a ValueError), 1 for anything else."""
    return EXIT_USAGE if isinstance(exc, InfomarketError) and isinstance(exc, ValueError) else EXIT_FAILED


def report(error: str | BaseException, code: int | None = None) -> int:
    """Print ``infomarket: error: MESSAGE`` on stderr and return the exit status to use: ``code``, or for
    an exception ``exit_code(error)``, or 2 for a message.  Every command-line error goes through here."""
    if code is None:
        code = exit_code(error) if isinstance(error, BaseException) else EXIT_USAGE
    print(f"infomarket: error: {printable(str(error))}", file=sys.stderr, flush=True)
    return code


def os_error_message(exc: OSError) -> str:
    """One line for an error of the operating system (a full disk, a read-only folder, a name too long, a
    file where a folder must be): what failed, on which path, and why, each path once.  The command line
    prints it with exit code 2: the fix (space, permissions, another path) is the user's; what was
    committed before stays as it was, since every file is written whole and then renamed into place."""
    why = exc.strerror or str(exc) or type(exc).__name__
    paths = [str(p) for p in (exc.filename, exc.filename2) if p is not None]
    where = " -> ".join(dict.fromkeys(paths))
    hint = ""
    if exc.errno in (errno.ENOSPC, errno.EDQUOT):
        hint = "; free some space (what was finished is kept) and run the same command again"
    elif exc.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
        hint = "; choose a folder you can write to"
    elif exc.errno == errno.ENAMETOOLONG:
        hint = "; choose a shorter name"
    elif exc.errno in (errno.ENOTDIR, errno.EISDIR):
        hint = "; a file stands where a folder must be (or the other way round): move it away or choose another path"
    return f"{where}: {why}{hint}" if where else f"{why}{hint}"


def show_warning(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                 file: TextIO | None = None, line: str | None = None) -> None:
    """``warnings.showwarning`` for the command line: a ``ConfigWarning`` as ``infomarket: warning: ...``
    (one line, no source location); any other warning as Python prints it."""
    out = sys.stderr if file is None else file
    if issubclass(category, ConfigWarning):
        print(f"infomarket: warning: {printable(str(message))}", file=out, flush=True)
    else:
        out.write(warnings.formatwarning(message, category, filename, lineno, line))


def printable(text: str, limit: int = 20000) -> str:
    """``text`` safe to print on a terminal: control characters other than newline and tab (ANSI escape
    sequences, carriage returns) are written as ``\\x1b``-style escapes, and it is cut to ``limit`` characters."""
    out = "".join(c if c in "\n\t" or (c.isprintable()) else repr(c)[1:-1] for c in text)
    return out if len(out) <= limit else out[:limit] + f"... ({len(out) - limit} more characters)"
