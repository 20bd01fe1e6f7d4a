"""Argument types shared by every ``infomarket`` subcommand, so each bad value reads the same way."""
from __future__ import annotations

import argparse

from .errors import InfomarketError


class UsageError(InfomarketError, ValueError):
    """A command-line option is wrong (the CLI prints it and exits with code 2)."""


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
