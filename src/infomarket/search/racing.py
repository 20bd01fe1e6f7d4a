"""Successive halving on one shared seed set: the budget of the selection goes where the decision is.

Every attack of a race runs on the same selection seeds (run ``k`` of every attack has the same seed), so
attacks are compared run for run.  At stage ``i`` every attack still in contention has ``stages[i]`` runs
(cumulative: a stage adds runs, it never repeats one); after each stage but the last, each group keeps its
best ``keep`` fraction (at least two; a group of one keeps it) by mean loss.  Groups race side by side
(one call per stage runs all of them), never against each other: each group ends with its own winner.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np


@dataclass
class Race:
    """What a race decided: per group, its ranking after the last stage (best first) and who was
    dropped after which stage."""

    ranking: dict[str, list[str]]
    dropped: dict[str, int]   # label -> the stage after which it was dropped
    means: dict[str, float]   # label -> its mean loss over the runs it made


def survivors(n: int, keep: float) -> int:
    """How many of ``n`` candidates go on to the next stage: the ``keep`` share rounded up, at least 2 (all of them
    when there are 2 or fewer)."""
    return n if n <= 2 else max(2, math.ceil(keep * n))


def race(groups: dict[str, list[str]], stages: tuple[int, ...], keep: float,
         evaluate: Callable[[list[str], int], dict[str, np.ndarray]]) -> Race:
    """Race ``groups`` (name -> attack labels, best guess first: ties keep that order).  ``evaluate(labels,
    runs)`` gives each label's loss on runs 0..runs-1 (lower is more damaging), making the missing ones."""
    alive = {g: list(dict.fromkeys(labels)) for g, labels in groups.items()}
    dropped: dict[str, int] = {}
    means: dict[str, float] = {}
    for i, runs in enumerate(stages):
        labels = [a for g in alive.values() for a in g]
        values = evaluate(labels, runs)
        for a in labels:
            means[a] = float(np.mean(values[a]))
        for g, members in alive.items():
            ranked = sorted(members, key=lambda a: (means[a], members.index(a)))
            if i < len(stages) - 1:
                n = survivors(len(ranked), keep)
                for a in ranked[n:]:
                    dropped[a] = i
                ranked = ranked[:n]
            alive[g] = ranked
    return Race(alive, dropped, means)


def merged(result: Race, group: str, other: str) -> list[str]:
    """``group``'s last survivors and ``other``'s, one ranking by mean loss (ties: ``group``'s first, then in
    order).  Both groups' last survivors ran every stage on the same runs, so their means compare: the
    ranking of a searcher that keeps the best attack it raced beside (the search, beside the baselines)."""
    mine = result.ranking.get(group, [])
    both = mine + [a for a in result.ranking.get(other, []) if a not in mine]
    return sorted(both, key=lambda a: (result.means[a], both.index(a)))
