"""Gymnasium environments over the compiled engine: ``AttackEnv`` (one run; one controller for all the
Byzantine robots) and ``AttackVectorEnv`` (B such runs stepped in one compiled call, autoreset on the
next step).  docs/rl.md describes observations, actions and rewards.

One ``step`` is a *decision interval* of ``interval`` (K) engine steps: the action sets the Byzantine
robots' attack parameters, the engine runs K steps with them, and the reward is what those K steps did.
An episode is one run of the experiment (``steps`` engine steps); it ends *truncated* (a time limit, no
terminal state), so ``terminated`` is always False.
"""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import gymnasium as gym
from gymnasium import spaces
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode
from gymnasium.vector.utils import batch_space

from ..config import sizes
from ..errors import ArgumentError, ConfigError, InputTypeError, UsageError
from ..seeds import MAX_SEED, checked_seed_arg
from .interop import RENDER_MODES, ArenaRenderer, Rebuilt, checked_render_mode
from ..agents.observe import OBSERVATION
from ..agents.runs import ACTIONS, Runs, select_cell

#: Rewards by name, per decision interval (docs/rl.md).  ``items``: minus the items the honest robots
#: deposited in the interval, per honest robot (the attack-search objective ``items``, negated so the
#: attacker maximises it; zero during the transitory period, when items do not count).  ``liar_wealth``:
#: the gain in the Byzantine robots' wealth share (in the parallel env, each agent its own).
REWARDS = {"items": "minus the honest robots' items deposited in the interval, per honest robot",
           "liar_wealth": "the Byzantine robots' gain in wealth share over the interval"}


def configured(experiment, cell, steps, transitory):
    """The experiment an environment runs: ``select_cell`` with ``steps`` / ``transitory`` overridden."""
    if isinstance(experiment, str) and not experiment.strip():  # Path("") would read as the current folder
        raise ArgumentError(f"experiment {experiment!r}: name a shipped experiment (e.g. attack_search), a file "
                            f"or give an Experiment")
    if cell is not None and not isinstance(cell, Mapping):
        raise InputTypeError(f"cell={cell!r}: a dict of the sweep's keys, e.g. "
                             f"cell={{'defence': 'staking', 'byzantines': 3}}")
    cfg = select_cell(experiment, cell)
    changes = {k: v for k, v in (("steps", steps), ("transitory", transitory)) if v is not None}
    return cfg.with_overrides(**changes) if changes else cfg


def checked_actions(actions):
    """``actions`` as a tuple of names; a bare string is refused rather than split into its letters."""
    if isinstance(actions, str):
        raise InputTypeError(f"actions={actions!r}: a sequence of the attacker's parameter names, e.g. "
                             f"actions=({actions!r},)")
    try:
        return tuple(actions)
    except TypeError:
        raise InputTypeError(f"actions={actions!r}: a sequence of the attacker's parameter names, e.g. "
                             f"{ACTIONS}") from None


def action_array(action, shape: tuple[int, ...] | None, what: str) -> np.ndarray:
    """``action`` as a float array of exactly ``shape``; None, text, a wrong shape or NaN are refused here
    (naming ``what``) rather than failing inside numpy or writing NaN into the run.  +-inf is clipped to
    the parameter's range like any value outside it."""
    if action is None:
        raise InputTypeError(f"{what} is None: an array of shape {shape} is needed")
    try:
        a = np.asarray(action, np.float64)
    except (TypeError, ValueError):
        raise InputTypeError(f"{what}: not an array of numbers of shape {shape} ({type(action).__name__})") from None
    if a.shape != shape:
        raise ArgumentError(f"{what} has shape {a.shape}; this environment takes shape {shape}")
    if np.isnan(a).any():
        raise ArgumentError(f"{what} holds NaN at {tuple(int(i) for i in np.argwhere(np.isnan(a))[0])}: every "
                            f"entry must be a number (values outside a parameter's range are clipped to it)")
    return a


def checked(interval, reward):
    """``interval`` and ``reward`` checked: a positive integer number of steps per decision and a known reward.

    Raises:
        ConfigError: either is not.
    """
    if isinstance(interval, bool) or not isinstance(interval, (int, np.integer)) or interval < 1:
        raise ConfigError(f"interval (K, engine steps per decision) must be a positive integer, got {interval!r}")
    if reward not in REWARDS:
        raise ConfigError(f"reward {reward!r}: unknown; allowed: {', '.join(REWARDS)}")
    return int(interval), reward


def episode_seed(rng: np.random.Generator) -> int:
    """The next episode's run seed (what ``simulate(config, seed=...)`` takes to rerun it alone)."""
    return int(rng.integers(0, MAX_SEED, endpoint=True))


