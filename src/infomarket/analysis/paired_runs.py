"""Paired comparisons: two conditions run on the same seeds, judged on their per-seed differences.

When every condition runs on one shared seed set (common random numbers), run *i* of x and run *i* of y
differ only by the condition, so the sample is the per-seed difference d_i = x_i - y_i, and the noise
the two conditions share cancels.  Unpaired tests (``stats.compare``) throw that away.  Here:

- the test is Wilcoxon's signed-rank test (``scipy.stats.wilcoxon``), one-sided, of d + ``shift``: a
  shift turns a superiority test into a non-inferiority test against a margin (H1 "x > y - m" is
  "d + m > 0");
- the effect is the Hodges-Lehmann estimate of the differences' centre, the median of the Walsh averages
  (d_i + d_j) / 2, i <= j, with its distribution-free confidence interval: the Walsh averages' order
  statistics at the ranks the signed-rank null distribution gives (Hollander & Wolfe, *Nonparametric
  Statistical Methods*, 3.6), so interval and test agree: the interval holds exactly the shifts the
  two-sided test at 1 - confidence does not reject;
- Holm's adjustment over a question's family (``stats.holm``);
- power and run counts by SIMULATION: differences drawn from a noise model (a pilot's differences,
  centred and resampled, or a normal with a stated sd) plus a declared true effect, tested as the study
  will test them; the run count is the smallest on a grid whose power reaches the target.

Zero differences are dropped by the test (scipy's default ``zero_method="wilcox"``) and by the interval
alike; with no non-zero difference left, nothing can be shown (p = 1).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy import stats as sps

from ..errors import ArgumentError
from .stats import ALPHA, CONFIDENCE, POWER, POWER_SIMS, SEED, _fmt_p, holm, walsh_median


def walsh_averages(d) -> np.ndarray:
    """Every (d_i + d_j) / 2 with i <= j, sorted: n (n + 1) / 2 values."""
    d = np.asarray(d, float)
    i, j = np.triu_indices(len(d))
    return np.sort((d[i] + d[j]) / 2.0)


def hodges_lehmann(d) -> float:
    """The Hodges-Lehmann estimate of the differences' centre: the median of their Walsh averages."""
    d = np.asarray(d, float)
    if len(d) == 0:
        raise ArgumentError("the Hodges-Lehmann estimate needs at least one difference")
    return float(walsh_median(d))


