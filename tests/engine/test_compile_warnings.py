"""Compiling a step kernel shows no numba pedantic warnings: numba's notes about its own IR are not the
user's to act on, and a first run printed dozens of lines of them."""
import re
import warnings

from numba.core.errors import NumbaIRAssumptionWarning, NumbaPerformanceWarning

from infomarket.engine.compiling import compile_notice

#: numba styles its warnings' text with terminal codes wherever colorama is installed (the docs extra's griffe
#: brings it): which warnings pass is the question here, not how they are styled
STYLE = re.compile(r"\x1b\[[0-9;]*m")


def test_pedantic_warnings_are_silenced_while_compiling_and_others_are_not(monkeypatch):
    monkeypatch.setenv("INFOMARKET_COMPILE_NOTICE", "1")
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        with compile_notice(["naive"], "delayed", after=60.0):
            warnings.warn("variable 'x.1' is not in scope", NumbaIRAssumptionWarning, stacklevel=1)
            warnings.warn("a loop was not vectorised", NumbaPerformanceWarning, stacklevel=1)
        warnings.warn("after the compile", NumbaIRAssumptionWarning, stacklevel=1)
    assert [STYLE.sub("", str(w.message)).split("\n")[0] for w in seen] == ["a loop was not vectorised",
                                                                             "after the compile"]


def test_quiet_compiles_are_silenced_too(monkeypatch):
    monkeypatch.setenv("INFOMARKET_COMPILE_NOTICE", "0")
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        with compile_notice(["naive"], "delayed"):
            warnings.warn("variable 'x.1' is not in scope", NumbaIRAssumptionWarning, stacklevel=1)
    assert seen == []

