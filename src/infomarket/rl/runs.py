"""The batched runs under the environments, under the name the API reference has always given them.

They live in ``infomarket.agents.runs`` (the attack search stands on them too, without the RL layer);
this module re-exports its public names so ``from infomarket.rl.runs import Runs`` keeps working.
"""
from __future__ import annotations

from ..agents.runs import ACTIONS, AGENT_BEHAVIOUR, Runs, select_cell

__all__ = ["ACTIONS", "AGENT_BEHAVIOUR", "Runs", "select_cell"]
