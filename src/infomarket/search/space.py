"""The search space: the unit cube mapped onto the `attacker`'s parameters (``behaviours.attacks.POLICY``).

CMA-ES searches z in [0, 1]^d.  Each coordinate maps onto its parameter piecewise, so that every gate of
the policy has a wide *neutral zone* (half the interval, or a fifth around zero for the slopes) where it
is off: a small step from a hand-written attack then leaves its other gates off instead of switching on
a gate that silences it (with a plain linear map, any ``fresh_record`` above 0 makes a liar withdraw after
a few sales).  Values are rounded to 4 decimals, so a candidate's configuration (and its hash in the
store) is the same on every machine and every replay.
"""
from __future__ import annotations

import numpy as np

from ..behaviours.attacks import POLICY
from ..errors import ArgumentError

#: name -> (shape, arguments): "linear" lo..hi; "signed" lo..0..hi with z in [0.4, 0.6] giving 0;
#: "below" lo..hi over z < 0.5 and ``off`` from 0.5; "above" ``off`` = lo up to 0.5, then lo..hi;
#: "switch" a below 0.5, b from 0.5; "choice" one of the values, in equal thirds.
SHAPES = {
    "rot_base": ("linear", 0.0, 180.0),
    "rot_rep": ("signed", -90.0, 90.0),
    "rot_buyer_rep": ("signed", -90.0, 90.0),
    "rot_age": ("signed", -90.0, 90.0),
    "cap_theta": ("below", 0.05, 6.0, 6.0),
    "cap_sceptic": ("below", 0.05, 12.5, 100.0),
    "lie_from_rep": ("above", 0.0, 1.0),
    "lie_min_record": ("above", 0.0, 40.0),
    "fresh_record": ("above", 0.0, 40.0),
    "max_confirmers": ("below", 0.0, 24.0, 24.0),
    "buyer_age_min": ("above", 0.0, 2000.0),
    "lie_site": ("choice", 0.0, 1.0, 2.0),
    "withhold": ("switch", 0.0, 1.0),
    "collude": ("switch", 0.0, 1.0),
}
NAMES: tuple[str, ...] = tuple(p[0] for p in POLICY)
DIGITS = 4
assert set(SHAPES) == set(NAMES)


def dimension() -> int:
    """The number of coordinates of the search space (one per attack parameter searched)."""
    return len(NAMES)


def _value(shape, z: float) -> float:
    kind, *a = shape
    if kind == "linear":
        return a[0] + z * (a[1] - a[0])
    if kind == "signed":
        if z < 0.4:
            return a[0] * (0.4 - z) / 0.4
        return 0.0 if z <= 0.6 else a[1] * (z - 0.6) / 0.4
    if kind == "below":
        return a[2] if z >= 0.5 else a[0] + (z / 0.5) * (a[1] - a[0])
    if kind == "above":
        return a[0] if z <= 0.5 else a[0] + ((z - 0.5) / 0.5) * (a[1] - a[0])
    if kind == "switch":
        return a[0] if z < 0.5 else a[1]
    return a[min(int(z * len(a)), len(a) - 1)]  # choice


def _unit(shape, v: float) -> float:
    kind, *a = shape
    if kind == "linear":
        return (v - a[0]) / (a[1] - a[0])
    if kind == "signed":
        return 0.5 if v == 0 else (0.4 - 0.4 * v / a[0] if v < 0 else 0.6 + 0.4 * v / a[1])
    if kind == "below":
        return 0.75 if v == a[2] else 0.5 * (min(v, a[1]) - a[0]) / (a[1] - a[0])
    if kind == "above":
        return 0.25 if v == a[0] else 0.5 + 0.5 * (v - a[0]) / (a[1] - a[0])
    if kind == "switch":
        return 0.25 if v < 0.5 * (a[0] + a[1]) else 0.75
    return (int(np.argmin([abs(v - c) for c in a])) + 0.5) / len(a)


def to_params(z) -> dict[str, float]:
    """The attacker's parameters at point ``z`` of the unit cube (clipped into it)."""
    z = np.clip(np.asarray(z, float), 0.0, 1.0)
    if z.shape != (len(NAMES),):
        raise ArgumentError(f"a point of the attack space has {len(NAMES)} coordinates, got {z.shape}")
    return {n: round(float(_value(SHAPES[n], float(x))), DIGITS) for n, x in zip(NAMES, z)}


def to_unit(params: dict[str, float]) -> np.ndarray:
    """A point of the unit cube where ``to_params`` gives ``params`` (missing ones at their defaults); a
    gate that is off sits in the middle of its neutral zone."""
    defaults = {p[0]: p[1] for p in POLICY}
    return np.array([_unit(SHAPES[n], float(params.get(n, defaults[n]))) for n in NAMES], float)
