"""What the bad-input tests share: a command refused with one error line and exit 2, no traceback."""
from __future__ import annotations

import pytest

from infomarket.cli import main

ERROR = "infomarket: error: "


def refused(capsys, argv: list[str], *words: str) -> str:
    """``main(argv)`` exits 2 with one error line holding ``words``, and no traceback; that line."""
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse's errors leave through the parser
        code = exc.code
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count(ERROR) == 1 and "Traceback" not in err, err
    line = err[err.index(ERROR):]
    assert all(w in line for w in words), line
    return line


def never(*args, **kwargs):
    """Stands in for the work a refused command must not start."""
    pytest.fail("started work instead of refusing the input")