class _Rewarder:
    """Turns the runs' running totals (honest items, agents' wealth shares) into per-interval rewards."""

    def __init__(self, runs: Runs, reward: str):
        self.runs, self.reward = runs, reward
        self.items = runs.items.copy()
        self.shares = runs.shares.copy()
        self.per_honest = 1.0 / max(len(runs.honest), 1)

    def mark(self, which=slice(None)) -> None:
        self.items[which] = self.runs.items[which]
        self.shares[which] = self.runs.shares[which]

    def per_agent(self) -> np.ndarray:
        """[B, agents]: each agent's reward for the interval since the last ``mark``."""
        if self.reward == "items":
            lost = -(self.runs.items - self.items) * self.per_honest
            return np.repeat(lost[:, None], len(self.runs.agents), axis=1)
        return self.runs.shares - self.shares

    def team(self) -> np.ndarray:
        """[B]: the controller's reward (the shared items reward, or the summed wealth-share gain)."""
        if self.reward == "items":
            return -(self.runs.items - self.items) * self.per_honest
        return (self.runs.shares - self.shares).sum(axis=1)


def _spaces(runs: Runs):
    a, o, k = len(runs.agents), len(OBSERVATION), len(runs.actions)
    obs = spaces.Box(0.0, 1.0, (a, o), np.float32)
    act = spaces.Box(np.tile(runs.low, (a, 1)).astype(np.float32), np.tile(runs.high, (a, 1)).astype(np.float32),
                     (a, k), np.float32)
    return obs, act


class AttackEnv(Rebuilt, gym.Env):
    """One run of ``experiment`` with its ``attacker`` robots controlled together.

    Observation [agents, len(OBSERVATION)] in [0, 1]; action [agents, len(actions)], each column one of
    the attacker's parameters in its own range (default ``rot_base`` in [0, 180] degrees and ``collude``,
    >= 0.5 to share one rotation and buy each other's offers); reward ``REWARDS[reward]``; ``info["seed"]`` is the
    episode's run seed.  ``render_mode="rgb_array"``: ``render()`` draws the arena as the replay movie does.
    Pickled and copied as its arguments (``rl.interop.Rebuilt``): a copy starts before its first reset."""

    metadata = {"render_modes": list(RENDER_MODES), "render_fps": 15}

    def __init__(self, experiment="attack_search", *, cell: dict | None = None, steps: int | None = None,
                 transitory: int | None = None, interval: int = 10, actions=ACTIONS, reward: str = "items",
                 render_mode: str | None = None):
        self.interval, self.reward_name = checked(interval, reward)
        self.render_mode = checked_render_mode(render_mode)
        self.runs = Runs(configured(experiment, cell, steps, transitory), 1, actions=checked_actions(actions))
        self._renderer = ArenaRenderer(self.runs)
        self.observation_space, self.action_space = _spaces(self.runs)
        self.agents = self.runs.agents
        self._rewards = _Rewarder(self.runs, reward)
        self._over = True

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """Start a new episode (Gymnasium's API): a fresh run whose seed is drawn from the env's random stream.

        It returns the first observation and ``{"seed": the run's seed}``.
        """
        super().reset(seed=None if seed is None else checked_seed_arg(seed, "reset(seed=...)"))
        s = episode_seed(self.np_random)
        self.runs.reset([0], [s])
        self._rewards.mark()
        self._over = False
        return self.runs.obs[0].copy(), {"seed": s}

    def step(self, action):
        """Play ``action`` for ``interval`` engine steps (Gymnasium's API).

        It returns ``(observation, reward, terminated, truncated, info)``, with the team reward since the last
        step; an episode is never terminated, only truncated at the run's last step.

        Raises:
            UsageError: the episode is over or was never started (call ``reset``).
        """
        if self._over:
            raise UsageError("the episode is over (or was never started): call reset() first")
        self.runs.act(action_array(action, self.action_space.shape, "action")[None])
        self.runs.advance(self.runs.clocks + self.interval)
        reward = float(self._rewards.team()[0])
        self._rewards_last = self._rewards.per_agent()[0]  # what the parallel env hands each agent
        self._rewards.mark()
        truncated = bool(self.runs.clocks[0] >= self.runs.steps)
        self._over = truncated
        return self.runs.obs[0].copy(), reward, False, truncated, {"seed": int(self.runs.seeds[0])}

    def render(self) -> np.ndarray | None:
        """The arena now, [height, width, 3] uint8 (``render_mode="rgb_array"``; otherwise None)."""
        return self._renderer.rgb(0) if self.render_mode == "rgb_array" else None


