"""Planted weaknesses: cells whose most damaging attack is known by construction, to measure how often a
searcher recovers it (``infomarket attack-search --validate``, ``search.validate``).

Each planted cell replaces the simulation by a landscape over the attacker's parameters (the same 14
coordinates, the same unit-cube map, the same driver: baselines, start points, CMA-ES restarts, random
search, race and confirmation), with the noise of a run: a part shared by every attack on the same seed
(what common random numbers cancel) and a part of the seed and the attack.  A landscape is the honest
robots' items: ``BASE`` less the attack's damage, where the damage is

    silenced(p, exempt) x max(decoy(rotation), planted(p)),

``decoy`` the plain rotation damage every hand-written attack reaches (at most ``DECOY``), ``planted``
the weakness of its kind, and ``silenced`` a factor ``SILENCE`` per restricting gate that is open but
not part of the weakness (a gate makes a liar lie less often).  So the optimum is ``OPTIMUM`` at the
point each kind names (every other gate closed), computed here, not found by a search; no baseline and
no point of the rotation grid reaches 0.9 of it (``tests/search/test_validate.py`` checks both).

Kinds: a rotation window away from every baseline's angle; a trust gate that must be open at the right
reputation (a farmer's); collusion at a rotation the grid misses; a lie about the nest only; a timing (lie
only over the first sales of an identity); two gates that must be open together (few confirmers, a cap
under Θ).
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass

import numpy as np

BASE = 10.0      # items per honest robot with no attack
DECOY = 1.0      # the best damage of a plain liar (rotation 25°), reached by hand-written attacks
OPTIMUM = 3.0    # the damage at each planted weakness
SILENCE = 0.7    # damage factor per restricting gate open beyond the weakness's own
RECOVERED = 0.9  # a searcher recovers the weakness when its attack's true damage is >= this x OPTIMUM
SHARED_SD = 0.8  # per-seed noise shared by every attack on that seed
OWN_SD = 0.5     # per-seed noise of the attack itself

#: a restricting gate: (parameter, is it open at value v)
GATES = {
    "cap_theta": lambda v: v < 6.0, "cap_sceptic": lambda v: v < 100.0, "lie_from_rep": lambda v: v > 0.0,
    "lie_min_record": lambda v: v > 0.0, "fresh_record": lambda v: v > 0.0, "max_confirmers": lambda v: v < 24.0,
    "buyer_age_min": lambda v: v > 0.0, "withhold": lambda v: v >= 0.5, "rot_rep": lambda v: v != 0.0,
    "rot_buyer_rep": lambda v: v != 0.0, "rot_age": lambda v: v != 0.0,
}


def tri(v: float, centre: float, half: float) -> float:
    """1 at ``centre``, falling linearly to 0 at ``centre`` +- ``half``."""
    return max(0.0, 1.0 - abs(v - centre) / half)


def ramp(v: float, lo: float, hi: float) -> float:
    """0 below ``lo``, 1 above ``hi``, linear between."""
    return float(np.clip((v - lo) / (hi - lo), 0.0, 1.0))


@dataclass(frozen=True)
class Kind:
    """One planted weakness: its damage function, the gates it needs open, and its optimum's point."""

    name: str
    what: str
    planted: object            # params -> damage in [0, OPTIMUM]
    exempt: tuple[str, ...]    # restricting gates that are part of the weakness
    optimum: dict              # a point where planted = OPTIMUM (other parameters at their defaults)


KINDS = {k.name: k for k in (
    Kind("window", "a rotation window at 47.5° (35°-60° damages more than the decoy), every gate closed",
         lambda p: OPTIMUM * tri(p["rot_base"], 47.5, 25.0), (), {"rot_base": 47.5}),
    Kind("trust_gate", "lie 20°+ only from a reputation of 0.7 (a farmer's gate, open at the right value)",
         lambda p: (OPTIMUM * tri(p["lie_from_rep"], 0.7, 0.4) * ramp(p["rot_base"], 5.0, 20.0)
                    * (p["lie_from_rep"] > 0)),
         ("lie_from_rep",), {"rot_base": 30.0, "lie_from_rep": 0.7}),
    Kind("collusion", "colluding liars at 70° (the grid has 60° and 90°)",
         lambda p: OPTIMUM * (p["collude"] >= 0.5) * tri(p["rot_base"], 70.0, 25.0), (),
         {"rot_base": 70.0, "collude": 1.0}),
    Kind("site", "a lie about the nest only, at 110° (the grid has 90° and 120°)",
         lambda p: OPTIMUM * (0.5 <= p["lie_site"] < 1.5) * tri(p["rot_base"], 110.0, 30.0), (),
         {"rot_base": 110.0, "lie_site": 1.0}),
    Kind("timing", "lie 20°+ only over an identity's first 25 sales (the newcomer's is 10)",
         lambda p: (OPTIMUM * tri(p["fresh_record"], 25.0, 20.0) * ramp(p["rot_base"], 5.0, 20.0)
                    * (p["fresh_record"] > 0)),
         ("fresh_record",), {"rot_base": 30.0, "fresh_record": 25.0}),
    Kind("two_gates", "lie 20°+ only with at most one confirmer in range AND capped at 0.7 Θ (half the damage "
         "with the first gate alone)",
         lambda p: OPTIMUM * tri(p["max_confirmers"], 1.0, 10.0) * (0.6 + 0.4 * tri(p["cap_theta"], 0.7, 2.0))
         * ramp(p["rot_base"], 5.0, 20.0),
         ("max_confirmers", "cap_theta"), {"rot_base": 30.0, "max_confirmers": 1.0, "cap_theta": 0.7}),
)}


def decoy(p: dict) -> float:
    return DECOY * float(np.exp(-((p["rot_base"] - 25.0) / 25.0) ** 2))


def damage(kind: Kind, p: dict) -> float:
    """The attack's true (noise-free) damage in items: what recovery is judged by.  A liar that waits for
    a reputation of 1 never lies (a reputation stays below 1): no damage, as the truthful reference."""
    if p["lie_from_rep"] >= 1.0:
        return 0.0
    open_ = sum(1 for g, is_open in GATES.items() if g not in kind.exempt and is_open(float(p[g])))
    return SILENCE ** open_ * max(decoy(p), float(kind.planted(p)))


def noise(seed: int, params: dict) -> float:
    """A run's noise: shared by every attack on ``seed``, plus the attack's own on it (a pure function)."""
    shared = np.random.default_rng([seed % 2**63, 0]).normal(0.0, SHARED_SD)
    key = int(hashlib.sha256(repr(sorted(params.items())).encode()).hexdigest()[:15], 16)
    return float(shared + np.random.default_rng([seed % 2**63, key]).normal(0.0, OWN_SD))


def items(kind: Kind, params: dict, seed: int) -> float:
    return BASE - damage(kind, params) + noise(seed, params)
