"""Reinforcement-learning interfaces over the compiled engine, the Byzantine robots as agents (docs/rl.md).

``AttackParallelEnv`` (PettingZoo), ``AttackEnv`` and ``AttackVectorEnv`` (Gymnasium) need the ``rl``
extra (``pip install 'infomarket[rl]'``); ``rl.train`` (evolution strategies in numpy) and the runs under
the environments (``infomarket.agents.runs``: B runs stepped in one compiled call, which the attack search
uses too) need only the core.

Importing this package registers ``ENV_ID`` with Gymnasium, when it is installed:
``gymnasium.make(ENV_ID, **kwargs)`` builds ``AttackEnv(**kwargs)`` and ``gymnasium.make_vec(ENV_ID,
num_envs=B, **kwargs)`` builds ``AttackVectorEnv(num_envs=B, **kwargs)`` (the compiled vector env, not B
copies of the single one).  The entry points are strings, so nothing of the envs is imported until then.
"""
from __future__ import annotations

from ..errors import UsageError

#: The Gymnasium id of ``AttackEnv`` (and, through ``make_vec``, of ``AttackVectorEnv``).
ENV_ID = "infomarket/Attack-v0"


def _register_with_gymnasium() -> None:
    try:
        from gymnasium.envs.registration import register, registry
    except ImportError:  # the rl extra is not installed: nothing to register with
        return
    if ENV_ID not in registry:
        register(id=ENV_ID, entry_point=f"{__name__}.envs:AttackEnv",
                 vector_entry_point=f"{__name__}.envs:AttackVectorEnv")


_register_with_gymnasium()

_ENVS = {"AttackEnv": "envs", "AttackVectorEnv": "envs", "AttackParallelEnv": "parallel", "REWARDS": "envs"}
__all__ = list(_ENVS)


def __getattr__(name: str):
    if name not in _ENVS:
        raise AttributeError(name)
    import importlib

    try:
        module = importlib.import_module(f".{_ENVS[name]}", __name__)
    except ModuleNotFoundError as exc:
        if exc.name in ("gymnasium", "pettingzoo"):
            raise UsageError(f"infomarket.rl.{name} needs {exc.name}: pip install 'infomarket[rl]'") from exc
        raise
    return getattr(module, name)
