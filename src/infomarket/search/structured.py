"""The structured start of the global search: open one restricting gate at a time.

A hand-written attack or a rotation-grid point has every gate closed; a weakness that needs a gate open
(lie only once trusted, only to a fresh identity's buyers, only with few confirmers) sits where a sample
around it almost never goes: with CMA-ES's step sigma a sample keeps a closed gate closed, and a uniform
point has all of them closed with a probability of a few in a thousand.  So, before CMA-ES, the search
takes the best point it has (on the start phase's seeds: a baseline or a spread point), moves its rotation
by 5-15° either way, switches its collusion and tries each other lie site (``choices``), and opens each
restricting gate alone at a few values spread over its range, and closes each one open (``openings``);
a second round opens each
gate again on the best point of the first, so a weakness that needs two gates open is reached in two
steps.  Every opening runs on the start phase's seeds, paired with the baselines.  Before each round,
and before CMA-ES starts from the best points, the leaders run again on more of the same seeds
(``reevaluate``), so what the search builds on is the best point, not the luckiest evaluation.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from . import space

#: where each kind of gate is opened, in its coordinate's unit interval (``space.SHAPES``)
AT = {
    "above": (0.5 + 0.5 / 6, 0.75, 1.0 - 0.5 / 6),   # off up to 0.5, its range above
    "below": (0.5 / 6, 0.25, 0.5 - 0.5 / 6),         # its range below 0.5, off above
    "signed": (0.2, 0.8),                            # a slope of -45 or +45 (off between 0.4 and 0.6)
    "switch": (0.75,),                               # on
}
#: where each kind of gate is closed (the middle of its neutral zone, as ``space.to_unit`` puts it)
OFF = {"above": 0.25, "below": 0.75, "signed": 0.5, "switch": 0.25}
#: the gates that restrict when an attacker lies (a rotation, a site and collusion are choices, not gates)
GATES = ("rot_rep", "rot_buyer_rep", "rot_age", "cap_theta", "cap_sceptic", "lie_from_rep", "lie_min_record",
         "fresh_record", "max_confirmers", "buyer_age_min", "withhold")


def is_open(name: str, u: float) -> bool:
    """Whether gate ``name`` is open at unit coordinate ``u`` (``space``'s neutral zones)."""
    kind = space.SHAPES[name][0]
    return {"above": u > 0.5, "below": u < 0.5, "signed": not 0.4 <= u <= 0.6, "switch": u >= 0.5}[kind]


#: the rotation's steps around the best point (degrees), a fine sweep between the grid's angles
TURNS = (-15.0, -10.0, -5.0, 5.0, 10.0, 15.0)


def choices(z: np.ndarray) -> list[np.ndarray]:
    """``z`` with its rotation moved by each of ``TURNS`` (kept in 0..180°), collusion switched, and each
    other lie site: the fine sweep of rotation x colluding x site around the best point."""
    out = []
    k = space.NAMES.index("rot_base")
    lo, hi = space.SHAPES["rot_base"][1:]
    for t in TURNS:
        x = np.array(z, float)
        x[k] = float(np.clip(x[k] + t / (hi - lo), 0.0, 1.0))
        out.append(x)
    c = space.NAMES.index("collude")
    x = np.array(z, float)
    x[c] = 0.25 if x[c] >= 0.5 else 0.75
    out.append(x)
    s = space.NAMES.index("lie_site")
    here = min(int(z[s] * 3), 2)
    for other in (v for v in range(3) if v != here):
        x = np.array(z, float)
        x[s] = (other + 0.5) / 3
        out.append(x)
    return out


def openings(z: np.ndarray) -> list[np.ndarray]:
    """``z`` with one choice or one gate changed at a time: the ``choices`` (rotation, collusion, site),
    then each closed gate opened at each of its ``AT`` values, each open one moved to them and closed (in
    place of the ``AT`` value nearest its own): ``per_round`` points."""
    out = choices(z)
    for name in GATES:
        k = space.NAMES.index(name)
        kind = space.SHAPES[name][0]
        values = list(AT[kind])
        if is_open(name, float(z[k])):
            values[int(np.argmin([abs(v - z[k]) for v in values]))] = OFF[kind]
        for u in values:
            x = np.array(z, float)
            x[k] = u
            out.append(x)
    return out


def per_round() -> int:
    return len(TURNS) + 1 + 2 + sum(len(AT[space.SHAPES[n][0]]) for n in GATES)


def reevaluate(ev, conds: list, scores: list[float], rows: list[dict], count: int, runs: int) -> None:
    """The ``count`` best points by ``scores`` run again on ``runs`` of the same seeds (their conditions
    grown, the runs they made kept), their scores and candidate rows' fitness replaced by the longer
    mean: picked from many noisy evaluations, the best one's score is flattered by its noise (the
    winner's curse), and a restart from it would start from luck."""
    top = sorted(range(len(scores)), key=lambda k: (scores[k], k))[:count]
    grow = [k for k in top if conds[k].runs < runs]
    if not grow:
        return
    frames = ev.evaluate([dataclasses.replace(conds[k], runs=runs) for k in grow])
    label = {c.keys["attack"]: k for k, c in zip(grow, [conds[k] for k in grow])}
    for k, f in zip(grow, frames):
        scores[k] = ev.fitness(f)
        conds[k] = dataclasses.replace(conds[k], runs=runs)
    for row in rows:
        if row["label"] in label:
            row["fitness"] = scores[label[row["label"]]]
