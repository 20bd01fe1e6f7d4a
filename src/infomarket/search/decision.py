"""The worst case of a cell decided over every confirmed attack, with intervals at the decision's level.

Each role a cell confirmed (the search's attack, the random search's, the best baselines, the adaptive
attacker where it ran) has a per-seed loss l_r,i = 1 - items(r)_i / items(reference)_i on the same
confirmation seeds.  "Is the loss within the margin m?" is asked of the worst attack, which is unknown;
so:

- **yes** by intersection-union: every role's loss is shown below m (signed-rank of l_r - m, "less"),
  the cell's p-value the largest of its roles' (no adjustment over roles: an intersection-union test
  at level alpha needs every one of its tests at alpha), Holm over the cells of the question's family;
- **no** when some role's loss is shown above m (signed-rank of l_r - m, "greater"), Holm over every
  (cell, role) of the family: any one attack beyond the margin answers "no";
- otherwise inconclusive.

The worst case reported is the most damaging confirmed role (the highest Hodges-Lehmann loss).  Each
interval is printed at the level its test was judged at in Holm's step-down (``holm_levels``): its
upper end is the one-sided bound at the cell's "within" level, its lower end the one-sided bound at the
role's "beyond" level, so an interval that excludes the margin is a decision taken, and one that holds
it is none (up to the signed-rank test's ties and zeros).
"""
from __future__ import annotations

import math

import numpy as np

from ..analysis import paired_runs as pr
from ..analysis import stats


def holm_levels(pvalues, alpha: float) -> tuple[list[bool], list[float]]:
    """Holm's step-down over ``pvalues``: (rejected, level) per hypothesis, where ``level`` is the
    threshold it was judged at: alpha / (K - j + 1) at the step j it was rejected, and, for every one
    not rejected, the threshold of the step where the procedure stopped."""
    p = [float(v) for v in pvalues]
    k = len(p)
    order = sorted(range(k), key=lambda i: (p[i], i))
    rejected, level = [False] * k, [math.nan] * k
    stop = None
    for j, i in enumerate(order):
        a = alpha / (k - j)
        if stop is None and p[i] < a:
            rejected[i], level[i] = True, a
        else:
            stop = a if stop is None else stop
            level[i] = stop
    return rejected, level


def bound(values, level: float, side: str) -> float:
    """The one-sided distribution-free bound at ``level`` of the Hodges-Lehmann estimate of ``values``
    (``side`` "upper" or "lower"): the bound the signed-rank test at ``level`` inverts."""
    low, high, _ = pr.hl_interval(np.asarray(values, float), 1.0 - 2.0 * level)
    return high if side == "upper" else low


def bounded(losses: list[dict[str, np.ndarray]], groups: list[list[int]], margin: float,
            alpha: float = stats.ALPHA) -> list[dict]:
    """Per cell (``losses[c]``: role -> per-seed losses), the answer to "within ``margin``?" decided over
    every role, ``groups``: the cells' Holm families (lists of indices).  Returns per cell: ``answer``,
    ``worst`` {role, loss}, ``roles`` {role: {loss, interval, p_within, p_beyond, level_within,
    level_beyond, beyond}}, ``p_within`` (the intersection-union p) and ``level_within``."""
    out = [dict() for _ in losses]
    p_in = {c: {r: pr.wilcoxon_p(v - margin, "less") for r, v in ls.items()} for c, ls in enumerate(losses)}
    p_out = {c: {r: pr.wilcoxon_p(v - margin, "greater") for r, v in ls.items()} for c, ls in enumerate(losses)}
    for idx in groups:
        iut = [max(p_in[c].values(), default=1.0) for c in idx]  # a cell with no attack shows nothing
        rej, lev = holm_levels(iut, alpha)
        pairs = [(c, r) for c in idx for r in losses[c]]
        rej_b, lev_b = holm_levels([p_out[c][r] for c, r in pairs], alpha)
        beyond = {cr: (b, lv) for cr, b, lv in zip(pairs, rej_b, lev_b)}
        for c, p, yes, lv in zip(idx, iut, rej, lev):
            roles = {}
            for r, v in losses[c].items():
                b, lvb = beyond[(c, r)]
                roles[r] = {"loss": pr.hodges_lehmann(v), "interval": [bound(v, lvb, "lower"), bound(v, lv, "upper")],
                            "p_within": p_in[c][r], "p_beyond": p_out[c][r], "level_within": lv,
                            "level_beyond": lvb, "beyond": b}
            if not roles:
                out[c] = {"answer": stats.INCONCLUSIVE, "max_loss": margin, "worst": {}, "roles": {},
                          "p_within": p, "level_within": lv}
                continue
            no = any(x["beyond"] for x in roles.values())
            worst = max(roles, key=lambda r: (roles[r]["loss"], -list(roles).index(r)))
            out[c] = {"answer": stats.answer(yes, no), "max_loss": margin, "worst": {"role": worst,
                      "loss": roles[worst]["loss"]}, "roles": roles, "p_within": p, "level_within": lv}
    return out


def dominated(damage: dict[str, np.ndarray], mine: str = "search") -> list[tuple[str, float]]:
    """(role, one-sided signed-rank p) of each other role against ``mine``, H1: the role's per-seed damage
    value is below ``mine``'s (a more damaging attack than the search's own); the caller adjusts them."""
    if mine not in damage:
        return []
    return [(r, pr.wilcoxon_p(v - damage[mine], "less")) for r, v in damage.items() if r != mine]
