import math

import pytest

from infomarket.engine.geometry import angular_distance, direction, norm, rotate


def test_rotate_quarter_turn():
    x, y = rotate(1.0, 0.0, 90.0)
    assert x == pytest.approx(0.0, abs=1e-12) and y == pytest.approx(1.0)


def test_direction_is_in_0_360():
    assert direction(1.0, 0.0) == 0.0
    assert direction(0.0, -2.0) == pytest.approx(270.0)
    assert direction(-1.0, -1e-300) < 360.0


@pytest.mark.parametrize("a,b,d", [(10, 20, 10), (350, 10, 20), (0, 180, 180), (5, 725, 0)])
def test_angular_distance_is_circular(a, b, d):
    assert angular_distance(a, b) == pytest.approx(d)


def test_norm():
    assert norm(3.0, 4.0) == 5.0
    assert math.isclose(norm(1e-3, 0.0), 1e-3)
