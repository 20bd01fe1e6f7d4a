"""B runs of one experiment stepped together in one compiled call, then observed in another: the core
of every RL interface.

The agents are the robots whose behaviour is ``attacker`` (``behaviours.attacks``).  An action is a row of
the attacker's own parameters (``ACTIONS`` picks which, default the lie's rotation and whether to collude):
it is written into the run's per-robot parameter array (``bparams``, which the compiled sell and buy
rules read every step), so actions change between calls without recompiling anything and the engine
itself is untouched.  All B runs' ``bparams`` are slices of one [B, n, P] array, so one numpy assignment
sets every agent of every run.

The runs are the engine's own (``engine.batch.Simulations``, the driver sweeps use): ``advance``
steps each world to its ``t_end``, grows the worlds that ran short and names a rule's error as
``Simulation`` does; its finishing call (``observe.observe_all``, one compiled call after the kernel's)
computes every observation, the honest robots' items and every agent's wealth share.  A run built here with seed s is
the run ``simulate(config, seed=s)`` makes, step for step, as long as the actions equal the
configuration's parameters (tests/rl/test_runs.py); chain runs included.
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..behaviours.attacks import POLICY
from ..config.schema import Experiment
from ..engine.params import behaviour_kinds
from ..engine.batch import Simulations
from ..engine.compiling import compile_notice
from ..engine.simulation import as_experiment
from ..errors import ConfigError
from .. import interrupts
from ..generated import compile_marker
from ..registry import behaviours, get_behaviour
from .observe import OBSERVATION
from ..runner.plan import conditions

#: The behaviour whose robots are the agents.
AGENT_BEHAVIOUR = "attacker"
#: The attacker's parameters an action sets by default: the lie's rotation (degrees; 0 is the truth) and
#: whether to collude (>= 0.5: the liars share one rotation and buy each other's offers).  (``withhold``
#: alone would do nothing: an attacker whose gates are all open always lies, rotation 0 included.)
ACTIONS = ("rot_base", "collude")
#: What the attacker knows of the contract, read by the observation (``behaviours.attacks.KNOWN``).
_KNOWN = ("theta", "theta_min", "adaptive")
#: The compiled observation the engine's driver runs once every world is done.
OBSERVE = "infomarket.agents.observe:observe_all"


def select_cell(experiment, cell: Mapping | None = None) -> Experiment:
    """The experiment to run: ``experiment`` (an Experiment, a shipped name, a file or a dict), or, when
    ``cell`` is given, the one condition of its sweep whose keys match ``cell`` (e.g. ``{"defence":
    "theta20", "byzantines": 3}`` of ``attack_search``)."""
    exp = as_experiment(experiment)
    if not cell:
        return exp

    conds = conditions(exp)
    hits = [c for c in conds if all(str(c.keys.get(k)) == str(v) for k, v in cell.items())]
    if len(hits) != 1:
        have = "; ".join(", ".join(f"{k}={v}" for k, v in c.keys.items()) for c in conds)
        raise ConfigError(f"{exp.name}: cell {cell} matches {len(hits)} conditions (one needed); "
                          f"its conditions: {have}")
    return hits[0].config


class Runs:
    """``size`` runs of ``config`` in lockstep, each a world with its own seed (``reset``)."""

    def __init__(self, config, size: int, *, actions=ACTIONS):
        cfg = as_experiment(config)
        if isinstance(size, bool) or not isinstance(size, (int, np.integer)) or size < 1:
            raise ConfigError(f"the number of runs must be a positive integer, got {size!r}")
        self.config = cfg
        self.size = int(size)
        kinds = behaviour_kinds(cfg)
        if AGENT_BEHAVIOUR not in kinds:
            raise ConfigError(f"{cfg.name}: no robot runs `{AGENT_BEHAVIOUR}`, so there are no agents; give a "
                              f"group of Byzantine robots the behaviour `{AGENT_BEHAVIOUR}` (like attack_search)")
        spec = get_behaviour(AGENT_BEHAVIOUR)
        actions = tuple(actions)
        bad = [a for a in actions if a not in spec.params or a in _KNOWN or a == "threshold"]
        if not actions or bad or len(set(actions)) != len(actions):
            raise ConfigError(f"actions {actions}: each must be one of the attacker's policy parameters, once: "
                              f"{', '.join(p[0] for p in POLICY)}")
        self.actions = actions
        ranges = {p[0]: (p[2], p[3]) for p in POLICY}
        self.low = np.array([ranges[a][0] for a in actions], np.float64)
        self.high = np.array([ranges[a][1] for a in actions], np.float64)
        self.columns = np.array([spec.params.index(a) for a in actions], np.int64)
        self.known = np.array([spec.params.index(k) for k in _KNOWN], np.int64)
        self.steps = int(cfg.steps)
        with compile_notice(kinds, cfg.payment.scheme):
            self.sims = Simulations(cfg, range(self.size), finish=OBSERVE)
        first = self.sims.sims[0]
        names = first.behaviour_names
        specs = behaviours()
        self.agents = np.array([i for i, b in enumerate(names) if b == AGENT_BEHAVIOUR], np.int64)
        self.honest = np.array([i for i, b in enumerate(names) if specs[b].honest], np.int64)
        self.default_action = first.world.bparams[self.agents][:, self.columns].copy()
        self.bparams = np.zeros((self.size,) + first.world.bparams.shape)  # every run's parameter rows
        a, o = len(self.agents), len(OBSERVATION)
        self.obs = np.zeros((self.size, a, o), np.float32)
        self.items = np.zeros(self.size, np.int64)
        self.shares = np.zeros((self.size, a))
        self.seeds = np.zeros(self.size, np.int64)
        # the first observation compiles (or loads) observe_all: in a child a signal can stop at once
        interrupts.compiled_apart(lambda: self.reset(np.arange(self.size), np.arange(self.size)),
                                  compile_marker(self.sims.kernel, "runs"))

    @property
    def worlds(self) -> list:
        """Each run's world (the engine's arrays; replaced when the run grows or is reset)."""
        return [s.world for s in self.sims.sims]

    @property
    def clocks(self) -> np.ndarray:
        """Each run's clock (steps simulated so far)."""
        return self.sims.clocks

    def reset(self, which, seeds, observe: bool = True) -> None:
        """Start runs ``which`` afresh with ``seeds`` (the seed ``simulate`` takes), at the configuration's
        parameters, and (``observe``) observe every run (nothing is stepped)."""
        for b, seed in zip(np.asarray(which, np.int64), seeds):
            self.sims.reset(int(b), seed, into={"bparams": self.bparams[b]})
            self.seeds[b] = self.sims.sims[b].seed
        if observe:
            self.advance(self.clocks)

    def act(self, actions: np.ndarray, which=None) -> None:
        """Set the agents' action parameters: ``actions`` [B, agents, len(ACTIONS)] (or [agents, ...] for
        the runs ``which``), clipped to each parameter's range."""
        a = np.clip(np.asarray(actions, np.float64), self.low, self.high)
        rows = self.agents[:, None]
        if which is None:
            self.bparams[:, rows, self.columns] = a
        else:
            self.bparams[np.asarray(which)[:, None, None], rows[None], self.columns[None, None]] = a

    def advance(self, t_end) -> None:
        """Run every world b up to step ``t_end[b]`` (no further than the run's length), then observe all."""
        t_end = np.minimum(np.asarray(t_end, np.int64), self.steps)
        self.sims.advance(t_end, (self.agents, self.known, self.honest, self.steps, self.obs, self.items,
                                  self.shares))
