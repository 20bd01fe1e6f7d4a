import dataclasses

import numpy as np
import pytest

from infomarket.analysis import stats


def test_mann_whitney_finds_clearly_richer_honest_robots():
    rng = np.random.default_rng(1)
    mw = stats.mann_whitney(rng.normal(4.2, 0.3, 200), rng.normal(3.0, 0.3, 20))
    assert mw.pvalue < 0.001
    assert (mw.n_honest, mw.n_byzantine) == (200, 20)


def test_mann_whitney_is_one_sided():
    """Byzantine robots richer than honest ones is not evidence for the paper's claim."""
    rng = np.random.default_rng(2)
    assert stats.mann_whitney(rng.normal(3.0, 0.3, 200), rng.normal(4.2, 0.3, 20)).pvalue > 0.99


def test_mann_whitney_on_one_distribution_is_not_significant():
    rng = np.random.default_rng(3)
    assert stats.mann_whitney(rng.normal(4, 0.3, 200), rng.normal(4, 0.3, 40)).pvalue > 0.01


def test_mann_whitney_needs_both_groups():
    with pytest.raises(ValueError):
        stats.mann_whitney([1.0, 2.0], [])


def test_pearson_recovers_a_known_correlation_and_its_interval():
    rng = np.random.default_rng(4)
    n, rho = 5000, -0.6
    x = rng.normal(size=n)
    y = rho * x + np.sqrt(1 - rho**2) * rng.normal(size=n)
    c = stats.pearson(x, y)
    assert c.low < c.r < c.high and c.low < rho < c.high
    assert c.r == pytest.approx(rho, abs=0.03)
    assert c.n == n and c.pvalue < 1e-10


def test_mean_band_brackets_the_mean_and_narrows_with_more_runs():
    rng = np.random.default_rng(5)
    few, many = rng.normal(10, 2, (5, 30)), rng.normal(10, 2, (80, 30))
    for samples in (few, many):
        band = stats.mean_band(samples)
        np.testing.assert_allclose(band.centre, samples.mean(axis=0))
        assert np.all(band.low <= band.centre) and np.all(band.centre <= band.high)
    assert np.mean(stats.mean_band(many).high - stats.mean_band(many).low) < \
        np.mean(stats.mean_band(few).high - stats.mean_band(few).low)


def test_mean_band_covers_the_true_mean_about_95_percent_of_the_time():
    rng = np.random.default_rng(6)
    band = stats.mean_band(rng.normal(0.0, 1.0, (32, 400)))
    coverage = np.mean((band.low <= 0.0) & (0.0 <= band.high))
    assert 0.88 <= coverage <= 0.99


def test_mean_band_of_equal_samples_has_no_width():
    """At step 0 every robot has the same wealth: the band must be the value, not NaN."""
    band = stats.mean_band(np.full((8, 3), 0.04))
    np.testing.assert_allclose([band.low, band.high], 0.04)
    band = stats.mean_band(np.array([[1.0, 2.0]]))
    np.testing.assert_array_equal(band.low, band.high)


def test_regression_band_follows_least_squares():
    # x = 0, 1, 2, 3 (ten times each), y = 1, 3, 2, 5: by hand, mean x = 1.5, mean y = 2.75,
    # Sxy = 1.5*1.75 - 0.5*0.25 - 0.5*0.75 + 1.5*2.25 = 5.5, Sxx = 5, slope 1.1, intercept 2.75 - 1.65 = 1.1
    x = np.tile([0.0, 1.0, 2.0, 3.0], 10)
    y = np.tile([1.0, 3.0, 2.0, 5.0], 10)
    band = stats.regression_band(x, y, [0.0, 1.0, 3.0])
    np.testing.assert_allclose(band.centre, [1.1, 2.2, 4.4], rtol=1e-12)
    assert np.all(band.low < band.centre) and np.all(band.centre < band.high)


def test_regression_band_of_points_on_a_line_is_the_line():
    x = np.arange(10.0)
    band = stats.regression_band(x, 2 * x + 1, [0.0, 4.5, 20.0])
    for edge in (band.centre, band.low, band.high):
        np.testing.assert_allclose(edge, [1.0, 10.0, 41.0], rtol=1e-9)


