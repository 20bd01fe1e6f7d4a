"""The statistics the reports use: tests and intervals come from scipy; the few pieces scipy lacks (the
Hodges-Lehmann shift, Cliff's delta, Holm's adjustment, simulated power) are short and tested against
hand calculations.

- Mann-Whitney U (Figs. 3-4): one-sided, honest > Byzantine, because the paper's claim is that the
  honest distribution is higher, not merely different.
- Pearson r with its confidence interval (Fig. 6), from ``scipy.stats.pearsonr``.
- Bootstrap bands (Figs. 5-6): percentile bootstrap, which stays defined when every sample is equal
  (at step 0 every robot holds the same wealth, where BCa would return NaN).  Resampling is seeded, so
  a report is reproducible byte for byte.

Run-level comparisons: every research answer and report verdict
that compares two conditions goes through ``compare`` / ``answer_*`` here, so each states

- the effect with an interval: the Hodges-Lehmann shift (median of all pairwise differences x_i - y_j,
  in the data's unit) and Cliff's delta (P(x > y) - P(x < y)), each with a seeded percentile bootstrap
  interval (``scipy.stats.bootstrap``, groups resampled independently);
- the test: Mann-Whitney U (``scipy.stats.mannwhitneyu``), one-sided in the direction asked, against a
  null shift (``margin``) for non-inferiority; two one-sided tests (TOST) for equivalence;
- Holm's step-down adjustment over the comparisons a question spans (``holm``; statsmodels is not in
  the environment, so it is the short textbook procedure, checked against a hand example);
- the power the run count gives for the declared effect, by SIMULATION (``power``): the groups' residuals
  around their medians are pooled and resampled (seeded), the declared shift is added to the first
  group, and the fraction of Mann-Whitney rejections at alpha is the power.  It is a location-shift model
  whose noise is the observed noise (not the observed effect: "observed power" is not used);
- the smallest p-value the run counts allow (exact Mann-Whitney: 1 / C(n + m, n) one-sided), so that a
  question whose run count cannot reach its alpha, or reach its power, says "inconclusive", never "no".
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy import stats

from ..errors import ArgumentError

CONFIDENCE = 0.95
RESAMPLES = 2000
SEED = 20240613
ALPHA = 0.05
POWER = 0.80       # the power a "no" needs: below it, an undetected effect is "inconclusive"
POWER_SIMS = 1000  # simulated experiments per power estimate (standard error <= 0.016)
YES, NO, INCONCLUSIVE = "yes", "no", "inconclusive"
N_TOO_SMALL = "n too small"  # the note an inconclusive answer carries when no run count could have decided it
BATCH = 100  # resamples held in memory at once: 100 x 32 runs x 1001 steps x 8 B = 26 MB for Fig. 5


@dataclass(frozen=True)
class MannWhitney:
    """A one-sided Mann-Whitney U test's statistic and p-value, with the two group sizes."""
    statistic: float
    pvalue: float
    n_honest: int
    n_byzantine: int


def mann_whitney(honest, byzantine) -> MannWhitney:
    """One-sided Mann-Whitney U test that ``honest`` values tend to exceed ``byzantine`` values."""
    h, b = np.asarray(honest, float), np.asarray(byzantine, float)
    if len(h) == 0 or len(b) == 0:
        raise ArgumentError("Mann-Whitney U needs at least one value in each group")
    res = stats.mannwhitneyu(h, b, alternative="greater")
    return MannWhitney(float(res.statistic), float(res.pvalue), len(h), len(b))


@dataclass(frozen=True)
class Correlation:
    """A correlation coefficient ``r`` with its p-value, its confidence interval and the number of pairs."""
    r: float
    pvalue: float
    low: float   # confidence interval of r
    high: float
    n: int


