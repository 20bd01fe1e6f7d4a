"""Small compiled geometry helpers; angles in degrees throughout, as in the model."""
import math

from numba import njit

DEG = math.pi / 180.0


@njit(inline="always")
def rotate(x, y, deg):
    """Rotate (x, y) counter-clockwise by ``deg`` degrees."""
    a = deg * DEG
    c = math.cos(a)
    s = math.sin(a)
    return c * x - s * y, s * x + c * y


@njit(inline="always")
def direction(x, y):
    """Direction of (x, y) in degrees, in [0, 360)."""
    d = math.atan2(y, x) / DEG
    if d < 0.0:
        d += 360.0
    if d >= 360.0:
        d -= 360.0
    return d


@njit(inline="always")
def norm(x, y):
    return math.sqrt(x * x + y * y)


@njit(inline="always")
def angular_distance(a, b):
    """Smallest absolute difference between two directions in degrees, in [0, 180]."""
    d = abs(a - b)
    if d >= 360.0:  # only for directions outside [0, 360): fmod is a library call, keep it off the hot path
        d = d % 360.0
    if d > 180.0:
        d = 360.0 - d
    return d
