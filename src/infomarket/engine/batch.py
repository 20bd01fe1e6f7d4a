"""Many runs of one configuration stepped together: ``Simulations`` runs B worlds of one kernel back to
back in one compiled call (the kernel's own ``step_all``, which steps a single ``Simulation`` as a batch of
one), grows the worlds that ran short and calls again.  Sweeps, the attack search and the RL interface step
their runs through it (docs/performance.md), so a batch pays one kernel load and one Python call per
advance, not one per run.
"""
from __future__ import annotations

import importlib
import time

import numpy as np

from .. import interrupts
from ..errors import ArgumentError, SimulationError
from .lists import put, typed_list
from .simulation import CALL_ROBOT_STEPS, Result, Simulation, _explained


def finish_function(finish: str | None):
    """The compiled ``function(views, extra)`` that ``finish`` (``"module:function"``) names, or None."""
    if not finish:
        return None
    module, name = finish.split(":")
    return getattr(importlib.import_module(module), name)


class Simulations:
    """B runs of one configuration stepped together: ``advance`` runs every world up to its own step in
    one compiled call (back to back), grows the worlds that ran short and calls again, and raises a run's
    error named as ``Simulation`` names it.  Each run is the run ``Simulation(config, seed)`` makes.

    ``finish``: ``"module:function"``, a compiled ``function(views, extra)`` called once every world is
    done (the RL interface's observation: ``advance``), in a call of its own, so that the kernel's code
    is compiled once, in its ``step_all``, whoever steps it."""

    def __init__(self, config, seeds, *, record_events: bool = False, history_every: int | None = None,
                 finish: str | None = None):
        seeds = list(seeds)
        if not seeds:
            raise ArgumentError("Simulations: at least one seed")
        first = Simulation(config, seeds[0], record_events=record_events, history_every=history_every)
        self.config = first.config
        self.sims = [first] + [first.another(s) for s in seeds[1:]]
        self._kernel = first._kernel
        self._finish = finish_function(finish)
        self._views = typed_list([s._view for s in self.sims])
        self._rngs = typed_list([s.rng for s in self.sims])
        self._status = np.zeros(len(self.sims), np.int64)
        self._clocks = np.zeros(len(self.sims), np.int64)
        self._seconds = np.zeros(len(self.sims))  # each run's share of the calls' seconds (``run``)

    @property
    def kernel(self):
        """The kernel module whose ``step_all`` steps these runs."""
        return self._kernel

    def __len__(self) -> int:
        return len(self.sims)

    @property
    def clocks(self) -> np.ndarray:
        """Each run's step (a copy)."""
        return self._clocks.copy()

    def reset(self, b: int, seed: int, into: dict | None = None) -> None:
        """Start run ``b`` afresh with ``seed`` (``Simulation.reset``)."""
        sim = self.sims[b]
        sim.reset(seed, into)
        put(self._views, b, sim._view)
        put(self._rngs, b, sim.rng)
        self._clocks[b] = sim.clock
        self._seconds[b] = 0.0

    def advance(self, t_end, extra=0) -> None:
        """Run world b up to step ``t_end[b]`` (an array, or one step for all), in calls of at most
        ``CALL_ROBOT_STEPS`` robot-steps in all, as ``Simulation.advance_to`` does: Python, and so Ctrl-C
        (``interrupts``), gets control between calls however many and long the runs (each world resumes
        exactly where it stopped, so the calls do not change the runs).  ``finish`` runs after each call
        that leaves every world at its call's step, the last one included.  Seconds are shared among the
        runs by the steps each made."""
        t_end = np.ascontiguousarray(np.broadcast_to(np.asarray(t_end, np.int64), (len(self.sims),)))
        before = self._clocks.copy()
        t0 = time.perf_counter()
        while True:
            target = self._call_targets(t_end)
            try:
                short = self._kernel.step_all(self._views, self._rngs, target, self._status, self._clocks)
            except Exception as exc:  # a rule raised in the step of the run left at -1
                sim = self.sims[int(np.argmax(self._status == -1))]
                raise _explained(sim.config, sim.seed, exc, sim) from exc
            if not short and self._finish is not None:
                self._finish(self._views, extra)
            interrupts.check()  # between kernel calls: a stop asked for while the kernel ran
            if not short:
                if (self._clocks >= t_end).all():
                    break
                continue
            for b in np.flatnonzero(self._status):
                sim = self.sims[b]
                if self._status[b] == self._kernel.FLAGGED:  # an error bit a rule (or the engine) set: named
                    try:
                        sim.check_flags()
                    except SimulationError as exc:
                        raise _explained(sim.config, sim.seed, exc, sim) from exc
                sim.grow()
                put(self._views, b, sim._view)
        made = self._clocks - before
        for b in np.flatnonzero((self._clocks >= self.config.steps) & (before < self.config.steps)):
            self.sims[b].remember_room()  # a run just ended: keep its room for the next ones
        total = int(made.sum())
        if total:
            self._seconds += (time.perf_counter() - t0) / total * made

    def _call_targets(self, t_end: np.ndarray) -> np.ndarray:
        """Each world's step for the next call: the worlds short of ``t_end`` advance by the same number
        of steps, as many as fit in ``CALL_ROBOT_STEPS`` robot-steps; when even one step each does not
        fit, one step for as many of them as fit, in order (one world at the least)."""
        short = np.flatnonzero(self._clocks < t_end)
        target = t_end.copy()
        if not len(short):
            return target
        robots = max(1, self.sims[0].world.pos.shape[0])
        budget = max(1, CALL_ROBOT_STEPS // robots)  # world-steps per call
        each = max(1, budget // len(short))
        target[short] = self._clocks[short]  # the worlds left out of this call stay where they are
        moving = short[:max(1, budget // each)]
        target[moving] = np.minimum(t_end[moving], self._clocks[moving] + each)
        return target

    def run(self) -> list[Result]:
        """Every run to the configuration's ``steps``; their results, in order (each run's ``run_seconds``
        its share of the calls' seconds, by the steps it made)."""
        self.advance(self.config.steps)
        for sim, seconds in zip(self.sims, self._seconds):
            sim.run_seconds = float(seconds)
        return [s.result() for s in self.sims]
