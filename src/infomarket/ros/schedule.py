"""Which of the engine's trades may run at once, so that the chain still ends on the engine's ledger.

A sale reads and writes only its two robots' state on chain: the seller's free balance (its stake,
checked against the stake and moved out) and the buyer's round trip (its trip number, records, pot,
repeat counts), each keyed by that robot; the light contract's own reveal key is unique to the sale,
and each reveal is sent from the seller's own account (its own nonce). So two sales with no robot in
common commute: run in either order, or at once, they leave the same state, and each one's outcome
(made, or void for a short stake) is the one the engine's order gives. Two trades that share a robot
run in the engine's order: the later one starts only when the earlier is done. A deposit is a barrier:
the nest's account sends ``buyItem`` and ``settle`` (one nonce sequence), and the settlement pays every
seller in the depositor's pot, so it starts when every earlier trade is done and nothing starts
until it is over.

The schedule bounds the trades unfinished at once (``limit`` running, ``QUEUE`` waiting or running):
an offer is valid for a fixed number of blocks (``agent.BLOCKS_VALID``) and every other trade's reveal
mines one while it is open, so the blocks mined during one trade's life stay well below that.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import InternalError

#: Trades unfinished at once (waiting or running) at most: the world stops stepping until fewer are.
QUEUE = 64
#: Sales running at once at most (``--parallel-trades``); 1 runs them one after the other.
PARALLEL = 8
#: Steps the world may run ahead of its earliest unfinished trade (``--window``); 0 waits for every
#: trade of a step before the next step.
WINDOW = 20


@dataclass(frozen=True)
class Job:
    """One of the engine's ledger events: ``key`` its place in the engine's order."""

    key: int
    step: int
    robots: frozenset[int]
    barrier: bool = False  # runs alone (a deposit)


class Schedule:
    """The engine's trades in its order; ``start()`` hands out those that may run now."""

    def __init__(self, limit: int):
        if limit < 1:
            raise InternalError("at least one trade must be able to run")
        self.limit = limit
        self.waiting: list[Job] = []  # in the engine's order
        self.running: dict[int, Job] = {}
        self.most_running = 0

    def add(self, job: Job) -> None:
        if self.waiting and job.key <= self.waiting[-1].key:
            raise InternalError(f"job {job.key} is not after job {self.waiting[-1].key} in the engine's order")
        self.waiting.append(job)

    def start(self) -> list[Job]:
        """The waiting jobs that may run now, in the engine's order (each marked running).

        A job may start when no earlier unfinished job (waiting or running) shares a robot with it and
        no earlier barrier is unfinished; a barrier when it is the first unfinished job of all."""
        if any(j.barrier for j in self.running.values()):
            return []
        busy: set[int] = set().union(*(j.robots for j in self.running.values()))
        started: list[Job] = []
        for job in self.waiting:
            if job.barrier:
                if not self.running and not started and job is self.waiting[0]:
                    started.append(job)
                break  # nothing after a barrier overtakes it
            if len(self.running) + len(started) >= self.limit:
                break
            if not job.robots & busy:
                started.append(job)
            busy |= job.robots  # a later job sharing a robot waits for this one, started or not
        for job in started:
            self.waiting.remove(job)
            self.running[job.key] = job
        self.most_running = max(self.most_running, len(self.running))
        return started

    def finish(self, key: int) -> None:
        del self.running[key]

    def unfinished(self) -> int:
        return len(self.waiting) + len(self.running)

    def oldest_step(self) -> int | None:
        """The step of the earliest unfinished job (``None`` when all are done)."""
        steps = [j.step for j in self.waiting[:1]] + [j.step for j in self.running.values()]
        return min(steps) if steps else None
