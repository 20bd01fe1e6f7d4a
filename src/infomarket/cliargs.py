"""Argument types shared by every ``infomarket`` subcommand, so each bad value reads the same way."""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

from .errors import UsageError, report

__all__ = ["Parser", "UsageError", "at_least", "fraction", "seed_value", "writable_dir", "writable_file"]


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


def writable_file(path: str | Path, option: str = "--out") -> Path:
    """Check that file ``path`` can be written (its folder exists and takes new files; an existing file is
    writable), before any work; creates nothing."""
    path = Path(path)
    if path.is_dir():
        raise UsageError(f"{option} {path}: is a directory; give a file name")
    folder = path.parent
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


def fraction(text: str) -> float:
    """A number in (0, 1]."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not 0 < value <= 1:
        raise argparse.ArgumentTypeError(f"must be in (0, 1], got {text}")
    return value


def dask_client(address: str, option: str = "--dask"):
    """A dask.distributed Client of the scheduler at ``address``; a missing Dask or a scheduler that does not
    answer is a UsageError naming ``option``."""
    try:
        from distributed import Client  # only when a command is sent to Dask: distributed is slow to import
    except ImportError:
        raise UsageError("Dask is not installed: pip install 'infomarket[dask]'") from None
    try:
        return Client(address, timeout="5s")
    except (OSError, TimeoutError) as exc:
        raise UsageError(f"{option} {address}: no Dask scheduler answers there ({exc})") from None
