"""The statistics the paper reports, each a thin wrapper over scipy so no test or CI is hand-rolled.

- Mann-Whitney U (Figs. 3-4): one-sided, honest > Byzantine, because the paper's claim is that the
  honest distribution is higher, not merely different.
- Pearson r with its confidence interval (Fig. 6), from ``scipy.stats.pearsonr``.
- Bootstrap bands (Figs. 5-6): percentile bootstrap, which stays defined when every sample is equal
  (at step 0 every robot holds the same wealth, where BCa would return NaN).  Resampling is seeded, so
  a report is reproducible byte for byte.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import stats

CONFIDENCE = 0.95
RESAMPLES = 2000
SEED = 20240613
BATCH = 100  # resamples held in memory at once: 100 x 32 runs x 1001 steps x 8 B = 26 MB for Fig. 5


@dataclass(frozen=True)
class MannWhitney:
    statistic: float
    pvalue: float
    n_honest: int
    n_byzantine: int


def mann_whitney(honest, byzantine) -> MannWhitney:
    """One-sided Mann-Whitney U test that ``honest`` values tend to exceed ``byzantine`` values."""
    h, b = np.asarray(honest, float), np.asarray(byzantine, float)
    if len(h) == 0 or len(b) == 0:
        raise ValueError("Mann-Whitney U needs at least one value in each group")
    res = stats.mannwhitneyu(h, b, alternative="greater")
    return MannWhitney(float(res.statistic), float(res.pvalue), len(h), len(b))


@dataclass(frozen=True)
class Correlation:
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
