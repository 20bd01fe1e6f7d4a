"""Paired statistics on per-seed differences: each expected value by hand (small n, enumerated on paper)
or from an independent computation (every sign vector enumerated; scipy's exact Wilcoxon test inverted;
a power that has a closed form)."""
from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from scipy import stats as sps

from infomarket.analysis import paired_runs as pr
from infomarket.errors import ArgumentError


def test_walsh_averages_and_hodges_lehmann_by_hand():
    # [0, 1, 5]: (0+0)/2, (0+1)/2, (0+5)/2, (1+1)/2, (1+5)/2, (5+5)/2 = 0, .5, 2.5, 1, 3, 5
    assert pr.walsh_averages([0, 1, 5]).tolist() == [0, 0.5, 1, 2.5, 3, 5]
    assert pr.hodges_lehmann([0, 1, 5]) == 1.75   # (1 + 2.5) / 2: not the median 1, not the mean 2
    assert pr.hodges_lehmann([1, 2, 3]) == 2.0    # 1, 1.5, 2, 2, 2.5, 3
    assert pr.hodges_lehmann([4.0]) == 4.0
    with pytest.raises(ArgumentError):
        pr.hodges_lehmann([])


def test_signed_rank_null_by_hand_and_by_enumerating_every_sign():
    # n = 3: subsets of {1,2,3} by sum: {} 0, {1} 1, {2} 2, {3} {1,2} 3, {1,3} 4, {2,3} 5, {1,2,3} 6
    assert (pr.signed_rank_null(3) * 8).tolist() == [1, 1, 1, 2, 1, 1, 1]
    for n in (1, 5, 10):
        counts = np.zeros(n * (n + 1) // 2 + 1)
        for signs in itertools.product((0, 1), repeat=n):
            counts[sum(r for r, s in zip(range(1, n + 1), signs) if s)] += 1
        np.testing.assert_array_equal(pr.signed_rank_null(n), counts / 2 ** n)


def test_interval_rank_by_hand():
    # n = 8: P(T+ <= 3) = (1 + 1 + 1 + 2) / 256 = 0.0195 <= 0.025 < P(T+ <= 4) = 7 / 256
    assert pr.interval_rank(8) == (4, 1 - 10 / 256)
    # n = 6: only T+ = 0 (1 / 64) is in the 2.5 % tail: the interval is the extreme differences
    assert pr.interval_rank(6) == (1, 1 - 2 / 64)
    # n = 5: 1 / 32 > 0.025, no interval of 95 % can be bounded by the data
    assert pr.interval_rank(5) == (0, 1.0)


def test_hl_interval_by_hand():
    # d = 1..8: Walsh sums i + j sorted 2, 3, 4, 4, ...: the 4th smallest average 2, the 4th largest 7
    low, high, cover = pr.hl_interval(np.arange(1.0, 9.0))
    assert (low, high, cover) == (2.0, 7.0, 1 - 10 / 256)
    # zeros are dropped: six non-zero differences, the interval is their extremes
    assert pr.hl_interval([0, 0, -1, 2, 3, 4, 5, 6])[:2] == (-1.0, 6.0)
    assert pr.hl_interval([1, 2, 3]) == (-math.inf, math.inf, 1.0)


@pytest.mark.parametrize("n", [8, 12, 15])
def test_hl_interval_is_scipys_exact_test_inverted(n):
    """The interval holds exactly the shifts theta at which scipy's exact two-sided signed-rank test of
    d - theta does not reject at 5 %: probed between consecutive Walsh averages."""
    d = np.random.default_rng(n).normal(0.4, 1.0, n)
    low, high, _ = pr.hl_interval(d)
    w = np.unique(pr.walsh_averages(d))
    for theta in (w[:-1] + w[1:]) / 2:
        p = sps.wilcoxon(d - theta, alternative="two-sided", method="exact").pvalue
        assert (p >= 0.05) == (low < theta < high), (theta, p, low, high)


def test_wilcoxon_p_by_hand_and_with_a_margin():
    d = [-0.5, -0.2, 0.3, 0.6, 1.0]
    # ranks of |d|: .2 (1, -), .3 (2, +), .5 (3, -), .6 (4, +), 1 (5, +): T+ = 11; P(T+ >= 11) = P(T+ <= 4)
    # = #{{}, {1}, {2}, {3}, {4}, {1,2}, {1,3}} / 32
    assert pr.wilcoxon_p(d) == pytest.approx(7 / 32)
    # shifted by a margin of 1 every difference is positive: T+ = 15, p = 1 / 32
    assert pr.wilcoxon_p(d, shift=1.0) == pytest.approx(1 / 32)
    assert pr.wilcoxon_p(d, alternative="less", shift=-1.1) == pytest.approx(1 / 32)
    # shifted by -1 the last difference is 0 and is dropped: four negative ones, p = 1 / 16
    assert pr.wilcoxon_p(d, alternative="less", shift=-1.0) == pytest.approx(1 / 16)
    assert pr.wilcoxon_p([0.0, 0.0]) == 1.0


def test_exact_only_for_few_untied_differences():
    assert pr.method([1.0, -2.0, 3.0]) == "exact"
    assert pr.method([1.0, -1.0, 3.0]) == "asymptotic"      # |d| tied
    assert pr.method([0.0, 1.0, 2.0]) == "asymptotic"
    assert pr.method(np.arange(1.0, 52.0)) == "asymptotic"  # 51 differences
    assert pr.method([[1.0, 2.0], [1.0, 1.0]]) == "asymptotic"  # any row tied
    # eight equal negative differences: all ranks 4.5, T+ = 0; mean 8 x 9 / 4 = 18, variance
    # 8 x 9 x 17 / 24 - (8^3 - 8) / 48 = 40.5 (tie-corrected): p = Phi(-18 / sqrt(40.5))
    assert pr.wilcoxon_p([-1.0] * 8, alternative="less") == pytest.approx(sps.norm.cdf(-18 / math.sqrt(40.5)))


def test_power_matches_its_closed_form():
    """n = 5 at alpha 0.05: only "all five positive" (p = 1/32) rejects, so with normal differences of
    centre 1 and sd 1 the power is Phi(1)^5 = 0.4214; 4 000 simulations: standard error 0.008."""
    exact = sps.norm.cdf(1.0) ** 5
    assert pr.power(pr.noise(sd=1.0), 5, 1.0, sims=4000) == pytest.approx(exact, abs=0.025)
    # 4 differences cannot reach alpha 0.05 (1/16): no power at all
    assert pr.power(pr.noise(sd=1.0), 4, 5.0) == 0.0
    # a non-inferiority test: true centre 0, margin 1 -> the same as centre 1 without a margin
    assert pr.power(pr.noise(sd=1.0), 5, 0.0, shift=1.0, sims=4000) == pytest.approx(exact, abs=0.025)


def test_runs_for_power_against_the_normal_approximation():
    """Normal differences, centre 0.5, sd 1, alpha 0.05 one-sided: the signed-rank test's power is about
    Phi(0.5 sqrt(0.955 n) - 1.645) (its efficiency 3/pi relative to the t-test), 0.80 at n = 26.2: the
    grid's first count above that is 32 and 24 stays below."""
    n, pw = pr.runs_for_power(pr.noise(sd=1.0), 0.5, sims=4000)
    assert n == 32 and pw >= 0.8
    assert pr.power(pr.noise(sd=1.0), 24, 0.5, sims=4000) < 0.8
    assert pr.runs_for_power(pr.noise(sd=1.0), 0.01, grid=[8, 16]) == (None, pytest.approx(0.06, abs=0.03))


def test_a_pilots_noise_is_its_centred_differences():
    rng = np.random.default_rng(0)
    draws = pr.noise([1.0, 2.0, 3.0, 10.0])(rng, (2000,))
    # HL of [1, 2, 3, 10]: Walsh 1 1.5 2 2 2.5 3 5.5 6 6.5 10 -> 2.75; residuals -1.75 -.75 .25 7.25
    assert set(np.round(draws, 6)) == {-1.75, -0.75, 0.25, 7.25}
    with pytest.raises(ArgumentError):
        pr.noise([1.0])
    with pytest.raises(ArgumentError):
        pr.noise(sd=0.0)


def test_compare_and_holm():
    x = np.array([10.5, 10.8, 11.3, 11.6, 12.0])
    y = np.full(5, 11.0)                     # d = -0.5, -0.2, 0.3, 0.6, 1.0 as above
    c = pr.compare(x, y, label="x - y")
    assert c.p == pytest.approx(7 / 32) and c.hl == pytest.approx(pr.hodges_lehmann(x - y))
    assert (c.n, c.median_x, c.median_y) == (5, 11.3, 11.0)
    assert math.isinf(c.low) and math.isnan(c.power)          # 5 pairs cannot bound a 95 % interval
    ni = pr.compare(x, y, shift=1.0)                          # within 1 of y: shown, 1 / 32
    assert ni.p == pytest.approx(1 / 32) and ni.significant and ni.test == "d > -1"
    with pytest.raises(ArgumentError):
        pr.compare([1.0, 2.0], [1.0])
    ps = [pr.compare(x, y, shift=s) for s in (1.0, 0.0, 0.25)]
    adj = pr.adjust(ps)
    # Holm by hand on p = (1/32, 7/32, p3): smallest x 3, then x 2, then x 1, running maximum
    p3 = ps[2].p
    order = sorted([(1 / 32, 0), (7 / 32, 1), (p3, 2)])
    run, want = 0.0, [0.0] * 3
    for i, (p, k) in enumerate(order):
        run = max(run, min(1.0, (3 - i) * p))
        want[k] = run
    assert [a.p_adjusted for a in adj] == pytest.approx(want)
    assert {a.family for a in adj} == {3}
    assert not adj[0].significant  # 3 / 32 after Holm


def test_compare_power_uses_the_family():
    rng = np.random.default_rng(3)
    y = rng.normal(10, 1, 40)
    x = y + rng.normal(-0.3, 0.5, 40)
    alone = pr.compare(x, y, alternative="less", declared=-0.3)
    in24 = pr.compare(x, y, alternative="less", declared=-0.3, family=24)
    assert 0 < in24.power < alone.power <= 1