def pearson(x, y, confidence: float = CONFIDENCE) -> Correlation:
    """Pearson r, its two-sided p-value and its confidence interval (Fisher transformation, scipy)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    res = stats.pearsonr(x, y)
    ci = res.confidence_interval(confidence_level=confidence)
    return Correlation(float(res.statistic), float(res.pvalue), float(ci.low), float(ci.high), len(x))


@dataclass(frozen=True)
class Band:
    """A curve with its confidence band, all arrays of the same length."""

    centre: np.ndarray
    low: np.ndarray
    high: np.ndarray


def mean_band(samples: np.ndarray, confidence: float = CONFIDENCE, resamples: int = RESAMPLES,
              seed: int = SEED) -> Band:
    """Mean over axis 0 (independent samples, e.g. runs) of ``samples`` [n, points], with a bootstrap CI
    at every point.  With a single sample the band collapses onto the mean."""
    samples = np.asarray(samples, float)
    centre = samples.mean(axis=0)
    if samples.shape[0] < 2:
        return Band(centre, centre.copy(), centre.copy())
    res = stats.bootstrap((samples,), np.mean, axis=0, vectorized=True, n_resamples=resamples, batch=BATCH,
                          confidence_level=confidence, method="percentile", rng=np.random.default_rng(seed))
    return Band(centre, res.confidence_interval.low, res.confidence_interval.high)


def regression_band(x, y, grid, confidence: float = CONFIDENCE, resamples: int = RESAMPLES,
                    seed: int = SEED) -> Band:
    """Least-squares line of ``y`` on ``x`` evaluated on ``grid``, with a pairs-bootstrap CI of the line
    (the band seaborn's regplot draws, without seaborn)."""
    x, y, grid = np.asarray(x, float), np.asarray(y, float), np.asarray(grid, float)
    fit = stats.linregress(x, y)
    centre = fit.intercept + fit.slope * grid

    def line(xs, ys):
        f = stats.linregress(xs, ys)
        return f.intercept + f.slope * grid

    res = stats.bootstrap((x, y), line, paired=True, vectorized=False, n_resamples=resamples,
                          confidence_level=confidence, method="percentile", rng=np.random.default_rng(seed))
    return Band(centre, res.confidence_interval.low, res.confidence_interval.high)


# ------------------------------------------------------------------------------ run-level comparisons
def _pairwise(x: np.ndarray, y: np.ndarray, axis: int = -1) -> np.ndarray:
    """All differences x_i - y_j, flattened onto the last axis (leading axes broadcast)."""
    x, y = np.moveaxis(np.asarray(x, float), axis, -1), np.moveaxis(np.asarray(y, float), axis, -1)
    d = x[..., :, None] - y[..., None, :]
    return d.reshape(*d.shape[:-2], -1)


def hodges_lehmann(x, y, axis: int = -1):
    """Hodges-Lehmann estimate of the shift of ``x`` over ``y``: the median of all x_i - y_j."""
    return np.median(_pairwise(x, y, axis), axis=-1)


def cliffs_delta(x, y, axis: int = -1):
    """Cliff's delta: P(x > y) - P(x < y) over all pairs, in [-1, 1] (0: neither tends to exceed)."""
    return np.mean(np.sign(_pairwise(x, y, axis)), axis=-1)


def min_pvalue(n: int, m: int, alternative: str = "greater") -> float:
    """The smallest p-value an exact Mann-Whitney test of ``n`` against ``m`` values can give:
    1 / C(n + m, n) one-sided (the one most extreme ordering), twice that two-sided."""
    if n < 1 or m < 1:
        return 1.0
    p = 1.0 / math.comb(n + m, n)
    return min(1.0, 2.0 * p) if alternative == "two-sided" else p


def mw_pvalue(x, y, alternative: str = "greater", shift: float = 0.0) -> float:
    """Mann-Whitney U p-value of ``x + shift`` against ``y`` (scipy; exact for small untied samples).
    ``shift`` > 0 with "greater" tests non-inferiority: H0 "x is worse than y by ``shift`` or more"."""
    x, y = np.asarray(x, float) + shift, np.asarray(y, float)
    return float(stats.mannwhitneyu(x, y, alternative=alternative).pvalue)


def power(x, y, shift: float, alpha: float = ALPHA, alternative: str = "greater", sims: int = POWER_SIMS,
          seed: int = SEED) -> float:
    """Simulated power of the one-sided Mann-Whitney test of ``x`` against ``y`` (``alternative``
    "greater" or "less") with ``len(x)`` and ``len(y)`` runs, when x + ``shift`` and y differ only by
    noise: ``shift`` is the true shift of x over y plus the test's own null shift.  Noise model: residuals
    of both groups around their own medians, pooled and resampled with replacement (seeded).  Zero when
    the run counts cannot reach ``alpha`` at all."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    n, m = len(x), len(y)
    if min_pvalue(n, m, alternative) >= alpha:
        return 0.0
    resid = np.concatenate([x - np.median(x), y - np.median(y)])
    rng = np.random.default_rng(seed)
    sx = rng.choice(resid, (sims, n)) + shift
    sy = rng.choice(resid, (sims, m))
    p = stats.mannwhitneyu(sx, sy, axis=1, alternative=alternative).pvalue
    return float(np.mean(p < alpha))


@dataclass(frozen=True)
class Effect:
    """Run-level effect of x over y with percentile bootstrap intervals (NaN with fewer than 2 runs)."""

    hl: float
    hl_low: float
    hl_high: float
    delta: float
    delta_low: float
    delta_high: float
    confidence: float


def effect(x, y, confidence: float = CONFIDENCE, resamples: int = RESAMPLES, seed: int = SEED) -> Effect:
    """Hodges-Lehmann shift and Cliff's delta of ``x`` over ``y``, each with a bootstrap interval
    (``scipy.stats.bootstrap``, the two groups resampled independently, percentile method, seeded)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    hl, delta = float(hodges_lehmann(x, y)), float(cliffs_delta(x, y))
    if len(x) < 2 or len(y) < 2:
        return Effect(hl, math.nan, math.nan, delta, math.nan, math.nan, confidence)
    ci = []
    for fn in (hodges_lehmann, cliffs_delta):
        res = stats.bootstrap((x, y), fn, vectorized=True, paired=False, n_resamples=resamples, batch=BATCH * 5,
                              confidence_level=confidence, method="percentile", rng=np.random.default_rng(seed))
        ci.append((float(res.confidence_interval.low), float(res.confidence_interval.high)))
    return Effect(hl, *ci[0], delta, *ci[1], confidence)


@dataclass(frozen=True)
class Comparison:
    """One run-level comparison of runs x against runs y, everything a verdict rests on.

    ``test`` is the alternative hypothesis (e.g. "x > y", "x > y - 33": non-inferiority within 33);
    ``p`` the raw Mann-Whitney p-value, ``p_adjusted`` the Holm-adjusted one (== p outside a family);
    ``power`` the simulated power at alpha / family when the true shift of x over y is ``declared``
    (NaN when no effect was declared); ``min_p`` the smallest p-value these run counts allow."""

    label: str
    test: str
    n_x: int
    n_y: int
    median_x: float
    median_y: float
    effect: Effect
    p: float
    p_adjusted: float
    min_p: float
    declared: float
    power: float
    alpha: float
    family: int = 1     # how many comparisons the Holm adjustment spans

    @property
    def significant(self) -> bool:
        """Whether the Holm-adjusted p-value is below alpha."""
        return self.p_adjusted < self.alpha

    def describe(self, unit: str = "") -> str:
        """One line for a report: medians and sizes, Hodges-Lehmann shift and Cliff's delta with intervals, the
        p-value (Holm-adjusted in a family) and the power; ``unit`` follows each effect."""
        e = self.effect
        adj = (f", Holm-adjusted over {self.family} {_fmt_p(self.p_adjusted)}"
               if self.family > 1 or self.p_adjusted != self.p else "")
        pw = ("" if math.isnan(self.power)
              else f", power {self.power:.2f} if the true shift is {self.declared:+.3g}{unit}")
        return (f"{self.label}: medians {self.median_x:.4g} vs {self.median_y:.4g} (n = {self.n_x}, {self.n_y}), "
                f"HL shift {e.hl:+.3g}{unit} [{e.hl_low:.3g}, {e.hl_high:.3g}], Cliff's delta {e.delta:+.2f} "
                f"[{e.delta_low:.2f}, {e.delta_high:.2f}]; Mann-Whitney {self.test}: p = {_fmt_p(self.p)}{adj}{pw}")


def _fmt_p(p: float) -> str:
    return f"{p:.1e}" if p < 0.001 else f"{p:.3f}"


def compare(x, y, *, alternative: str = "greater", shift: float = 0.0, declared: float | None = None,
            alpha: float = ALPHA, family: int = 1, label: str = "x vs y", seed: int = SEED) -> Comparison:
    """Compare runs ``x`` against runs ``y``: Mann-Whitney of x + ``shift`` against y, one-sided.

    - superiority: ``shift`` 0, H1 x > y ("greater") or x < y ("less");
    - non-inferiority within m: ``shift`` +m, "greater": H1 x > y - m;
    - non-superiority within m: ``shift`` -m, "less": H1 x < y + m;
    - shown below y - m: ``shift`` +m, "less": H1 x < y - m.
    ``declared``: the true shift of x over y the power is computed for (e.g. +m for "is x better by
    the smallest effect of interest", 0 for "can non-inferiority be shown when nothing differs");
    ``family``: the size of the Holm family the comparison belongs to (power is computed at alpha / family)."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) == 0 or len(y) == 0:
        raise ArgumentError("a comparison needs at least one run in each group")
    op = ">" if alternative == "greater" else "<"
    test = f"x {op} y" + (f" {'-' if shift > 0 else '+'} {abs(shift):.3g}" if shift else "")
    p = mw_pvalue(x, y, alternative, shift)
    pw = math.nan if declared is None else power(x, y, shift + declared, alpha / family, alternative, seed=seed)
    return Comparison(label, test, len(x), len(y), float(np.median(x)), float(np.median(y)),
                      effect(x, y, seed=seed), p, p, min_pvalue(len(x), len(y), alternative),
                      math.nan if declared is None else float(declared), pw, alpha)


def holm(pvalues) -> np.ndarray:
    """Holm's step-down adjusted p-values (Holm 1979): sort ascending, p_(i) times (k - i + 1) for the
    i-th smallest, made monotone by a running maximum, capped at 1; returned in the input order.
    Rejecting where adjusted p < alpha controls the family-wise error rate at alpha."""
    p = np.asarray(pvalues, float)
    k = len(p)
    order = np.argsort(p, kind="stable")
    adj = np.minimum(1.0, np.maximum.accumulate((k - np.arange(k)) * p[order]))
    out = np.empty(k)
    out[order] = adj
    return out


def adjust(comparisons: list[Comparison]) -> list[Comparison]:
    """The comparisons of one question with Holm-adjusted p-values (unchanged for a single one)."""
    adj = holm([c.p for c in comparisons])
    return [replace(c, p_adjusted=float(a), family=len(comparisons)) for c, a in zip(comparisons, adj)]


def tost(x, y, margin: float, alpha: float = ALPHA, seed: int = SEED) -> tuple[float, Comparison, Comparison]:
    """Equivalence of x and y within +/- ``margin`` by two one-sided Mann-Whitney tests (TOST):
    H1 x > y - margin and H1 x < y + margin; the equivalence p-value is the larger of the two."""
    lo = compare(x, y, alternative="greater", shift=margin, alpha=alpha, label="x > y - margin", seed=seed)
    hi = compare(x, y, alternative="less", shift=-margin, alpha=alpha, label="x < y + margin", seed=seed)
    return max(lo.p, hi.p), lo, hi


def too_few_runs(comparisons) -> bool:
    """Whether the run counts cannot reach alpha in any of these comparisons: even the most extreme
    ordering of the runs (``min_p``), Holm-adjusted over the family (x ``family``), is not below alpha."""
    comparisons = list(comparisons)
    return bool(comparisons) and all(c.min_p * c.family >= c.alpha for c in comparisons)


def shown(answer: str, note: str = "") -> str:
    """An answer as printed: ``inconclusive (n too small)`` when a note qualifies it."""
    return f"{answer} ({note})" if note else answer


def answer(yes: bool, no: bool) -> str:
    """yes / no from the evidence for each; neither (or, impossibly, both) is "inconclusive"."""
    if yes and not no:
        return YES
    if no and not yes:
        return NO
    return INCONCLUSIVE


def answer_superiority(comparisons: list[Comparison], min_hits: int = 1, target: float = POWER) -> str:
    """"Is x better than y at >= ``min_hits`` of these conditions?": yes when that many Holm-adjusted
    tests reject; no when fewer do AND at least ``min_hits`` of them had the power ``target`` for the
    declared effect (an effect of that size would most likely have been seen); else inconclusive."""
    hits = sum(c.significant for c in comparisons)
    powered = sum(c.power >= target for c in comparisons)
    if hits >= min_hits:
        return YES
    return NO if powered >= min_hits else INCONCLUSIVE


@dataclass(frozen=True)
class Paired:
    """Within-run differences (e.g. honest minus Byzantine mean wealth share of each run): the run is
    the sample, so honest and Byzantine values of one run are paired.  Wilcoxon signed-rank test
    (``scipy.stats.wilcoxon``), the Hodges-Lehmann pseudo-median (median of the Walsh averages) with a
    seeded percentile bootstrap interval."""

    n: int
    median: float
    hl: float
    hl_low: float
    hl_high: float
    p: float
    min_p: float       # 1 / 2^n one-sided: every difference of one sign
    alpha: float
    positive: float    # share of runs with a positive difference

    @property
    def significant(self) -> bool:
        """Whether the run-level p-value is below alpha."""
        return self.p < self.alpha

    def describe(self, unit: str = "") -> str:
        """One line for a report: the median difference, the Hodges-Lehmann pseudo-median with its interval, the
        share of positive runs and the p-value."""
        return (f"{self.n} runs, median difference {self.median:+.3g}{unit}, HL pseudo-median {self.hl:+.3g}{unit} "
                f"[{self.hl_low:.3g}, {self.hl_high:.3g}], positive in {100 * self.positive:.0f} % of runs; "
                f"Wilcoxon signed-rank (run-level) p = {_fmt_p(self.p)} (smallest possible {_fmt_p(self.min_p)})")


def walsh_median(d, axis: int = -1):
    """Hodges-Lehmann one-sample estimate: the median of the Walsh averages (d_i + d_j) / 2, i <= j."""
    d = np.moveaxis(np.asarray(d, float), axis, -1)
    i, j = np.triu_indices(d.shape[-1])
    return np.median((d[..., i] + d[..., j]) / 2.0, axis=-1)


def paired(d, alpha: float = ALPHA, alternative: str = "greater", confidence: float = CONFIDENCE,
           resamples: int = RESAMPLES, seed: int = SEED) -> Paired:
    """Run-level test of within-run differences ``d`` (one per run) being above zero ("greater")."""
    d = np.asarray(d, float)
    if len(d) == 0:
        raise ArgumentError("a paired test needs at least one run")
    p = float(stats.wilcoxon(d, alternative=alternative).pvalue) if np.any(d != 0) else 1.0
    lo = hi = math.nan
    if len(d) >= 2:
        res = stats.bootstrap((d,), walsh_median, vectorized=True, n_resamples=resamples, batch=BATCH * 5,
                              confidence_level=confidence, method="percentile", rng=np.random.default_rng(seed))
        lo, hi = float(res.confidence_interval.low), float(res.confidence_interval.high)
    return Paired(len(d), float(np.median(d)), float(walsh_median(d)), lo, hi, p,
                  0.5 ** len(d) * (2.0 if alternative == "two-sided" else 1.0), alpha, float(np.mean(d > 0)))


@dataclass(frozen=True)
class Ratio:
    """Ratio of medians x / y with a seeded percentile bootstrap interval (groups resampled apart)."""

    value: float
    low: float
    high: float
    confidence: float


def median_ratio(x, y, confidence: float = CONFIDENCE, resamples: int = RESAMPLES, seed: int = SEED) -> Ratio:
    """The ratio of medians ``median(x) / median(y)`` with a seeded percentile bootstrap interval.

    0 / 0 is NaN (no answer can rest on it) and x / 0 infinite; with fewer than two values in a group the
    interval is NaN.

    Example:
        >>> from infomarket.analysis.stats import median_ratio
        >>> median_ratio([2.0, 4.0, 6.0], [1.0, 2.0, 3.0]).value
        2.0
    """
    x, y = np.asarray(x, float), np.asarray(y, float)

    def ratio(a, b, axis=-1):  # 0 / 0 is undefined (NaN: no answer can rest on it), x / 0 infinite
        ma, mb = np.median(a, axis=axis), np.median(b, axis=axis)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(mb == 0, np.where(ma == 0, np.nan, np.inf), ma / np.where(mb == 0, 1.0, mb))

    value = float(ratio(x, y))
    if len(x) < 2 or len(y) < 2:
        return Ratio(value, math.nan, math.nan, confidence)
    res = stats.bootstrap((x, y), ratio, vectorized=True, paired=False, n_resamples=resamples, batch=BATCH * 5,
                          confidence_level=confidence, method="percentile", rng=np.random.default_rng(seed))
    return Ratio(value, float(res.confidence_interval.low), float(res.confidence_interval.high), confidence)


def answer_interval(r: Ratio, bound: float) -> str:
    """"Is the ratio at least ``bound``?" from its interval: yes when the whole interval is at or
    above it, no when the whole interval is below it, inconclusive when it straddles (or is undefined)."""
    if r.low >= bound:
        return YES
    if r.high < bound:
        return NO
    return INCONCLUSIVE
