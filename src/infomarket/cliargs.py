"""Argument types shared by every ``infomarket`` subcommand, so each bad value reads the same way."""
from __future__ import annotations

import argparse
import errno
import os
import re
import sys
import tempfile
from pathlib import Path

from .errors import UsageError, printable, report

__all__ = ["Parser", "UsageError", "at_least", "creatable_dir", "fraction", "scheduler_address", "seed_value",
           "study_options", "workers_count", "writable_dir", "writable_file"]


class Parser(argparse.ArgumentParser):
    """argparse, with its errors (unknown option, bad value) reported like every other CLI error."""

    def error(self, message: str):
        """Print the usage and exit with code 2 through ``errors.report``, so a bad option reads like every other
        error."""
        self.print_usage(sys.stderr)
        raise SystemExit(report(f"{self.prog}: {message}"))


def writable_dir(path: str | Path, option: str = "--out") -> Path:
    """Check that folder ``path`` can be created and written to, before any work; creates it (and its
    parents) if needed, so call it after validating everything else."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise UsageError(f"{option} {path}: exists and is not a directory")
    try:
        path.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=path):
            pass
    except OSError as exc:
        raise UsageError(f"{option} {path}: cannot write there ({exc.strerror or exc})") from None
    return path


def creatable_dir(path: str | Path, option: str = "--out") -> Path:
    """Check that folder ``path`` could be created (or, existing, written to) and create nothing: for a
    command that must still refuse its input after this check, and leaves no empty folder when it does.
    The nearest existing folder above ``path`` must take new files, and each missing name must fit."""
    path = Path(path)
    try:
        if path.exists() and not path.is_dir():
            raise UsageError(f"{option} {path}: exists and is not a directory")
        probe, missing = path, []
        while not probe.exists() and probe != probe.parent:
            missing.append(probe.name)
            probe = probe.parent
        if not probe.is_dir():
            raise UsageError(f"{option} {path}: {probe} is not a folder; choose another path")
        longest = os.pathconf(probe, "PC_NAME_MAX") if hasattr(os, "pathconf") else 255
        if any(len(os.fsencode(name)) > longest for name in missing):
            raise UsageError(f"{option} {path}: cannot write there ({os.strerror(errno.ENAMETOOLONG)})")
        with tempfile.TemporaryFile(dir=probe):
            pass
    except OSError as exc:  # a read-only or full folder, a name too long
        raise UsageError(f"{option} {path}: cannot write there ({exc.strerror or exc})") from None
    return path


def writable_file(path: str | Path, option: str = "--out") -> Path:
    """Check that file ``path`` can be written (its folder exists and takes new files; an existing file is
    writable), before any work; creates nothing."""
    path = Path(path)
    if path.is_dir():
        raise UsageError(f"{option} {path}: is a directory; give a file name")
    folder = path.parent
    if folder.exists() and not folder.is_dir():
        raise UsageError(f"{option} {path}: {folder} is not a folder; give a file name in an existing folder")
    if not folder.is_dir():
        raise UsageError(f"{option} {path}: the folder {folder} does not exist; give a file name in an existing folder")
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        raise UsageError(f"{option} {path}: cannot write there ({exc.strerror or exc})") from None
    if path.exists() and not os.access(path, os.W_OK):
        raise UsageError(f"{option} {path}: cannot write there (Permission denied)")
    return path


def seed_value(text: str) -> int:
    """A seed: an integer in [0, 2**63 - 1], as in experiment files and the Python API."""
    from .seeds import MAX_SEED  # argument parsing is imported by every command; seeds only when parsed

    value = at_least(0)(text)
    if value > MAX_SEED:
        raise argparse.ArgumentTypeError(f"must be at most 2**63 - 1 = {MAX_SEED}, got {value}")
    return value


def at_least(low: int):
    """An integer option that must be >= ``low``."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        if value < low:
            raise argparse.ArgumentTypeError(f"must be >= {low}, got {value}")
        return value

    parse.__name__ = f"integer >= {low}"
    return parse


def max_workers() -> int:
    """The most local processes a command may ask for: 8 per core, and at least 32 (more only queue for the
    cores, each holding its own copy of the engine's memory)."""
    return max(32, 8 * (os.cpu_count() or 1))


def workers_count(text: str) -> int:
    """A ``--workers`` value: an integer from 1 to ``max_workers()``.  Commands also use no more
    processes than they have tasks (``--workers 100`` for 2 runs starts 2)."""
    value = at_least(1)(text)
    if value > max_workers():
        raise argparse.ArgumentTypeError(f"must be at most {max_workers()} ({os.cpu_count() or 1} cores here), "
                                         f"got {value}")
    return value


