"""The search space: the unit cube mapped onto the `attacker`'s parameters (``behaviours.attacks.POLICY``).

CMA-ES searches z in [0, 1]^d; ``to_params`` maps each coordinate linearly onto its parameter's range and
rounds to 4 decimals, so a candidate's configuration (and its hash in the store) is the same on every
machine and every replay.
"""
from __future__ import annotations

import numpy as np

from ..behaviours.attacks import POLICY

NAMES: tuple[str, ...] = tuple(p[0] for p in POLICY)
LOW = np.array([p[2] for p in POLICY], float)
HIGH = np.array([p[3] for p in POLICY], float)
DIGITS = 4


def dimension() -> int:
    return len(NAMES)


def to_params(z) -> dict[str, float]:
    """The attacker's parameters at point ``z`` of the unit cube (clipped into it)."""
    z = np.clip(np.asarray(z, float), 0.0, 1.0)
    if z.shape != LOW.shape:
        raise ValueError(f"a point of the attack space has {len(NAMES)} coordinates, got {z.shape}")
    values = LOW + z * (HIGH - LOW)
    return {name: round(float(v), DIGITS) for name, v in zip(NAMES, values)}


def to_unit(params: dict[str, float]) -> np.ndarray:
    """The point of the unit cube of ``params`` (missing ones at their defaults)."""
    defaults = {p[0]: p[1] for p in POLICY}
    v = np.array([params.get(n, defaults[n]) for n in NAMES], float)
    return (v - LOW) / (HIGH - LOW)
