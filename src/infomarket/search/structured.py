"""The structured start of the global search: open one restricting gate at a time.

A hand-written attack or a rotation-grid point has every gate closed; a weakness that needs a gate open
(lie only once trusted, only to a fresh identity's buyers, only with few confirmers) sits where a sample
around it almost never goes: with CMA-ES's step sigma a sample keeps a closed gate closed, and a uniform
point has all of them closed with a probability of a few in a thousand.  So, before CMA-ES, the search
takes the best point it has (on the start phase's seeds: a baseline or a spread point) and opens each
restricting gate alone at a few values spread over its range (``openings``); a second round opens each
gate again on the best point of the first, so a weakness that needs two gates open is reached in two
steps.  Every opening runs on the start phase's seeds, paired with the baselines.
"""
from __future__ import annotations

import numpy as np

from . import space

#: where each kind of gate is opened, in its coordinate's unit interval (``space.SHAPES``)
AT = {
    "above": (0.5 + 0.5 / 6, 0.75, 1.0 - 0.5 / 6),   # off up to 0.5, its range above
    "below": (0.5 / 6, 0.25, 0.5 - 0.5 / 6),         # its range below 0.5, off above
    "signed": (0.2, 0.8),                            # a slope of -45 or +45 (off between 0.4 and 0.6)
    "switch": (0.75,),                               # on
}
#: the gates that restrict when an attacker lies (a rotation, a site and collusion are choices, not gates)
GATES = ("rot_rep", "rot_buyer_rep", "rot_age", "cap_theta", "cap_sceptic", "lie_from_rep", "lie_min_record",
         "fresh_record", "max_confirmers", "buyer_age_min", "withhold")


def openings(z: np.ndarray) -> list[np.ndarray]:
    """``z`` with one gate changed at a time, to each of its ``AT`` values (the gate's own value left out
    when ``z`` already has it): a fixed number of points per call (``per_round``)."""
    out = []
    for name in GATES:
        k = space.NAMES.index(name)
        for u in AT[space.SHAPES[name][0]]:
            x = np.array(z, float)
            x[k] = u
            out.append(x)
    return out


def per_round() -> int:
    return sum(len(AT[space.SHAPES[n][0]]) for n in GATES)
