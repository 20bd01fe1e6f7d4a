"""The search's last phase: a pattern search on the best attack's own coordinates, on common seeds.

CMA-ES in 14 dimensions with a few dozen evaluations does not settle on an optimum: it wanders around
it, and every generation draws new seeds, so the best point it ever evaluated is partly the luckiest.
What is left once the start, the gates and CMA-ES have found a basin is a small problem: move the
rotation and each open gate's value a little, and close each open gate that is not needed.  So the
refinement takes the best points of the whole search, runs them again on one seed set of its own (the
leaders, ``leader_runs`` each: the same swarms for every point, so a difference between two points is
the attacks' and not the seeds'), and from the best of them makes ``rounds`` rounds of moves
(``moves``): each round's points run on those seeds, its best few grown to ``leader_runs`` runs, and the
centre moves to the best one if it beats the centre on the same runs; the step halves after a round
that found nothing better (a compass search).  Every move stays inside the open zone of the gate it moves,
so a round refines values instead of switching gates; closing a gate is a move of its own.
"""
from __future__ import annotations

import numpy as np

from . import space
from .structured import GATES, OFF, is_open

#: the most open gates a round moves (the first ones in ``structured.GATES``): a round's points at most
WIDTH = 3
#: the edges of each gate kind's open zone in its unit coordinate (``space``'s neutral zones)
OPEN = {"above": ((0.5001, 1.0),), "below": ((0.0, 0.4999),), "signed": ((0.0, 0.3999), (0.6001, 1.0))}


def per_round() -> int:
    """The most points one round evaluates: the rotation's two moves and three per moved gate."""
    return 2 + 3 * WIDTH


def active(z: np.ndarray) -> list[str]:
    """The gates open at ``z`` whose value a round moves (switches have no value to move), at most ``WIDTH``."""
    out = [g for g in GATES if space.SHAPES[g][0] in OPEN and is_open(g, float(z[space.NAMES.index(g)]))]
    return out[:WIDTH]


def _inside(kind: str, before: float, after: float) -> float:
    """``after`` kept inside the open zone that holds ``before``."""
    for lo, hi in OPEN[kind]:
        if lo <= before <= hi:
            return float(np.clip(after, lo, hi))
    return float(np.clip(after, 0.0, 1.0))


def moves(z: np.ndarray, step: float) -> list[np.ndarray]:
    """The points of one round around ``z``: the rotation moved by +-``step`` (in the unit cube: 180° x
    step), each ``active`` gate's value moved by +-``step`` inside its open zone, and the gate closed.
    A move that changes nothing (at an edge) is left out."""
    z = np.asarray(z, float)
    out: list[np.ndarray] = []

    def add(x: np.ndarray) -> None:
        if not np.allclose(x, z) and not any(np.allclose(x, y) for y in out):
            out.append(x)

    k = space.NAMES.index("rot_base")
    for sign in (-1.0, 1.0):
        x = z.copy()
        x[k] = float(np.clip(z[k] + sign * step, 0.0, 1.0))
        add(x)
    for g in active(z):
        k, kind = space.NAMES.index(g), space.SHAPES[g][0]
        for sign in (-1.0, 1.0):
            x = z.copy()
            x[k] = _inside(kind, float(z[k]), float(z[k]) + sign * step)
            add(x)
        x = z.copy()
        x[k] = OFF[kind]
        add(x)
    return out
