"""The adaptive attacker, a second searcher beside the parametric one: a policy that maps what each
Byzantine robot observes (the RL interface's observation, ``agents.observe.OBSERVATION``) to its action (the
attacker's parameters named by ``actions``, by default the lie's rotation and whether to collude), chosen
anew every ``interval`` steps, trained by evolution strategies through the RL interface's compiled runs
(docs/rl.md, "The adaptive attacker").

Policy: ``action = low + (high - low) * clip(obs . W + b, 0, 1)`` per action column, the same for every
agent.  Linear and clipped rather than squashed: a constant attack, edges included (a 180° lie, collusion
on or off), is a policy with W = 0, and the hand-written Θ-surfer (a rotation proportional to the Θ
applied to the robot, an observed column) is a linear one.

Training: OpenAI-ES (Salimans et al. 2017) with antithetic pairs, rank-normalised fitness and Adam, with
common random numbers: each generation plays its centre and every perturbation on the same ``runs`` run
seeds, so candidates differ only by their policy.  Chosen over CMA-ES on the weights because the policy
has (observations + 1) x actions weights (40 by default) and a cell's budget is a few hundred
evaluations: CMA-ES's covariance needs many more to adapt in that dimension, while the ES estimate
with ranks is invariant to the objective's scale and its state (the weights and Adam's moments) is a few
arrays that a checkpoint stores exactly.  The noise and seeds of generation g derive from the seed and g
alone, so training is deterministic for a seed and a resumed training repeats nothing and skips nothing.
"""
from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..behaviours.attacks import POLICY
from ..errors import ArgumentError, UsageError
from ..agents.observe import OBSERVATION
from ..agents.optim import Adam
from ..agents.runs import ACTIONS
from ..seeds import run_seed
from .adaptive_play import BATCH, Player, check_memory
from .objective import OBJECTIVES
from .space import NAMES
from .study import Cell

_RANGES = {p[0]: (p[2], p[3]) for p in POLICY}
_DEFAULTS = {p[0]: p[1] for p in POLICY}
#: The checkpoint's file name inside the checkpoint folder.
CHECKPOINT = "adaptive-checkpoint.npz"


def _stream(*parts) -> int:
    """A seed stream (``seeds.run_seed``'s condition) of its own for ``parts``; the driver's streams are
    other strings, so the adaptive attacker never plays a selection or confirmation seed while training."""
    return int(hashlib.sha256("/".join(map(str, parts)).encode()).hexdigest()[:15], 16)


def _checked_actions(actions) -> tuple[str, ...]:
    if isinstance(actions, str):
        raise ArgumentError(f"actions={actions!r}: a sequence of the attacker's parameter names, e.g. ({actions!r},)")
    actions = tuple(actions)
    bad = [a for a in actions if a not in NAMES]
    if not actions or bad or len(set(actions)) != len(actions):
        raise ArgumentError(f"actions {actions}: each must be one of the attacker's parameters, once: "
                            f"{', '.join(NAMES)}")
    return actions


