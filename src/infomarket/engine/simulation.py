"""The engine's host side: build a world, call the compiled kernel, grow logs, collect results.

``Simulation`` is stateful (``step``/``run``, used by the viewer); ``simulate`` runs one experiment
once and returns a ``Result`` of pandas DataFrames; ``engine.batch.Simulations`` steps many runs of one
configuration in one compiled call (sweeps, the attack search, the RL interface).  No Python runs per
robot per step: the kernel advances the whole swarm for as many steps as asked in one call.
"""
from __future__ import annotations

import copy
import functools
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from ..config.schema import Experiment
from ..config import sizes
from ..config.load import load_experiment
from ..errors import ArgumentError, ConfigError, InputTypeError, SimulationError
from ..registry import behaviours
from . import specialise
from .. import interrupts
from ..generated import compile_marker
from ..seeds import MAX_SEED
from ..state.flags import ErrorFlags
from .compiling import compile_notice, kernel_for
from .build import build_world, make_room, room_of, with_room
from .lists import typed_list
from .params import behaviour_kinds, behaviour_table, build_params
from .world import EVENT_NAMES, SITE_NAMES, STATE_NAMES, headings, kernel_view
from ..config.load import validate


#: Robot-steps one kernel call may run (``Simulation.advance_to``): a bound on the work between two
#: moments when Python can act on a signal, small beside a run and large beside a call's own cost.
CALL_ROBOT_STEPS = 1 << 17


#: Empty tables of a run that recorded nothing, made once per table and world type (whose spec fixes the
#: dtypes) and copied: most runs of a study record no events or history, and making an empty DataFrame
#: cost more than copying one.
_EMPTY: dict = {}


def _empty(key, make) -> pd.DataFrame:
    if key not in _EMPTY:
        _EMPTY[key] = make()
    return _EMPTY[key].copy()


@functools.lru_cache(maxsize=64)
def _categories(names: tuple[str, ...]) -> pd.Categorical:
    """The robots' behaviours as a categorical column, made once per swarm (the same run after run); a
    DataFrame made from a dict copies it, so no result shares it."""
    return pd.Categorical(list(names))


@dataclass
class Result:
    """What one run produced.  ``robots``: one row per robot; ``history``: wealth every K steps (long
    format, empty unless asked); ``events``: the ledger's event log and ``payments``: what each seller
    received at each deposit, one row per settled transaction (both empty unless events are recorded)."""

    config: Experiment
    seed: int
    robots: pd.DataFrame
    history: pd.DataFrame
    events: pd.DataFrame
    steps: int
    compile_seconds: float
    run_seconds: float
    totals: dict = field(default_factory=dict)
    payments: pd.DataFrame = field(default_factory=pd.DataFrame)

    @property
    def steps_per_second(self) -> float:
        """Simulated steps per wall-clock second of running (compilation excluded); infinite for an instant run."""
        return self.steps / self.run_seconds if self.run_seconds > 0 else float("inf")


