"""Counting what a command compiles and runs: every kernel load (a world built on a step kernel, which
compiles it or loads it from the cache), every compile child and every task handed to a worker pool, counted by wrapping
the engine's and runner's entry points (``counting``)."""
from __future__ import annotations

import contextlib
from concurrent.futures import ProcessPoolExecutor

from infomarket import interrupts
from infomarket.engine.batch import Simulations
from infomarket.engine.simulation import Simulation


@contextlib.contextmanager
def counting(monkeypatch):
    """Yield a dict counting, while the block runs: ``worlds`` (``Simulation`` and ``Simulations`` made: a
    run, a warm-up or a kernel's preflight), ``compile_children`` (``interrupts.compiled_together``) and
    ``submitted`` (tasks handed to a local worker pool, whose first starts its processes)."""
    counts = {"worlds": 0, "compile_children": 0, "submitted": 0}

    def counted(key, original):
        def call(*args, **kwargs):
            counts[key] += 1
            return original(*args, **kwargs)
        return call

    for cls in (Simulation, Simulations):
        monkeypatch.setattr(cls, "__init__", counted("worlds", cls.__init__))
    monkeypatch.setattr(interrupts, "compiled_together", counted("compile_children", interrupts.compiled_together))
    monkeypatch.setattr(ProcessPoolExecutor, "submit", counted("submitted", ProcessPoolExecutor.submit))
    yield counts