@dataclass
class Policy:
    """An adaptive attack: ``weights`` [len(OBSERVATION) + 1, len(actions)] in units of each action's
    range (rows: one per observation column, then the constant), the decision ``interval`` (engine steps)
    and the attacker's other parameters ``base`` (the cell's own where absent).  ``info``: how it was made."""

    weights: np.ndarray
    actions: tuple[str, ...] = ACTIONS
    interval: int = 10
    base: dict = field(default_factory=dict)
    info: dict = field(default_factory=dict)

    def __post_init__(self):
        self.actions = _checked_actions(self.actions)
        self.weights = np.asarray(self.weights, np.float64)
        shape = (len(OBSERVATION) + 1, len(self.actions))
        if self.weights.shape != shape or not np.isfinite(self.weights).all():
            raise ArgumentError(f"policy weights: need a finite array of shape {shape}, got {self.weights.shape}")
        if isinstance(self.interval, bool) or not isinstance(self.interval, (int, np.integer)) or self.interval < 1:
            raise ArgumentError(f"policy interval {self.interval!r}: a positive number of engine steps")
        self.interval = int(self.interval)
        unknown = set(self.base) - set(NAMES)
        if unknown:
            raise ArgumentError(f"policy base: unknown attacker parameters {sorted(unknown)}")
        self.base = {k: float(v) for k, v in self.base.items()}

    @property
    def low(self) -> np.ndarray:
        """Each action's lower bound (the policy's outputs are scaled into [low, high])."""
        return np.array([_RANGES[a][0] for a in self.actions])

    @property
    def high(self) -> np.ndarray:
        """Each action's upper bound."""
        return np.array([_RANGES[a][1] for a in self.actions])

    @classmethod
    def constant(cls, values: dict, actions=ACTIONS, interval: int = 10, base: dict | None = None) -> Policy:
        """The policy that plays ``values`` (action -> parameter value, defaults where absent) whatever it
        observes."""
        actions = _checked_actions(actions)
        w = np.zeros((len(OBSERVATION) + 1, len(actions)))
        for k, a in enumerate(actions):
            lo, hi = _RANGES[a]
            w[-1, k] = (float(values.get(a, _DEFAULTS[a])) - lo) / (hi - lo)
        return cls(w, actions, interval, dict(base or {}))

    def act(self, obs) -> np.ndarray:
        """The action of each agent: ``obs`` [..., len(OBSERVATION)] -> [..., len(actions)]."""
        obs = np.asarray(obs, np.float64)
        u = obs @ self.weights[:-1] + self.weights[-1]
        return self.low + (self.high - self.low) * np.clip(u, 0.0, 1.0)

    def at_rest(self) -> dict[str, float]:
        """The action at an all-zero observation (the constant part of the policy)."""
        return dict(zip(self.actions, self.act(np.zeros(len(OBSERVATION))).tolist()))

    def save(self, path) -> Path:
        """Write the policy as ``.npz`` (the weights, and its settings as JSON), atomically."""
        path = Path(path)
        meta = {"actions": list(self.actions), "interval": self.interval, "base": self.base,
                "observation": list(OBSERVATION), "info": self.info}
        tmp = path.with_name(path.name + ".tmp.npz")
        np.savez(tmp, weights=self.weights, meta=np.array(json.dumps(meta)))
        os.replace(tmp, path)
        return path

    @classmethod
    def load(cls, path) -> Policy:
        """A policy saved by ``save``.

        Raises:
            UsageError: the file is not a policy, or the policy reads another observation than this version's.
        """
        try:
            with np.load(Path(path), allow_pickle=False) as z:
                weights, meta = z["weights"], json.loads(str(z["meta"]))
        except (OSError, KeyError, ValueError) as exc:
            raise UsageError(f"{path}: not an adaptive attacker's policy ({exc})") from None
        if meta.get("observation") != list(OBSERVATION):
            raise UsageError(f"{path}: the policy reads another observation ({meta.get('observation')}); this "
                             f"version observes {list(OBSERVATION)}")
        return cls(weights, tuple(meta["actions"]), meta["interval"], meta["base"], meta.get("info", {}))


def centred_ranks(x: np.ndarray) -> np.ndarray:
    """Ranks scaled to [-0.5, 0.5], ties sharing their mean rank: candidates that played identical runs
    (e.g. perturbations clipped to the same action) must not push the update by their order."""
    x = np.asarray(x, np.float64)
    order = np.argsort(x, kind="stable")
    ranks = np.empty(len(x))
    ranks[order] = np.arange(len(x))
    _, inverse = np.unique(x, return_inverse=True)
    ranks = (np.bincount(inverse, ranks) / np.bincount(inverse))[inverse]
    return ranks / max(len(x) - 1, 1) - 0.5


def es_gradient(fitness: np.ndarray, eps: np.ndarray, sigma: float) -> np.ndarray:
    """The antithetic ES estimate of the fitness gradient: ``fitness`` [2 * pairs], each pair's +eps and
    -eps candidates side by side; ``eps`` [pairs, ...]."""
    u = centred_ranks(fitness)
    return np.tensordot(u[0::2] - u[1::2], eps, axes=1) / (len(eps) * sigma)


def step_scale(actions) -> np.ndarray:
    """Per weight, the scale of its noise and steps relative to the constant's: 1 / sqrt(observation
    columns) for the observation rows, so that a perturbation or a step moves an action by about as much
    whatever the robot observes (observations are in [0, 1]), instead of sqrt(19) times more through the
    19 weights together than through the constant."""
    r = np.full((len(OBSERVATION) + 1, len(actions)), 1.0 / np.sqrt(len(OBSERVATION)))
    r[-1] = 1.0
    return r


def generation_seeds(master: int, seed: int, g: int, runs: int) -> list[int]:
    """The run seeds every candidate of generation ``g`` plays (common random numbers)."""
    stream = _stream("adaptive", "search", seed, g)
    return [run_seed(master, j, stream) for j in range(runs)]


