"""The robust combinations by hand, and their bound against f liars among 2f + 1 purchases.

The functions are the compiled ones the robust buyers call (``behaviours.robust``), run on plain arrays.
"""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from infomarket.behaviours.api import weighted
from infomarket.behaviours.robust import (coordinate_median, coordinate_trimmed_mean, geometric_median,
                                          trimmed_mean, weighted_median)


def _a(*values):
    return np.array(values, dtype=np.float64)


def test_median_of_three_with_one_rotated_by_90_degrees():
    # honest (100, 0) and (90, 10); the liar sells (100, 0) rotated by 90 degrees: (0, 100).
    # x: 0, 90, 100 -> 90; y: 0, 10, 100 -> 10.  The naive average would be (63.3, 36.7).
    assert coordinate_median(_a(100, 90, 0), _a(0, 10, 100), np.ones(3)) == (90.0, 10.0)


def test_median_of_an_even_count_is_halfway_and_weights_shift_it():
    assert weighted_median(_a(4, 1, 3, 2), np.ones(4)) == 2.5
    # cumulative weight in value order 1, 2, 7 of 7: half (3.5) is reached at the value 3
    assert weighted_median(_a(1, 2, 3), _a(1, 1, 5)) == 3.0
    # exactly half at 2 (weights 1 + 2 = 3 of 6): halfway to the next value
    assert weighted_median(_a(1, 2, 3), _a(1, 2, 3)) == 2.5
    assert weighted_median(_a(1, 2, 9), np.zeros(3)) == 2.0  # no weight at all: every value once


def test_a_trim_of_one_removes_exactly_the_planted_liar():
    # honest (40, 50), (60, 50), (50, 50), (50, 40) and a liar far up at (50, 1000).  Trimming one value
    # at each end: x 40, 50, 50, 50, 60 keeps 50, 50, 50; y 40, 50, 50, 50, 1000 drops the liar's 1000 (and
    # the honest 40 at the other end) and keeps 50, 50, 50: (50, 50).
    xs, ys = _a(40, 60, 50, 50, 50), _a(50, 50, 50, 40, 1000)
    assert coordinate_trimmed_mean(xs, ys, np.ones(5), 1) == (50.0, 50.0)
    # without the trim the liar pulls y to (50 + 50 + 50 + 40 + 1000) / 5 = 238
    assert coordinate_trimmed_mean(xs, ys, np.ones(5), 0) == (50.0, 238.0)


def test_a_trim_too_large_for_the_count_leaves_the_middle():
    # trim 5 of 3 values drops (3 - 1) // 2 = 1 at each end
    assert trimmed_mean(_a(1, 7, 100), np.ones(3), 5) == 7.0
    # the kept values weighed: 2 and 3 kept, weights 1 and 3 -> (2 + 9) / 4
    assert trimmed_mean(_a(1, 2, 3, 4), _a(9, 1, 3, 9), 1) == 2.75


def test_geometric_median_of_an_equilateral_triangle_is_its_centre():
    # every angle is 60 < 120 degrees, so the Fermat point is the centroid (1, 1/sqrt 3); Weiszfeld starts
    # from the coordinate median (1, 0), away from it
    s = math.sqrt(3.0)
    x, y = geometric_median(_a(0, 2, 1), _a(0, 0, s), np.ones(3), 30)
    assert (x, y) == pytest.approx((1.0, 1.0 / s), abs=1e-8)
    assert geometric_median(_a(0, 2, 1), _a(0, 0, s), np.ones(3), 0) == (1.0, 0.0)  # no step: the start


def test_geometric_median_stays_on_a_data_point_that_is_the_minimum():
    # a cross (+-1, 0), (0, +-1) with a fifth point at the centre: the unit pulls of the four cancel, so the
    # centre (a data point, where plain Weiszfeld divides by zero) is the minimum
    x, y = geometric_median(_a(1, -1, 0, 0, 0), _a(0, 0, 1, -1, 0), np.ones(5), 30)
    assert (x, y) == (0.0, 0.0)


