"""A PettingZoo ``ParallelEnv``: each Byzantine robot (behaviour ``attacker``) is an agent, named
``robot_<id>``, with its own observation row, its own action and its own reward (docs/rl.md)."""
from __future__ import annotations

import functools
from collections.abc import Mapping

import numpy as np
from gymnasium import spaces
from pettingzoo import ParallelEnv

from ..errors import InputTypeError, UsageError
from .envs import AttackEnv, action_array
from .interop import RENDER_MODES, Rebuilt
from ..agents.observe import OBSERVATION
from ..agents.runs import ACTIONS


class AttackParallelEnv(Rebuilt, ParallelEnv):
    """One run of ``experiment``; every ``step`` is a decision interval of ``interval`` engine steps.

    ``observation_space(agent)``: Box [len(OBSERVATION)] in [0, 1]; ``action_space(agent)``: Box
    [len(actions)] of the attacker's parameters; rewards per agent: ``items`` (shared by all) or
    ``liar_wealth`` (each agent's own gain in wealth share).  All agents are truncated together at the
    end of the run, and then leave ``agents``.  ``render_mode="rgb_array"``: ``render()`` draws the arena
    (as ``AttackEnv``); pickled and copied as its arguments (``rl.interop.Rebuilt``)."""

    metadata = {"name": "infomarket_attack_v0", "render_modes": list(RENDER_MODES), "render_fps": 15,
                "is_parallelizable": True}

    def __init__(self, experiment="attack_search", *, cell: dict | None = None, steps: int | None = None,
                 transitory: int | None = None, interval: int = 10, actions=ACTIONS, reward: str = "items",
                 render_mode: str | None = None):
        self._env = AttackEnv(experiment, cell=cell, steps=steps, transitory=transitory, interval=interval,
                              actions=actions, reward=reward, render_mode=render_mode)
        self.render_mode = self._env.render_mode
        self.runs = self._env.runs
        self.possible_agents = [f"robot_{i}" for i in self.runs.agents]
        self.agents: list[str] = []
        self._low = self.runs.low.astype(np.float32)
        self._high = self.runs.high.astype(np.float32)

    @functools.cache  # noqa: B019 - PettingZoo's idiom: one space per agent, kept as long as the env
    def observation_space(self, agent):
        """Each agent's observation space: its observation row, every value in [0, 1]."""
        return spaces.Box(0.0, 1.0, (len(OBSERVATION),), np.float32)

    @functools.cache  # noqa: B019 - PettingZoo's idiom: one space per agent, kept as long as the env
    def action_space(self, agent):
        """Each agent's action space: the attack parameters within their bounds."""
        return spaces.Box(self._low, self._high, (len(self.runs.actions),), np.float32)

    def _split(self, rows) -> dict:
        return {a: rows[k] for k, a in enumerate(self.possible_agents)}

    def reset(self, seed: int | None = None, options: dict | None = None):
        """Start a new episode (PettingZoo's parallel API): every agent acts again; returns per-agent observations
        and infos."""
        obs, info = self._env.reset(seed=seed, options=options)
        self.agents = list(self.possible_agents)
        return self._split(obs), {a: dict(info) for a in self.agents}

    def step(self, actions: dict):
        """Play every acting agent's action (PettingZoo's parallel API) for ``interval`` steps.

        It returns per-agent dicts of observations, rewards, terminations, truncations and infos; after the
        run's last step every agent is done.

        Raises:
            UsageError: an agent has no action or is not acting, or no episode is running.
            InputTypeError: ``actions`` is not a dict.
        """
        if not self.agents:
            raise UsageError("every agent is done (or the env was never reset): call reset() first")
        if not isinstance(actions, Mapping):
            raise InputTypeError(f"actions: a dict of each acting agent's action, got {type(actions).__name__}")
        unknown = set(actions) - set(self.agents)
        if unknown:
            raise UsageError(f"actions for agents that are not acting: {sorted(unknown, key=str)}")
        missing = [a for a in self.agents if a not in actions]
        if missing:  # every agent acts each step (PettingZoo's parallel API); {} is a mistake, not a no-op
            raise UsageError(f"actions: no action for {', '.join(missing[:5])}"
                             + (f" and {len(missing) - 5} more" if len(missing) > 5 else "")
                             + "; give one for every agent in env.agents")
        shape = (len(self.runs.actions),)
        act = np.stack([action_array(actions[a], shape, f"actions[{a!r}]") for a in self.possible_agents])
        obs, _, _, truncated, info = self._env.step(act)
        rewards = self._env._rewards_last
        out = (self._split(obs), self._split(rewards.astype(float).tolist()),
               {a: False for a in self.agents}, {a: truncated for a in self.agents},
               {a: dict(info) for a in self.agents})
        if truncated:
            self.agents = []
        return out

    def render(self) -> np.ndarray | None:
        """The arena now, [height, width, 3] uint8 (``render_mode="rgb_array"``; otherwise None)."""
        return self._env.render()

    def _carried(self) -> dict:
        return self._env._carried()  # the random streams live in the single env it wraps

    def _carry(self, values: dict) -> None:
        self._env._carry(values)

    def state(self) -> np.ndarray:
        """Every agent's observation row, stacked (the global state a centralised critic may use)."""
        return self.runs.obs[0].copy()

    @property
    def state_space(self):
        """The global state's space: every agent's observation row stacked (see ``state``)."""
        return spaces.Box(0.0, 1.0, (len(self.possible_agents), len(OBSERVATION)), np.float32)