def evaluation_seeds(master: int, seed: int, runs: int) -> list[int]:
    """Fresh run seeds for comparing a trained policy with its start (a stream training never plays)."""
    stream = _stream("adaptive", "evaluation", seed)
    return [run_seed(master, k, stream) for k in range(runs)]


def _noise(seed: int, g: int, shape) -> np.ndarray:
    rng = np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(_stream("adaptive", "noise"), g)))
    return rng.standard_normal(shape)


def fitness(items: np.ndarray, liar: np.ndarray, objective: str) -> np.ndarray:
    """What ES ascends, per episode: fewer honest items, or more wealth for the liars."""
    if objective == "items":
        return -items
    if objective == "liar_wealth":
        return liar
    raise ArgumentError(f"objective {objective!r}: unknown; allowed: {', '.join(OBJECTIVES)}")


@dataclass(frozen=True)
class Training:
    """What a training is (everything that changes its result; workers and batches do not)."""

    cell: str
    config: str  # sha256 of the cell's configuration as played
    budget: int
    pairs: int
    runs: int
    sigma: float
    lr: float
    seed: int
    actions: tuple[str, ...]
    interval: int
    start: dict
    base: dict
    objective: str

    @property
    def population(self) -> int:
        """Candidates per generation: the centre and the 2 x pairs perturbations."""
        return 1 + 2 * self.pairs

    @property
    def generations(self) -> int:
        """The generations the budget allows (``budget // population``, at least 1)."""
        return max(1, self.budget // self.population)

    def as_dict(self) -> dict:
        """The settings as JSON-able values (tuples as lists): what a checkpoint records and must match to resume."""
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in self.__dict__.items()}


def _checkpoint(folder: Path | None) -> Path | None:
    return None if folder is None else Path(folder) / CHECKPOINT


def _save_state(path: Path, training: Training, theta, opt: Adam, curve: list[dict]) -> None:
    tmp = path.with_name(path.name + ".tmp.npz")
    np.savez(tmp, theta=theta, m=opt.m if opt.m is not None else np.zeros_like(theta),
             v=opt.v if opt.v is not None else np.zeros_like(theta), t=np.array(opt.t),
             settings=np.array(json.dumps(training.as_dict())), curve=np.array(json.dumps(curve)))
    os.replace(tmp, path)


def _load_state(path: Path, training: Training):
    """(theta, Adam, curve) from a checkpoint of the same training; another training's is refused."""
    try:
        with np.load(path, allow_pickle=False) as z:
            settings = json.loads(str(z["settings"]))
            theta, m, v, t, curve = z["theta"], z["m"], z["v"], int(z["t"]), json.loads(str(z["curve"]))
    except (OSError, KeyError, ValueError) as exc:
        raise UsageError(f"{path}: not an adaptive attacker's checkpoint ({exc}); remove it or give another "
                         f"folder") from None
    if settings != training.as_dict():
        diff = {k: (settings.get(k), v) for k, v in training.as_dict().items() if settings.get(k) != v}
        raise UsageError(f"{path}: a checkpoint of another training (its setting -> this one's: {diff}); "
                         f"give another folder, or the same settings to resume it")
    opt = Adam(training.lr, t=t, m=m if t else None, v=v if t else None)
    return theta, opt, curve


def start_values(cell: Cell, actions, start: dict | None, base: dict | None = None) -> dict:
    """The constant attack training starts from: ``start``, else ``base``, else the cell's own attacker
    parameters."""
    own = {**cell.config.swarm.groups[1].params, **(base or {})}
    return {a: float((start or {}).get(a, own.get(a, _DEFAULTS[a]))) for a in actions}


