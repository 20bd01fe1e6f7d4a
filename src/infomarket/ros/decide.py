"""Who decides whether a robot sells or buys: its registered behaviour, or the robot's own controller.

By default an agent does what its tasks say: a task carries the decision of the robot's registered
infomarket behaviour (in the swarm, the engine's). An agent started with a controller asks before it
commits to anything: before it signs an offer (``sell``) and before it signs the acceptance of an offer
it heard (``buy``), it publishes the question on ``/robot_N/market/ask`` and waits for the answer on
``/robot_N/market/decision`` (both ``std_msgs/String`` holding JSON, so the controller can be written in
any language that speaks ROS 2). A question is asked again with every repeat of its task or offer (the
controller may have started after it), and an answer is kept in the agent's state on disk, so a
restarted agent never asks twice nor changes its mind about a sale it has signed. With a timeout, a
question left unanswered that long gets the behaviour's answer (yes: the task is the behaviour's
decision), and the agent logs that it fell back.

This module holds the bookkeeping only (no ROS 2), so that it can be checked on its own.
"""
from __future__ import annotations

import json
import time

from . import wire

QUESTIONS = ("sell", "buy")


class Decisions:
    """Questions asked and not yet answered; ``answer`` and ``expired`` say which to resume."""

    def __init__(self, ask, timeout: float | None = None, clock=time.monotonic):
        """``ask(text)`` publishes a question (JSON text); ``timeout`` seconds (None: wait for ever)."""
        self._ask, self.timeout, self._clock = ask, timeout, clock
        self.pending: dict[tuple[int, str], tuple[float, dict]] = {}

    def ask(self, task_id: int, question: str, facts: dict) -> None:
        """Ask (again) whether to ``question`` (``sell`` or ``buy``) in task ``task_id``."""
        key = (int(task_id), question)
        first = self.pending.get(key, (self._clock(), facts))[0]
        self.pending[key] = (first, facts)
        self._ask(json.dumps({"id": int(task_id), "question": question, **facts}))

    def answer(self, text: str) -> tuple[int, str, bool] | None:
        """The question an answer settles and the answer; None for an answer to a question not open (a
        controller answers every repeat of a question: the first answer counts); a WireError for a
        malformed answer."""
        d = wire.decode_json(text, "id", "question", "yes")
        if not isinstance(d["yes"], bool) or d["question"] not in QUESTIONS or isinstance(d["id"], bool) \
                or not isinstance(d["id"], int):
            raise wire.WireError("an answer is {\"id\": int, \"question\": \"sell\"/\"buy\", \"yes\": true/false}")
        key = (d["id"], d["question"])
        if key not in self.pending:
            return None
        del self.pending[key]
        return d["id"], d["question"], d["yes"]

    def expired(self) -> list[tuple[int, str]]:
        """Questions unanswered for longer than the timeout: settled now by the behaviour's answer (yes)."""
        if self.timeout is None:
            return []
        now = self._clock()
        late = [k for k, (t, _) in self.pending.items() if now - t >= self.timeout]
        for k in late:
            del self.pending[k]
        return late