workers_count.__name__ = "number of processes"


def fraction(text: str) -> float:
    """A number in (0, 1]."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not 0 < value <= 1:
        raise argparse.ArgumentTypeError(f"must be in (0, 1], got {text}")
    return value


#: Transports a Dask scheduler address may name (``tcp://host:8786``; no scheme means tcp).
#: ``inproc://HOST/PID/N`` names a scheduler in this very process (a local cluster started with processes=False).
DASK_SCHEMES = ("tcp", "tls", "ws", "wss", "ucx", "inproc")
_LABEL = r"[A-Za-z0-9](?:[A-Za-z0-9-]{0,62}[A-Za-z0-9])?"
_HOST = rf"(?:{_LABEL}(?:\.{_LABEL})*|\[[0-9A-Fa-f:.]+\])"


def scheduler_address(address: str, option: str = "--dask") -> str:
    """``address`` if it reads as a Dask scheduler's address, ``[SCHEME://]HOST[:PORT]`` with a known
    scheme and a port in 1..65535; else a UsageError naming ``option`` (before anything is imported or
    started).  Whether a scheduler answers there is ``dask_client``'s to find out."""
    def bad(why: str) -> UsageError:
        return UsageError(f"{option} {printable(address)[:200]!r}: not a Dask scheduler address ({why}); "
                          f"expected e.g. tcp://host:8786")

    if not isinstance(address, str) or not address.strip():
        raise bad("empty")
    scheme, sep, rest = address.partition("://")
    if not sep:
        scheme, rest = "tcp", address
    if scheme not in DASK_SCHEMES:
        raise bad(f"unknown scheme {scheme!r}; allowed: {', '.join(DASK_SCHEMES)}")
    if scheme == "inproc":
        if not re.fullmatch(rf"{_HOST}/[0-9]+/[0-9]+", rest):
            raise bad("an in-process address reads inproc://HOST/PID/N")
        return address
    m = re.fullmatch(rf"({_HOST})(?::([0-9]+))?/?", rest)
    if not m:
        raise bad("a host name or IP address, then an optional :PORT, is expected")
    if m.group(2) is not None and not 1 <= int(m.group(2)) <= 65535:
        raise bad(f"port {m.group(2)} is not in 1..65535")
    return address


def dask_client(address: str, option: str = "--dask"):
    """A dask.distributed Client of the scheduler at ``address``; a malformed address, a missing Dask or a
    scheduler that does not answer is a UsageError naming ``option``."""
    scheduler_address(address, option)
    try:
        from distributed import Client  # only when a command is sent to Dask: distributed is slow to import
    except ImportError:
        raise UsageError("Dask is not installed: pip install 'infomarket[dask]'") from None
    try:
        return Client(address, timeout="5s")
    except (OSError, TimeoutError, ValueError, TypeError) as exc:  # a scheme Dask lacks, an address it cannot parse
        raise UsageError(f"{option} {address}: no Dask scheduler answers there ({type(exc).__name__}: "
                         f"{printable(str(exc))[:300]})") from None


def study_options(p: argparse.ArgumentParser, out: str, *, required: bool = False, metavar: str | None = None,
                  questions: str | None = None, seed: str | None = None, seed_default: int | None = None) -> None:
    """The options a study's command shares with every other study's, added alike: ``--out`` (the folder
    its files go to; checked by ``analysis.study.out_dir`` before anything runs), ``--questions FILE``
    (its declaration file, read by ``analysis.study.questions_path``) and ``--seed`` (checked by
    ``analysis.study.refuse_declared_seed`` against the declared one), each added when its help is given.

    Args:
        p: the command's parser.
        out: ``--out``'s help: what the folder holds.
        required: ``--out`` must be given (argparse refuses the command without it).
        metavar: ``--out``'s metavar.
        questions: ``--questions``' help (None: the command takes no questions file).
        seed: ``--seed``'s help (None: the command takes no seed).
        seed_default: ``--seed``'s value when it is not given (None: the declared one).
    """
    if questions is not None:
        p.add_argument("--questions", metavar="FILE", help=questions)
    if seed is not None:
        p.add_argument("--seed", type=seed_value, default=seed_default, help=seed)
    p.add_argument("--out", required=required, metavar=metavar, help=out)
