"""Loading a step kernel: which generated module runs a configuration, the marker that says it is compiled,
and the notice on stderr while a first run waits for the compiler (10-30 s, with nothing else to show)."""
from __future__ import annotations

import os
import sys
import threading
import warnings
from contextlib import contextmanager
from pathlib import Path

from numba.core.errors import NumbaPedanticWarning

from ..config.schema import Experiment
from ..generated import compile_marker
from . import specialise
from .params import behaviour_kinds


#: Seconds after which loading the step kernel is taken to be compiling it, and said so on stderr; the
#: environment variable INFOMARKET_COMPILE_NOTICE=0 (set by the command line's --quiet) silences it.
COMPILE_NOTICE_AFTER = 1.0


@contextmanager
def quiet_compiles():
    """Compile inside without numba's pedantic warnings: its IR checks flag the inlined ledger closures
    ("variable ... is not in scope"), a note to numba's developers about its own IR, dozens of lines per
    kernel or rule, nothing a user can act on.  Every other warning passes."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", NumbaPedanticWarning)
        yield


def kernel_for(kinds: tuple[str, ...], config: Experiment):
    """The generated kernel module that runs ``config`` with these behaviours in kind order."""
    return specialise.kernel_module(kinds, config.payment.scheme, config.terrain, config.chain.enabled)


def kernel_marker(config: Experiment) -> Path | None:
    """The marker (``generated.compile_marker``) that says the kernel ``Simulation(config)`` runs on is
    compiled and in the cache; None where it cannot say (a kernel outside the cache folder, or one whose
    module does not load: ``Simulation`` then meets the error)."""
    try:
        kernel = kernel_for(behaviour_kinds(config), config)
    except Exception:  # noqa: BLE001 - Simulation(config) reports it, named
        return None
    return compile_marker(kernel, "simulation")


@contextmanager
def compile_notice(kinds, scheme: str, after: float | None = None):
    """Say on stderr, once ``after`` seconds have gone by inside the block, that the step kernel is being
    compiled (the first run of a behaviour mix waits 10-20 s with nothing else to show)."""
    after = COMPILE_NOTICE_AFTER if after is None else after
    with quiet_compiles():
        if os.environ.get("INFOMARKET_COMPILE_NOTICE", "1") == "0":
            yield
            return
        with _notice(kinds, scheme, after):
            yield


@contextmanager
def _notice(kinds, scheme: str, after: float):
    names = "+".join(str(k) for k in dict.fromkeys(kinds))

    def say() -> None:
        print(f"compiling the step kernel for {names} / {scheme} (once on this machine: later runs load it "
              f"from the cache)...", file=sys.stderr, flush=True)

    timer = threading.Timer(after, say)
    timer.daemon = True
    timer.start()
    try:
        yield
    finally:
        timer.cancel()
