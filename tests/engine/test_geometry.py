import math

import pytest

import numpy as np
from numba import njit

from infomarket.engine.geometry import angular_distance, direction, norm, rotate, wrap360


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


def test_wrap360_is_fmod_bit_for_bit():
    """The reference is libm's fmod through Python's math.fmod, on values spread over every exponent."""
    rng = np.random.default_rng(3)
    values = [0.0, 5e-324, 1e-300, 359.99999999999994, 360.0, 360.00000000000006, 719.9999999999999, 720.0,
              1080.0, 123456789.125, 2.0 ** 53 + 2, 1e300, 1.7976931348623157e308]
    values += list(rng.uniform(0.0, 720.0, 2000)) + list(10.0 ** rng.uniform(-5, 300, 2000))
    for v in values:
        assert wrap360(v) == math.fmod(v, 360.0), v
    assert math.isnan(wrap360(math.inf)) and math.isnan(wrap360(math.nan))


def test_angular_distance_compiles_without_a_float_remainder():
    """numba lowers ``%`` on floats to LLVM's frem, which LLVM hoists above the test that guards it:
    then every call pays a libm fmod.  The compiled distance must not contain one."""
    @njit
    def distance(a, b):
        return angular_distance(a, b)

    assert distance(350.0, 10.0) == 20.0
    ir = next(iter(distance.inspect_llvm().values()))
    assert "frem" not in ir and "fmod" not in ir