class AttackVectorEnv(Rebuilt, gym.vector.VectorEnv):
    """``num_envs`` independent runs of ``AttackEnv``'s task, stepped in one compiled call.

    Sub-environment i seeded with ``seed + i`` (``reset(seed=seed)``) is ``AttackEnv`` reset with that seed,
    episode after episode.  Autoreset is Gymnasium's default, next-step: the ``step`` after a run's episode
    ends starts its next episode (that run's action is ignored, its reward is 0).  ``render()`` (with
    ``render_mode="rgb_array"``) draws every sub-environment's arena, a tuple of arrays."""

    metadata = {"autoreset_mode": AutoresetMode.NEXT_STEP, "render_modes": list(RENDER_MODES), "render_fps": 15}
    _CARRIED = Rebuilt._CARRIED + ("_env_rngs",)

    def __init__(self, experiment="attack_search", num_envs: int = 64, *, cell: dict | None = None,
                 steps: int | None = None, transitory: int | None = None, interval: int = 10, actions=ACTIONS,
                 reward: str = "items", render_mode: str | None = None):
        self.interval, self.reward_name = checked(interval, reward)
        self.render_mode = checked_render_mode(render_mode)
        cfg = configured(experiment, cell, steps, transitory)
        if isinstance(num_envs, (int, np.integer)) and not isinstance(num_envs, bool) and num_envs > 0:
            too_big = sizes.batch_too_big(cfg, int(num_envs), f"num_envs={num_envs}")
            if too_big:  # checked before any world is built, as a single run's size is
                raise ArgumentError(too_big)
        self.runs = Runs(cfg, num_envs, actions=checked_actions(actions))
        self._renderer = ArenaRenderer(self.runs)
        self.num_envs = self.runs.size
        self.single_observation_space, self.single_action_space = _spaces(self.runs)
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._rewards = _Rewarder(self.runs, reward)
        self._env_rngs = [seeding.np_random(None)[0] for _ in range(self.num_envs)]
        self._autoreset = np.ones(self.num_envs, bool)
        self._started = False

    def reset(self, *, seed: int | list[int] | None = None, options: dict | None = None):
        """Start every sub-environment afresh (Gymnasium's vector API).

        Args:
            seed: one int (sub-environment i gets ``seed + i``), one seed per sub-environment, or None.

        Raises:
            UsageError: a list of seeds of the wrong length.
        """
        if seed is None:
            seeds: list[int | None] = [None] * self.num_envs
        elif isinstance(seed, (int, np.integer)) and not isinstance(seed, bool):
            checked_seed_arg(seed, "reset(seed=...)")
            checked_seed_arg(int(seed) + self.num_envs - 1, f"reset(seed=...) + {self.num_envs - 1} (the last "
                                                            f"environment's seed)")
            seeds = [int(seed) + i for i in range(self.num_envs)]
        elif isinstance(seed, (list, tuple, np.ndarray)):
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise UsageError(f"reset(seed=[...]): {len(seeds)} seeds for {self.num_envs} environments")
            seeds = [None if s is None else checked_seed_arg(s, f"reset(seed=[...])[{k}]") for k, s in enumerate(seeds)]
        else:  # a string is a sequence too: it is not a list of seeds
            raise InputTypeError(f"reset(seed=...): an integer seed, a list of {self.num_envs} seeds, or None; got "
                                 f"{type(seed).__name__} {str(seed)[:80]!r}")
        super().reset(seed=seeds[0] if isinstance(seed, (int, np.integer)) else None)
        self._env_rngs = [seeding.np_random(s)[0] for s in seeds]
        self.runs.reset(np.arange(self.num_envs), [episode_seed(r) for r in self._env_rngs])
        self._rewards.mark()
        self._autoreset[:] = False
        self._started = True
        return self.runs.obs.copy(), self._info()

    def step(self, actions):
        """Play one action per sub-environment for ``interval`` steps, all in one compiled call.

        It returns ``(observations, rewards, terminated, truncated, info)``, one row per sub-environment; a run
        that ended at the previous call starts its next episode instead (its action ignored, its reward 0).

        Raises:
            UsageError: the env was never reset.
        """
        if not self._started:
            raise UsageError("the vector env was never reset: call reset() first")
        actions = action_array(actions, self.action_space.shape, "actions")
        again = np.flatnonzero(self._autoreset)
        if len(again):
            self.runs.reset(again, [episode_seed(self._env_rngs[b]) for b in again], observe=False)
        go = ~self._autoreset
        if len(again):
            self.runs.act(actions[go], np.flatnonzero(go))
        else:
            self.runs.act(actions)
        clocks = self.runs.clocks
        self.runs.advance(np.where(go, clocks + self.interval, clocks))
        rewards = self._rewards.team()
        rewards[~go] = 0.0
        self._rewards.mark()
        truncated = go & (self.runs.clocks >= self.runs.steps)
        self._autoreset = truncated.copy()
        terminated = np.zeros(self.num_envs, bool)
        return self.runs.obs.copy(), rewards, terminated, truncated, self._info()

    def render(self) -> tuple[np.ndarray, ...] | None:
        """Each sub-environment's arena now (``render_mode="rgb_array"``; otherwise None)."""
        if self.render_mode != "rgb_array":
            return None
        return tuple(self._renderer.rgb(b) for b in range(self.num_envs))

    def _info(self) -> dict:
        """Each sub-environment's episode seed, with Gymnasium's vector-info mask (every entry set)."""
        return {"seed": self.runs.seeds.copy(), "_seed": np.ones(self.num_envs, bool)}