# ------------------------------------------------------------------ run-level comparisons (issue 24)
def test_hodges_lehmann_is_the_median_of_pairwise_differences_by_hand():
    # x = 1, 2, 3; y = 0, 5: differences 1, -4, 2, -3, 3, -2 -> sorted -4 -3 -2 1 2 3 -> median -0.5
    assert stats.hodges_lehmann([1.0, 2.0, 3.0], [0.0, 5.0]) == -0.5
    # x = 10, 12; y = 1, 2, 4: differences 9, 8, 6, 11, 10, 8 -> 6 8 8 9 10 11 -> median 8.5
    assert stats.hodges_lehmann([10.0, 12.0], [1.0, 2.0, 4.0]) == 8.5


def test_cliffs_delta_by_hand():
    # x = 1, 2, 3; y = 0, 5: pairs x > y: (1,0), (2,0), (3,0) = 3; x < y: 3; delta = 0
    assert stats.cliffs_delta([1.0, 2.0, 3.0], [0.0, 5.0]) == 0.0
    # x = 3, 4; y = 1, 3: x > y: (3,1), (4,1), (4,3) = 3; ties (3,3) = 1; x < y: 0 -> 3/4
    assert stats.cliffs_delta([3.0, 4.0], [1.0, 3.0]) == 0.75
    assert stats.cliffs_delta([1.0], [2.0]) == -1.0


def test_smallest_mann_whitney_p_by_hand():
    # 2 vs 2 runs: C(4, 2) = 6 orderings, the most extreme one has p = 1/6
    assert stats.min_pvalue(2, 2) == pytest.approx(1 / 6)
    assert stats.min_pvalue(2, 2, "two-sided") == pytest.approx(1 / 3)
    assert stats.min_pvalue(8, 8) == pytest.approx(1 / 12870)
    # and scipy's exact test reaches exactly it on fully separated samples
    assert stats.mw_pvalue([3.0, 4.0], [1.0, 2.0]) == pytest.approx(1 / 6)


def test_effect_intervals_bracket_the_estimates_and_shift_with_the_data():
    rng = np.random.default_rng(7)
    y = rng.normal(100.0, 10.0, 32)
    e = stats.effect(y + 30.0, y)
    assert e.hl == pytest.approx(30.0)
    assert e.hl_low < 30.0 < e.hl_high and e.delta_low <= e.delta <= e.delta_high
    assert stats.effect(y + 30.0, y) == e  # seeded: the same numbers every time
    few = stats.effect([1.0], [2.0, 3.0])
    assert np.isnan(few.hl_low) and few.hl == -1.5


def test_holm_on_a_hand_example():
    # p = .01 .04 .03 .005 -> sorted .005 .01 .03 .04 times 4 3 2 1 -> .02 .03 .06 .04 -> running max
    # .02 .03 .06 .06 -> back in input order: .03 .06 .06 .02
    np.testing.assert_allclose(stats.holm([0.01, 0.04, 0.03, 0.005]), [0.03, 0.06, 0.06, 0.02])
    np.testing.assert_allclose(stats.holm([0.5, 0.9]), [1.0, 1.0])  # capped at 1
    np.testing.assert_allclose(stats.holm([0.02]), [0.02])


def test_holm_turns_a_single_marginal_angle_into_a_no():
    """The review's case: one of 4 angles at p = 0.03 is significant alone, not after Holm over 4."""
    rng = np.random.default_rng(8)
    comps = [stats.compare(rng.normal(0, 1, 8), rng.normal(0, 1, 8)) for _ in range(4)]
    comps[0] = dataclasses.replace(comps[0], p=0.03, p_adjusted=0.03)
    assert comps[0].significant
    assert not stats.adjust(comps)[0].significant
    assert stats.adjust(comps)[0].family == 4 and "Holm-adjusted over 4" in stats.adjust(comps)[0].describe()


def test_tost_shows_equivalence_of_equal_samples_and_refuses_a_shifted_one():
    y = np.arange(20.0)
    p, lo, hi = stats.tost(y, y, margin=10.0)
    assert p < 0.05 and lo.significant and hi.significant
    p, lo, hi = stats.tost(y + 12.0, y, margin=10.0)  # shifted beyond the margin: not equivalent
    assert p > 0.05 and not hi.significant


def test_non_inferiority_is_not_the_absence_of_a_difference():
    """Two runs each, equal medians: no difference is significant, and no equivalence can be shown."""
    c = stats.compare([10.0, 12.0], [11.0, 13.0], shift=2.0, declared=0.0)
    assert not c.significant and c.power == 0.0