def signed_rank_null(n: int) -> np.ndarray:
    """P(T+ = t), t = 0 .. n (n + 1) / 2: the signed-rank statistic's distribution when each of n untied
    ranks is positive with probability 1/2 (the number of subsets of {1..n} summing to t, over 2^n)."""
    if n < 0:
        raise ArgumentError(f"signed-rank distribution of {n} differences")
    p = np.zeros(n * (n + 1) // 2 + 1)
    p[0] = 1.0
    for k in range(1, n + 1):  # rank k positive or not, each with probability 1/2
        top = k * (k + 1) // 2
        p[k:top + 1] = 0.5 * (p[k:top + 1] + p[:top + 1 - k])
        p[:k] *= 0.5
    return p


def interval_rank(n: int, confidence: float = CONFIDENCE) -> tuple[int, float]:
    """(k, coverage): the interval is the k-th smallest to the k-th largest Walsh average, k the largest
    with P(T+ <= k - 1) <= (1 - confidence) / 2; coverage = 1 - 2 P(T+ <= k - 1) >= confidence.  k = 0
    when even the widest interval (the extreme differences) has less coverage than asked."""
    cdf = np.cumsum(signed_rank_null(n))
    k = int(np.searchsorted(cdf, (1.0 - confidence) / 2.0 * (1 + 1e-12), side="right"))
    return k, (1.0 - 2.0 * float(cdf[k - 1])) if k else 1.0


def hl_interval(d, confidence: float = CONFIDENCE) -> tuple[float, float, float]:
    """(low, high, coverage) of the Hodges-Lehmann estimate of ``d`` (zeros dropped); (-inf, inf, 1)
    when too few non-zero differences can bound it at this confidence."""
    d = np.asarray(d, float)
    d = d[d != 0]
    k, cover = interval_rank(len(d), confidence)
    if k == 0:
        return -math.inf, math.inf, 1.0
    w = walsh_averages(d)
    return float(w[k - 1]), float(w[len(w) - k]), cover


#: up to this many differences, untied and non-zero, the signed-rank p-value is exact
EXACT = 50


def method(d) -> str:
    """"exact" for at most ``EXACT`` untied, non-zero differences (in every row), else "asymptotic" (the
    normal approximation with scipy's tie correction), never scipy's "auto", which with ties in few
    differences runs a permutation test: unseeded beyond 13 differences, and slow over many rows."""
    a = np.abs(np.atleast_2d(np.asarray(d, float)))
    if a.shape[-1] > EXACT or np.any(a == 0):
        return "asymptotic"
    s = np.sort(a, axis=-1)
    return "asymptotic" if np.any(s[..., 1:] == s[..., :-1]) else "exact"


def wilcoxon_p(d, alternative: str = "greater", shift: float = 0.0) -> float:
    """Signed-rank p-value of ``d + shift`` (``method``): "greater" tests H1 "the differences' centre
    is above -shift"."""
    d = np.asarray(d, float) + shift
    if not np.any(d != 0):
        return 1.0
    return float(sps.wilcoxon(d, alternative=alternative, method=method(d[d != 0])).pvalue)


def min_pvalue(n: int, alternative: str = "greater") -> float:
    """The smallest p-value n differences can give: 1 / 2^n one-sided (every sign the same)."""
    return min(1.0, 0.5 ** n * (2.0 if alternative == "two-sided" else 1.0))


# ------------------------------------------------------------------------------ power, run counts
def noise(pilot=None, *, sd: float | None = None):
    """A noise model for per-seed differences: a pilot's differences centred on their Hodges-Lehmann
    estimate (resampled with replacement), or, without a pilot, a normal with standard deviation ``sd``."""
    if pilot is not None:
        p = np.asarray(pilot, float)
        if len(p) < 2:
            raise ArgumentError("a pilot noise model needs at least two differences")
        resid = p - hodges_lehmann(p)
        return lambda rng, shape: rng.choice(resid, shape)
    if sd is None or not sd > 0:
        raise ArgumentError("a noise model needs a pilot's differences or a positive sd")
    return lambda rng, shape: rng.normal(0.0, sd, shape)


def power(model, n: int, effect: float, *, shift: float = 0.0, alternative: str = "greater",
          alpha: float = ALPHA, sims: int = POWER_SIMS, seed: int = SEED) -> float:
    """Simulated power of the one-sided signed-rank test of ``n`` differences drawn from ``model``
    (``noise``) around a true centre ``effect``, the test's null shifted by ``shift`` (as ``compare``):
    the fraction of ``sims`` simulated studies that reject at ``alpha`` (pass alpha / family for a Holm
    family: its first step).  Zero when n differences cannot reach alpha at all."""
    if n < 1 or min_pvalue(n, alternative) >= alpha:
        return 0.0
    d = model(np.random.default_rng(seed), (sims, n)) + effect + shift
    with np.errstate(invalid="ignore", divide="ignore"):  # a row of zeros: p is NaN, nothing shown
        p = sps.wilcoxon(d, alternative=alternative, axis=1, method=method(d)).pvalue
    return float(np.mean(p < alpha))


def runs_for_power(model, effect: float, *, shift: float = 0.0, alternative: str = "greater",
                   alpha: float = ALPHA, target: float = POWER, grid=range(8, 257, 8), sims: int = POWER_SIMS,
                   seed: int = SEED) -> tuple[int | None, float]:
    """(runs, power): the smallest run count of ``grid`` whose simulated ``power`` reaches ``target``
    (None and the last power when none does)."""
    pw = 0.0
    for n in grid:
        pw = power(model, n, effect, shift=shift, alternative=alternative, alpha=alpha, sims=sims, seed=seed)
        if pw >= target:
            return int(n), pw
    return None, pw


# ------------------------------------------------------------------------------ comparisons
@dataclass(frozen=True)
class PairedComparison:
    """Runs x against runs y of the same seeds: the per-seed differences d = x - y and everything a
    verdict rests on.  ``test`` names the alternative ("d > -0.5": non-inferiority within 0.5);
    ``p_adjusted`` is Holm's over the family (== p alone); ``power`` the simulated power at alpha /
    family when the true centre of d is ``declared`` (NaN when none was declared)."""

    label: str
    test: str
    n: int            # pairs
    median_x: float
    median_y: float
    hl: float         # Hodges-Lehmann estimate of d's centre
    low: float        # its distribution-free interval
    high: float
    confidence: float
    coverage: float   # the interval's exact coverage (>= confidence)
    p: float
    p_adjusted: float
    min_p: float
    declared: float
    power: float
    alpha: float
    family: int = 1

    @property
    def significant(self) -> bool:
        """Whether the Holm-adjusted p-value is below alpha."""
        return self.p_adjusted < self.alpha

    def describe(self, unit: str = "") -> str:
        """One line for a report: run count, medians, the Hodges-Lehmann shift with its interval, the p-value
        (Holm-adjusted in a family) and the power; ``unit`` follows each effect."""
        adj = f", Holm over {self.family} {_fmt_p(self.p_adjusted)}" if self.family > 1 else ""
        pw = "" if math.isnan(self.power) else f", power {self.power:.2f} at {self.declared:+.3g}{unit}"
        return (f"{self.label}: {self.n} paired runs, medians {self.median_x:.4g} vs {self.median_y:.4g}, "
                f"HL of the differences {self.hl:+.3g}{unit} [{self.low:.3g}, {self.high:.3g}]; "
                f"Wilcoxon {self.test}: p = {_fmt_p(self.p)}{adj}{pw}")


def pairs(x, y) -> tuple[np.ndarray, np.ndarray]:
    """``x`` and ``y`` as float arrays of equal length (run i of each on the same seed)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) != len(y) or len(x) == 0:
        raise ArgumentError(f"a paired comparison needs the same runs on each side (got {len(x)} and {len(y)})")
    return x, y


def compare(x, y, *, alternative: str = "greater", shift: float = 0.0, declared: float | None = None,
            alpha: float = ALPHA, family: int = 1, confidence: float = CONFIDENCE, label: str = "x - y",
            sims: int = POWER_SIMS, seed: int = SEED) -> PairedComparison:
    """Paired comparison of ``x`` and ``y`` (run i of each on the same seed): the signed-rank test of
    d + ``shift``, d = x - y, one-sided:

    - superiority: ``shift`` 0, H1 x > y ("greater") or x < y ("less");
    - non-inferiority within m: ``shift`` +m, "greater": H1 x > y - m;
    - shown beyond a margin m: ``shift`` -m, "greater": H1 x > y + m (or ``shift`` +m, "less": x < y - m).
    ``declared``: the true centre of d the power is simulated for, the noise being the observed
    differences centred (a location-shift model, not "observed power")."""
    x, y = pairs(x, y)
    d = x - y
    op = ">" if alternative == "greater" else "<"
    test = f"d {op} {-shift:.3g}" if shift else f"d {op} 0"
    low, high, cover = hl_interval(d, confidence)
    pw = math.nan
    if declared is not None:
        pw = power(noise(d), len(d), declared, shift=shift, alternative=alternative, alpha=alpha / family,
                   sims=sims, seed=seed) if len(d) >= 2 else 0.0
    p = wilcoxon_p(d, alternative, shift)
    return PairedComparison(label, test, len(d), float(np.median(x)), float(np.median(y)), hodges_lehmann(d),
                            low, high, confidence, cover, p, p, min_pvalue(len(d), alternative),
                            math.nan if declared is None else float(declared), pw, alpha, family)


def adjust(comparisons: list[PairedComparison]) -> list[PairedComparison]:
    """One question's comparisons with Holm-adjusted p-values over them (the family's size recorded)."""
    adj = holm([c.p for c in comparisons])
    return [replace(c, p_adjusted=float(a), family=len(comparisons)) for c, a in zip(comparisons, adj)]
