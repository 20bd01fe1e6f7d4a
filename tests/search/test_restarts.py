"""The restarts' plan, their start points, the random search's budget and the rotation grid."""
import numpy as np
import pytest

from infomarket.search import space
from infomarket.search.baselines import rotation_grid
from infomarket.search.restarts import Restarts, design, evaluations, plan, random_batches, spread_points
from infomarket.search.study import Settings


def test_the_plan_shares_the_budget_and_doubles_the_population():
    # by hand: a quarter of 256 (64) on spread start points; the other 192 in 4 shares of 48: populations
    # 8, then 16, 32 and 64 capped at 48 // 3 = 16
    s = Settings(budget=256, popsize=8, restarts=4, spread=0.25)
    assert spread_points(s) == 64
    assert [(leg.popsize, leg.generations) for leg in plan(s)] == [(8, 6), (16, 3), (16, 3), (16, 3)]
    assert evaluations(s) == 256
    # what a restart cannot use goes to the next: 75 after the 25 start points, shares 18, then 37 - 16 = 21,
    # 56 - 32 = 24, 75 - 56 = 19; populations 8 each (doubled, then capped at share // 3, never below 8)
    s = Settings(budget=100, popsize=8, restarts=4, spread=0.25)
    assert [(leg.popsize, leg.generations) for leg in plan(s)] == [(8, 2), (8, 2), (8, 3), (8, 2)]
    assert evaluations(s) == 25 + 72


def test_the_random_search_gets_the_same_budget_in_batches_of_a_population():
    # by hand: 5 start points (a quarter of 20), then 15 in shares of 7 (1 generation of 4) and 11 (2 of 4):
    # 17 evaluations, which the random search makes in batches of 4, 4, 4, 4 and 1
    s = Settings(budget=20, popsize=4, restarts=2, spread=0.25)
    batches = random_batches(s, space.dimension(), 3)
    assert evaluations(s) == 17 and [len(b) for b in batches] == [4, 4, 4, 4, 1]
    assert all(((0 <= b) & (b < 1)).all() for b in batches)


def test_start_points_spread_over_the_cube():
    pts = design(8, space.dimension(), 11)
    # a Sobol sequence of 8 points puts exactly one in each eighth of every coordinate's range
    for k in range(space.dimension()):
        assert sorted(np.floor(pts[:, k] * 8).astype(int)) == list(range(8))
    assert np.array_equal(pts, design(8, space.dimension(), 11))
    assert not np.array_equal(pts, design(8, space.dimension(), 12))


def test_each_restart_starts_where_it_is_told_and_replays_exactly():
    s = Settings(budget=15, popsize=2, restarts=3, sigma0=0.01, spread=0.2)
    starts = [np.full(space.dimension(), v) for v in (0.2, 0.5, 0.8)]

    def points(seed):
        rs, out = Restarts(s, space.dimension(), seed, lambda r: starts[r]), []
        while (asked := rs.ask()) is not None:
            out.append(asked)
            rs.tell([float(x.sum()) for x in asked[2]])
        return out

    got = points(5)
    assert [(r, g) for r, g, _ in got] == [(0, 0), (0, 1), (1, 0), (1, 1), (2, 0), (2, 1)]
    for r, _, X in got:
        assert np.abs(X - starts[r][0]).max() < 0.1  # sigma 0.01 around the start
    again = points(5)
    assert all(np.array_equal(a[2], b[2]) for a, b in zip(got, again))


@pytest.mark.parametrize("step, angles", [(15.0, 13), (45.0, 5), (50.0, 5), (180.0, 2)])
def test_the_rotation_grid_covers_0_to_180_alone_and_colluding_about_each_site(step, angles):
    grid = rotation_grid(step)
    assert len(grid) == angles * 2 * 3
    rotations = sorted({p["rot_base"] for p in grid.values()})
    assert rotations[0] == 0.0 and rotations[-1] == 180.0 and len(rotations) == angles
    assert grid["rot_000_solo_food"] == {"rot_base": 0.0, "collude": 0.0, "lie_site": 0.0}
    assert grid["rot_180_collude_both"] == {"rot_base": 180.0, "collude": 1.0, "lie_site": 2.0}
    defaults = {n: space.to_params(space.to_unit({}))[n] for n in space.NAMES}
    for p in grid.values():  # every grid point is a point of the search space
        assert space.to_params(space.to_unit(p)) == {**defaults, **p}