def test_power_is_zero_where_alpha_is_out_of_reach_and_grows_with_runs():
    rng = np.random.default_rng(9)
    # 2 vs 2 runs: the smallest p is 1/6 > 0.05, so no effect can ever be detected
    assert stats.power([1.0, 2.0], [1.5, 2.5], shift=100.0) == 0.0
    small, large = rng.normal(0, 1, (2, 8)), rng.normal(0, 1, (2, 64))
    p8 = stats.power(small[0], small[1], shift=0.8)
    p64 = stats.power(large[0], large[1], shift=0.8)
    assert p8 < p64 and p64 > 0.9
    # with no true shift, the rejection rate is the test's size, near alpha
    assert stats.power(large[0], large[1], shift=0.0) < 0.1


def test_power_matches_the_normal_theory_value_for_a_known_shift():
    """Independent reference: for normal data the Mann-Whitney test has asymptotic relative efficiency
    3/pi against the t test, so its power at n = 32 per group, shift 0.6 sd, one-sided alpha 0.05 is
    about Phi(0.6 * sqrt(32 / 2 * 3 / pi) - 1.645) = Phi(0.700) = 0.758."""
    rng = np.random.default_rng(10)
    x, y = rng.normal(0, 1, 400), rng.normal(0, 1, 400)
    pw = stats.power(x[:32], y[:32], shift=0.6 * np.std(np.r_[x[:32], y[:32]], ddof=1), sims=2000)
    assert pw == pytest.approx(0.758, abs=0.08)


def test_an_underpowered_question_is_inconclusive_never_no():
    """2 runs per condition: even a huge real gain cannot be shown, so the answer is inconclusive."""
    c = stats.compare([100.0, 101.0], [1.0, 2.0], declared=50.0)
    assert not c.significant
    assert stats.answer_superiority([c]) == stats.INCONCLUSIVE
    # the same non-significant comparison with 32 runs and power for the effect is a "no"
    rng = np.random.default_rng(11)
    a, b = rng.normal(0, 1, 32), rng.normal(0, 1, 32)
    c32 = stats.compare(a, b, declared=2.0)
    assert not c32.significant and c32.power > 0.8
    assert stats.answer_superiority([c32]) == stats.NO


def test_answer_needs_evidence_for_either_side():
    assert stats.answer(True, False) == "yes" and stats.answer(False, True) == "no"
    assert stats.answer(False, False) == "inconclusive" and stats.answer(True, True) == "inconclusive"


def test_walsh_median_and_the_signed_rank_test_by_hand():
    # d = 1, 2, 4: Walsh averages 1, 1.5, 2.5, 2, 3, 4 -> sorted 1 1.5 2 2.5 3 4 -> median 2.25
    assert stats.walsh_median([1.0, 2.0, 4.0]) == 2.25
    # 5 runs, all positive and distinct: exact one-sided signed-rank p = 1 / 2^5
    pr = stats.paired([0.5, 1.0, 2.0, 3.0, 4.0])
    assert pr.p == pytest.approx(1 / 32) and pr.min_p == 1 / 32 and pr.positive == 1.0
    assert pr.hl_low <= pr.hl <= pr.hl_high


def test_a_ratio_answer_needs_its_whole_interval_on_one_side():
    rng = np.random.default_rng(12)
    y = rng.normal(100, 5, 32)
    assert stats.answer_interval(stats.median_ratio(y * 0.8, y), 0.5) == stats.YES
    assert stats.answer_interval(stats.median_ratio(y * 0.3, y), 0.5) == stats.NO
    assert stats.median_ratio([1.0, 3.0], [2.0, 2.0]).value == 1.0  # medians 2 / 2, by hand
    wide = stats.median_ratio(rng.uniform(0, 100, 4), rng.uniform(50, 150, 4))
    assert stats.answer_interval(wide, 0.5) == stats.INCONCLUSIVE
    # point estimate below the bound (32.5 / 100), but resampled medians reach 0.9: inconclusive, not no
    below = stats.median_ratio([10.0, 20.0, 45.0, 90.0], [100.0, 100.0, 100.0, 100.0])
    assert below.value == 0.325 and below.high >= 0.5
    assert stats.answer_interval(below, 0.5) == stats.INCONCLUSIVE
    # nothing collected in either condition: the ratio 0 / 0 is undefined, so no answer
    zero = stats.median_ratio([0.0, 0.0], [0.0, 0.0])
    assert np.isnan(zero.value) and stats.answer_interval(zero, 0.5) == stats.INCONCLUSIVE