def train(cell: Cell, budget: int, *, pairs: int = 8, runs: int = 4, sigma: float = 0.05, lr: float = 0.02,
          seed: int = 0, steps: int | None = None, transitory: int | None = None, interval: int = 10,
          actions=ACTIONS, start: dict | None = None, base: dict | None = None, objective: str = "items",
          checkpoint=None, workers: int = 1, batch: int = BATCH,
          on_runs: Callable[[int], None] | None = None,
          on_generation: Callable[[int, dict], None] | None = None) -> Policy:
    """Train the adaptive attacker on ``cell`` with ``budget`` candidate evaluations of ``runs`` runs each.

    ``checkpoint``: a folder; after every generation the state is written there, and a training started
    again with the same settings resumes from it.  ``on_runs(k)``: k runs were played;
    ``on_generation(g, record)``: generation g is done and checkpointed."""
    actions = _checked_actions(actions)
    for name, v, low in (("budget", budget, 1), ("pairs", pairs, 1), ("runs", runs, 1), ("batch", batch, 1),
                         ("workers", workers, 1), ("interval", interval, 1)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or v < low:
            raise ArgumentError(f"{name} must be an integer >= {low}, got {v!r}")
    for name, v in (("sigma", sigma), ("lr", lr)):
        if not (isinstance(v, (int, float)) and np.isfinite(v) and v > 0):
            raise ArgumentError(f"{name} must be a finite number above 0, got {v!r}")
    fitness(np.zeros(1), np.zeros(1), objective)  # an unknown objective is refused before any run
    if set(start or {}) - set(actions):
        raise ArgumentError(f"start {start}: sets only the actions {actions}; the other parameters go in base")
    cfg = cell.with_attack(dict(base or {}), steps=steps, transitory=transitory)
    first = start_values(cell, actions, start, base)
    training = Training(cell.experiment, hashlib.sha256(cfg.model_dump_json().encode()).hexdigest(), int(budget),
                        int(pairs), int(runs), float(sigma), float(lr), int(seed), actions, int(interval), first,
                        dict(base or {}), objective)
    pop = training.population
    check_memory(cfg, min(batch, pop * runs), f"{pop} candidates x {runs} runs", pop * runs,
                 (len(OBSERVATION) + 1) * len(actions))
    theta = Policy.constant(first, actions, interval, base).weights
    scale = step_scale(actions)
    opt, curve = Adam(lr), []
    path = _checkpoint(checkpoint)
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        if path.exists():
            theta, opt, curve = _load_state(path, training)
    with Player(cfg, actions, interval, batch=batch, workers=workers) as player:
        for g in range(len(curve), training.generations):
            eps = _noise(seed, g, (pairs,) + theta.shape)
            cands = np.repeat(theta[None], pop, axis=0)
            cands[1::2] += sigma * scale * eps
            cands[2::2] -= sigma * scale * eps
            seeds = generation_seeds(cfg.seed, seed, g, runs)
            weights = np.repeat(cands, runs, axis=0)  # candidate c plays seeds[0..runs-1]
            items, liar = player.play(weights, np.array(seeds * pop, dtype=np.int64), on_done=on_runs)
            f = fitness(items, liar, objective).reshape(pop, runs).mean(axis=1)
            theta = theta + scale * opt.step(es_gradient(f[1:], eps, sigma))
            per = items.reshape(pop, runs).mean(axis=1)
            best = 1 + int(np.argmax(f[1:]))
            record = {"generation": g, "centre": float(f[0]), "mean": float(f[1:].mean()), "best": float(f[best]),
                      "centre_items": float(per[0]), "best_items": float(per[best])}
            curve.append(record)
            if path is not None:
                _save_state(path, training, theta, opt, curve)
            if on_generation is not None:
                on_generation(g, record)
    info = {"training": training.as_dict(), "generations": training.generations, "curve": curve,
            "runs_played": training.generations * pop * runs,
            "env_steps": training.generations * pop * runs * cfg.steps, "start_policy": first}
    return Policy(theta, actions, interval, dict(base or {}), info)


def confirm(cell: Cell, policy: Policy, seeds, *, steps: int | None = None, transitory: int | None = None,
            label: str = "adaptive", workers: int = 1, batch: int = BATCH) -> pd.DataFrame:
    """``policy`` on each of ``seeds`` (run k plays run seed ``seeds[k]``): columns attack (``label``),
    run, items, liar_wealth, computed by ``objective.per_run`` from each run's robots table, as for an
    ordinary run of the cell with that seed."""
    seeds = np.asarray([int(s) for s in seeds], np.int64)
    if not len(seeds):
        raise ArgumentError("confirm: at least one run seed")
    cfg = cell.with_attack(policy.base, steps=steps, transitory=transitory)
    check_memory(cfg, min(batch, len(seeds)), f"{len(seeds)} seeds", len(seeds), policy.weights.size)
    weights = np.repeat(policy.weights[None], len(seeds), axis=0)
    with Player(cfg, policy.actions, policy.interval, batch=batch, workers=workers) as player:
        per = player.per_run(weights, seeds)
    return per.assign(attack=label)[["attack", "run", "items", "liar_wealth"]]



def resumed_generations(folder) -> int:
    """Generations already done by the checkpoint in ``folder`` (0 when there is none or it is unreadable:
    ``train`` then says why)."""
    path = _checkpoint(folder)
    try:
        with np.load(path, allow_pickle=False) as z:
            return len(json.loads(str(z["curve"])))
    except (OSError, KeyError, ValueError):
        return 0