class Simulation:
    """One simulated swarm.  ``Simulation(cfg, seed).run()`` → Result; ``step(k)`` advances k steps.

    The step it runs: ``engine/loop_template.py`` (the loop, in the order of docs/model.md §3), whose
    pieces are all in ``engine/step.py``; ``self.kernel_source`` is the generated module the loop was
    compiled from (the template specialised to this experiment's rules and step options).  The state
    it steps is ``self.world`` (``engine.world``: parameters, swarm, ledger and log side by side).

    Example:
        >>> sim = Simulation("fig2A", seed=1)
        >>> sim.step(40)
        >>> sim.clock, len(sim.result().robots)
        (40, 25)
    """

    def __init__(self, config: Experiment | str | Path, seed: int | None = None, *, record_events: bool = False,
                 history_every: int | None = None, kernel_kinds: tuple[str, ...] | None = None):
        """``kernel_kinds``: the behaviours the step kernel is compiled for, in kind order, when it is to hold
        more than this experiment's own (``checks`` runs many small swarms on one kernel); the rules called,
        hence the run, are the same."""
        config = as_experiment(config)
        self.config = config
        self.record_events = record_events
        self.kinds = behaviour_kinds(config) if kernel_kinds is None else _checked_kinds(config, kernel_kinds)
        self._history = config.history_every if history_every is None else _checked_history(history_every,
                                                                                              config.steps)
        self._room_key = (self.kinds, config.payment.scheme, config.terrain, config.chain.enabled, record_events,
                          tuple((g.behaviour, g.count) for g in config.swarm.groups))
        self._kernel: Any = None  # the generated module of the compiled loop, loaded by reset
        self._params = build_params(config, behaviour_table(config, self.kinds)[1])  # the same for every run
        self.reset(config.seed if seed is None else seed)
        t0 = time.perf_counter()
        try:
            with compile_notice(self.kinds, config.payment.scheme):
                self._kernel = kernel_for(self.kinds, config)
                self._view = interrupts.compiled_apart(self._load, compile_marker(self._kernel, "simulation"))
        except Exception as exc:  # a rule that keeps the kernel from compiling: named
            raise _explained(config, self.seed, exc) from exc
        self.compile_seconds = time.perf_counter() - t0

    def reset(self, seed: int, into: dict | None = None) -> None:
        """Start afresh at step 0 with ``seed``: the run ``Simulation(config, seed)`` makes, on the kernel
        already loaded.  The world starts with the room this process's earlier runs of the same kernel
        grew to (``build.with_room``), so a batch of runs grows its arrays once, not in every run.
        ``into``: field -> array the world is to use instead of its own (its values copied in; the RL
        interface keeps every run's behaviour parameters in one array)."""
        self.seed = checked_seed(seed)
        self.rng = np.random.default_rng(self.seed)
        world, self.behaviour_names = build_world(self.config, self.rng, record_events=self.record_events,
                                                  history_every=self._history, kinds=self.kinds,
                                                  params=self._params)
        world = with_room(world, _ROOM.get(self._room_key))
        if into:
            for name, array in into.items():
                array[...] = getattr(world, name)
            world = world._replace(**into)
        self.world = world
        self._view = kernel_view(world) if self._kernel is not None else None
        self.run_seconds = 0.0

    def __copy__(self) -> Simulation:
        """A shallow copy sharing this one's world arrays and loaded kernel (``another`` resets it at once)."""
        sim = object.__new__(type(self))
        sim.__dict__.update(self.__dict__)
        return sim

    def __getstate__(self) -> dict:
        """What a pickle (or a deep copy) keeps: the configuration, the seed, the random generator and the world
        at its step; the loaded kernel (a module) is left out and loaded again from the cache on unpickling."""
        state = self.__dict__.copy()
        state.pop("_kernel", None)
        state.pop("_view", None)
        return state

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        with compile_notice(self.kinds, self.config.payment.scheme):
            self._kernel = kernel_for(self.kinds, self.config)
            self._view = interrupts.compiled_apart(self._resumed_view, compile_marker(self._kernel, "simulation"))

    def _resumed_view(self):
        """The kernel view of the world as it stands (an unpickled simulation's, at its step): no step runs."""
        return kernel_view(self.world)

    def another(self, seed: int) -> Simulation:
        """A new run of the same configuration with ``seed``, sharing this one's loaded kernel."""
        sim = copy.copy(self)
        sim.compile_seconds = 0.0
        sim.reset(seed)
        return sim

    def _load(self):
        """The world's kernel view, with the view constructor and the step loop compiled or loaded from
        the cache (a call that runs no step); a stop signal meanwhile stops it (``interrupts``)."""
        view = kernel_view(self.world)
        self._step_kernel(view, 0)
        return view

    def _step_kernel(self, view, t_end: int) -> int:
        """One call of the kernel's ``step_all`` on this world alone (a batch of one): its status (DONE,
        NEED_ROOM, or FLAGGED: ``check_flags`` names the error bit)."""
        status = np.zeros(1, np.int64)
        self._kernel.step_all(typed_list([view]), typed_list([self.rng]), np.array([t_end], np.int64), status,
                              np.zeros(1, np.int64))
        return int(status[0])

    @property
    def kernel_source(self) -> Path:
        """The generated module this simulation's loop was compiled from (its header names every source)."""
        return Path(self._kernel.__file__)

    @property
    def clock(self) -> int:
        """The number of steps simulated so far."""
        return int(self.world.clock[0])

    def step(self, k: int = 1) -> None:
        """Advance ``k`` steps (a positive integer)."""
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 1:
            raise ArgumentError(f"step(k): k must be a positive integer number of steps, got {k!r}")
        self.advance_to(self.clock + int(k))

    def advance_to(self, t_end: int) -> None:
        """Run to step ``t_end`` in kernel calls of at most ``CALL_ROBOT_STEPS`` robot-steps each: Python,
        and so Ctrl-C (``interrupts``), gets control between calls, however long the run (the kernel
        resumes exactly where it stopped, so the calls do not change the run)."""
        t0 = time.perf_counter()
        per_call = max(1, CALL_ROBOT_STEPS // max(1, self.world.pos.shape[0]))
        while True:
            stop = min(t_end, self.clock + per_call)
            try:
                status = self._step_kernel(self._view, stop)
                self.check_flags()
            except Exception as exc:  # a rule's error, or an error bit a rule set: named with the step
                raise _explained(self.config, self.seed, exc, self) from exc
            interrupts.check()  # between kernel calls: a stop asked for while the kernel ran
            if status == self._kernel.DONE:
                if stop >= t_end:
                    break
                continue
            self.grow()
        if t_end >= self.config.steps:
            self.remember_room()
        self.run_seconds += time.perf_counter() - t0

    def check_flags(self) -> None:
        """Raise SimulationError if the last call set an error bit (a rule's, or the engine's)."""
        flags = ErrorFlags(int(self.world.flags[0]))
        if flags:
            raise SimulationError(f"step {self.clock}: {flags.describe()}")

    def grow(self) -> None:
        """Grow what the next step might outgrow (the kernel said NEED_ROOM), and remember the room for
        the next run of this kernel in this process."""
        self.world = make_room(self.world)
        self._view = kernel_view(self.world)
        self.remember_room()

    def remember_room(self) -> None:
        """Keep the room this world has (the compiled step also moves a buyer's transactions to a larger
        block of the pool without the host) for the next run of this kernel in this process."""
        room = room_of(self.world, _ROOM.get(self._room_key))
        if room is not None:
            _ROOM[self._room_key] = room

    def run(self, steps: int | None = None) -> Result:
        """Advance to step ``steps`` (default: the experiment's ``steps``) and return the result.

        Args:
            steps: the step to stop at, counted from the start of the run (not from the current clock).

        Returns:
            The run's ``Result``, as ``result()`` gives it.
        """
        self.advance_to(self.config.steps if steps is None else steps)
        return self.result()

    # ------------------------------------------------------------------ results
    def result(self) -> Result:
        """What the run has produced so far, as a ``Result``.

        ``robots`` holds one row per robot (its behaviour, honesty, items, wealth and wealth share);
        ``history``,
        ``events`` and ``payments`` are filled only if the run was asked to record them.  It can be called at
        any
        clock, so a caller stepping the swarm can read it part way.
        """
        w = self.world
        specs = behaviours()
        honest = np.array([specs[b].honest for b in self.behaviour_names])
        total = float(w.balance.sum())
        robots = pd.DataFrame({
            "seed": np.full(len(honest), self.seed, dtype=np.uint64),
            "robot": np.arange(len(honest), dtype=np.int64),
            "behaviour": _categories(tuple(self.behaviour_names)),
            "honest": honest,
            "drift": w.bias.copy(),
            "items_collected": w.items.copy(),
            "wealth": w.balance.copy(),
            "wealth_share": w.balance / total if total > 0 else np.zeros(len(honest)),
        })
        rows = min(w.hist.shape[0], self.clock // w.hist_every) if w.hist_every else 0
        n = w.pos.shape[0]
        history = pd.DataFrame({
            "step": np.repeat((np.arange(rows) + 1) * w.hist_every, n),
            "robot": np.tile(np.arange(n), rows),
            "wealth": w.hist[:rows].ravel(),
        }) if rows else _empty("history", lambda: pd.DataFrame(columns=["step", "robot", "wealth"]))

        def events_of(k: int) -> pd.DataFrame:
            return pd.DataFrame({
                "step": w.ev_step[:k], "kind": pd.Categorical.from_codes(w.ev_kind[:k], EVENT_NAMES),
                "buyer": w.ev_buyer[:k], "seller": w.ev_seller[:k], "site": w.ev_site[:k],
                "direction_deg": w.ev_dir[:k], "x": w.ev_x[:k], "y": w.ev_y[:k], "age": w.ev_age[:k],
                "stake": w.ev_stake[:k], "seller_x": w.ev_sx[:k], "seller_y": w.ev_sy[:k],
            })

        def payments_of(k: int) -> pd.DataFrame:
            return pd.DataFrame({
                "step": w.pay_step[:k], "buyer": w.pay_buyer[:k], "seller": w.pay_seller[:k],
                "site": w.pay_site[:k], "weight": w.pay_weight[:k], "amount": w.pay_amount[:k],
            })

        k, j = int(w.ev_count[0]), int(w.pay_count[0])
        events = events_of(k) if k else _empty(("events", type(w)), lambda: events_of(0))
        payments = payments_of(j) if j else _empty(("payments", type(w)), lambda: payments_of(0))
        totals: dict[str, Any] = {"wealth": total, "pots": float(w.pot.sum()), "burned": float(w.burned[0]),
                  "items": int(w.items.sum())}
        if self.config.terrain:
            totals["sites"] = self.site_counts()
        if self.config.chain.enabled:
            totals["chain"] = self.chain_measures()
        return Result(self.config, self.seed, robots, history, events, self.clock, self.compile_seconds,
                      self.run_seconds, totals, payments)

    def chain_measures(self) -> dict:
        """The chain model's measures so far (docs/chain-model.md): blocks made, forks, reorganisations
        and the transactions they took out of the canonical chain, failed transactions, the mean delay
        from a deposit to the block that paid it, and per robot the gas paid on the canonical chain and
        the mean view lag (canonical height minus its head's, per step)."""
        w = self.world
        paid = int(w.chn_delay_count[0])
        steps = max(self.clock, 1)
        return {"blocks": int(w.chn_blocks[0]), "height": int(w.blk_height[w.chn_canon[0]]),
                "forks": int(w.chn_forks[0]), "reorgs": int(w.chn_reorgs[0]),
                "reorganised_tx": int(w.chn_reorg_tx[0]),
                "view_reorgs": int(w.chn_view_reorgs[0]), "failed_tx": int(w.chn_failed[0]),
                "pending_tx": int(w.mp_count[0]), "deposits_paid": paid,
                "mean_payment_delay": float(w.chn_delay_sum[0]) / paid if paid else float("nan"),
                "gas_paid": w.gas_paid.tolist(), "mean_lag": (w.chn_lag_sum / steps).tolist()}

    def site_counts(self) -> list[dict]:
        """Every site (food first, file order) with the items picked up there (food) or deposited
        there (nest) after the transitory period; counted only by the step's terrain variant."""
        w = self.world
        return [{"kind": SITE_NAMES[int(k)], "x": float(xy[0]), "y": float(xy[1]), "radius": float(r),
                 "items": int(c)} for xy, r, k, c in zip(w.sites_xy, w.sites_r, w.sites_kind, w.site_items)]

    def snapshot(self) -> dict:
        """Plain-Python view of the current state, for viewers and inspection.  With the chain model on,
        ``chain`` holds the canonical height, the forks and reorganisations so far, and per robot its
        head's height, its lag (canonical height minus its head's) and its branch (0: on the canonical
        branch; ``ledger.blocklog.chain_views``); else None."""
        w = self.world
        specs = behaviours()
        snap = {"step": self.clock, "pos": w.pos.tolist(), "heading": headings(w).tolist(),
                "state": [STATE_NAMES[s] for s in w.state], "carrying": w.carrying.tolist(),
                "last_site": [SITE_NAMES[s] if s >= 0 else None for s in w.last_site],
                "items": w.items.tolist(), "wealth": w.balance.tolist(),
                "behaviour": list(self.behaviour_names), "honest": [specs[b].honest for b in self.behaviour_names],
                "sites": SITE_NAMES, "chain": None}
        if self.config.chain.enabled:
            from ..ledger.blocklog import chain_views  # chain runs only

            height, lag, branch = chain_views(w)
            snap["chain"] = {"height": int(w.blk_height[w.chn_canon[0]]), "forks": int(w.chn_forks[0]),
                             "reorgs": int(w.chn_reorgs[0]), "head_height": height.astype(int).tolist(),
                             "lag": lag.astype(int).tolist(), "branch": branch.tolist()}
        return snap


#: The room (array capacities) runs of each kernel grew to in this process, by ``Simulation._room_key``:
#: a fresh world of the same kernel starts with it (``build.with_room``).  Capacities never change results.
_ROOM: dict[tuple, dict] = {}


#: How an error raised while compiling or stepping becomes one that names the rule, its file and line,
#: and the step: ``checks.explain``, installed by the package root (the engine cannot import the
#: checkers, which import the engine).  Empty: errors pass as they are.
_EXPLAINERS: list = []
_explaining = threading.local()


def explain_errors_with(explain) -> None:
    """Install ``explain(cfg, seed, exc, sim=None) -> Exception`` (``checks.explain``)."""
    _EXPLAINERS[:] = [explain]


def _explained(cfg, seed: int, exc: Exception, sim=None) -> Exception:
    """``exc`` as the installed explainer words it; as it is while explaining (the explainer reruns the
    run), or when none is installed."""
    if not _EXPLAINERS or getattr(_explaining, "on", False):
        return exc
    _explaining.on = True
    try:
        return _EXPLAINERS[0](cfg, seed, exc, sim, record_events=bool(getattr(sim, "record_events", False)))
    finally:
        _explaining.on = False


def as_experiment(config) -> Experiment:
    """An Experiment from what the Python API takes: an Experiment, a shipped name or a file path (as on the
    command line), or a dict of the experiment file's keys (validated like a file)."""
    if isinstance(config, Experiment):
        return config
    if isinstance(config, dict):

        return validate(config, "simulate()/Simulation() experiment")
    if isinstance(config, (str, Path)):
        return load_experiment(config)
    raise InputTypeError(f"expected an Experiment, a shipped name, a file path or a dict of experiment keys, "
                         f"got {type(config).__name__}")


def _checked_history(every, steps: int) -> int:
    if isinstance(every, bool) or not isinstance(every, (int, np.integer)) or not 0 <= int(every) <= steps:
        raise ConfigError(f"history_every must be an integer in [0, steps = {steps}] (0: no history), got {every!r}")
    return int(every)


def _checked_kinds(config: Experiment, kinds) -> tuple[str, ...]:
    kinds = tuple(kinds)
    own = behaviour_kinds(config)
    missing = [b for b in own if b not in kinds]
    if missing or len(set(kinds)) != len(kinds):
        raise ArgumentError(f"kernel_kinds must name each behaviour once and include the experiment's own; "
                            f"got {kinds!r}, missing {missing!r}")
    if specialise.uses_paths(kinds) != specialise.uses_paths(own):  # paths select another step
        raise ArgumentError(f"kernel_kinds {kinds!r} must keep waypoint paths on or off as {own!r} does")
    return kinds


def checked_seed(seed) -> int:
    """``seed`` as a run's seed (an integer in [0, 2**63 - 1]), else ConfigError."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or not 0 <= int(seed) <= MAX_SEED:
        raise ConfigError(f"seed must be an integer in [0, 2**63 - 1] (as in experiment files and on the "
                          f"command line), got {seed!r}")
    return int(seed)


def simulate(config: Experiment | str | Path, seed: int | None = None, *, steps: int | None = None,
             record_events: bool = False, history_every: int | None = None) -> Result:
    """Run one experiment (an Experiment, a shipped name like ``"fig2D"`` or a file path) once.
    The same configuration and seed give identical results.  ``steps`` is the run's length, exactly as
    the experiment's ``steps`` (it shapes the Lévy step-length table), so ``simulate(cfg, seed, steps=N)``
    reproduces a run stored with ``steps = N``.

    Example:
        >>> res = simulate("fig2A", seed=1, steps=200)
        >>> res.steps, sorted(res.robots.groupby("honest").size().items())
        (200, [(True, 25)])
    """
    config = as_experiment(config)
    if steps is not None:
        if isinstance(steps, bool) or not isinstance(steps, (int, np.integer)) or steps < 1:
            raise ConfigError(f"steps must be a positive integer number of steps, got {steps!r}")
        if steps > MAX_SEED:  # an int64 on the kernel's side
            raise ConfigError(f"steps must be at most 2**63 - 1, got {steps!r}")
        config = config.model_copy(update={"steps": int(steps)})
        too_big = sizes.run_too_big(config, record_events=record_events, history_every=history_every)
        if too_big:  # the Lévy table alone is 16 bytes a step: named before it is allocated
            raise ConfigError(f"steps={steps}: {too_big}")
    return Simulation(config, seed, record_events=record_events, history_every=history_every).run()