def test_geometric_median_leaves_a_data_point_that_is_not_the_minimum():
    # (0, 0) weighs 1 and (10, 0) weighs 3: the minimum is the heavier point; the start (the weighted
    # coordinate median) is already there.  Two equal points and a third far off: the minimum is the pair.
    assert geometric_median(_a(0, 10), _a(0, 0), _a(1, 3), 10) == (10.0, 0.0)
    x, y = geometric_median(_a(0, 0, 30), _a(0, 0, 40), np.ones(3), 10)
    assert (x, y) == (0.0, 0.0)


# ---------------------------------------------------------------- f liars among 2f + 1 purchases

def _honest(rng, f, spread):
    """f + 1 honest vectors within ``spread`` of a centre."""
    centre = rng.uniform(-500, 500, 2)
    r = spread * np.sqrt(rng.uniform(0, 1, f + 1))
    a = rng.uniform(0, 2 * np.pi, f + 1)
    return centre, centre + np.stack([r * np.cos(a), r * np.sin(a)], axis=1)


def _liars(rng, centre, honest, f, spread, mode, distance):
    """f adversarial vectors: all at one far point in one direction, spread along one far ray (from
    ``distance`` / 2 to ``distance`` spreads from the centre), or each
    just outside the honest cloud on the same side (the hardest for a trimmed mean)."""
    phi = rng.uniform(0, 2 * np.pi)
    e = np.array([np.cos(phi), np.sin(phi)])
    if mode == "one_point":
        return np.tile(centre + distance * spread * e, (f, 1))
    if mode == "ray":
        return centre + np.outer(np.linspace(distance / 2, distance, f) * spread, e)
    return np.tile(honest.max(axis=0) + spread * 1e-3, (f, 1))


@settings(max_examples=200, deadline=None)
@given(f=st.integers(1, 5), spread=st.floats(0.5, 50.0), distance=st.floats(200.0, 1e5),
       mode=st.sampled_from(["one_point", "ray", "just_outside"]), seed=st.integers(0, 2**32 - 1))
def test_with_f_liars_among_2f_plus_1_the_robust_update_is_bounded_and_the_naive_one_is_not(
        f, spread, distance, mode, seed):
    rng = np.random.default_rng(seed)
    centre, honest = _honest(rng, f, spread)
    liars = _liars(rng, centre, honest, f, spread, mode, distance)
    v = np.concatenate([honest, liars])[rng.permutation(2 * f + 1)]
    xs, ys, ones = v[:, 0].copy(), v[:, 1].copy(), np.ones(2 * f + 1)
    lo, hi = honest.min(axis=0), honest.max(axis=0)
    # Median and trimmed mean (trim f): f + 1 of 2f + 1 values of each coordinate are honest, so whatever
    # is left after the trim lies between two honest values: inside the honest bounding box.
    for est in (coordinate_median(xs, ys, ones), coordinate_trimmed_mean(xs, ys, ones, f)):
        assert lo[0] <= est[0] <= hi[0] and lo[1] <= est[1] <= hi[1]
    # Geometric median: every Weiszfeld step lowers F(p) = sum |p - x_i|, so the answer p has
    # F(p) <= F(p0), p0 the coordinate median (within sqrt 2 spread of the centre c).  With h = f + 1 honest
    # within `spread` of c: h (D - spread) + sum_liars (|x_j - c| - D) <= F(p) <= F(p0)
    # <= h spread + sum_liars |x_j - c| + n sqrt(2) spread, so D = |p - c| <= spread (2h + sqrt 2 n) / (h - f).
    n, h = 2 * f + 1, f + 1
    bound = spread * (2 * h + math.sqrt(2) * n) / (h - f)
    gx, gy = geometric_median(xs, ys, ones, 30)
    assert math.hypot(gx - centre[0], gy - centre[1]) <= bound
    if mode != "just_outside":
        # the naive robot averages the purchases in (eqs. 4-5, equal ages), the liars last: it ends at
        # least half way to the last liar, beyond every bound above
        nx, ny = honest[0]
        for x, y in [*honest[1:], *liars]:
            nx, ny, _ = weighted(nx, ny, 10, x, y, 10)
        assert math.hypot(nx - centre[0], ny - centre[1]) > bound
