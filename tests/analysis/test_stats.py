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
