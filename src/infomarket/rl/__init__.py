"""Reinforcement-learning interfaces over the compiled engine, the Byzantine robots as agents (docs/rl.md).

``AttackParallelEnv`` (PettingZoo), ``AttackEnv`` and ``AttackVectorEnv`` (Gymnasium) need the ``rl``
extra (``pip install 'infomarket[rl]'``); ``rl.runs`` (B runs stepped in one compiled call) and
``rl.train`` (evolution strategies in numpy) need only the core.
"""
from __future__ import annotations

from ..errors import UsageError

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
