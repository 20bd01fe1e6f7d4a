"""Small compiled geometry helpers: angles (in degrees throughout, as in the model), discs, the arena,
and a robot's own frame."""
import math

from ..jit import njit

DEG = math.pi / 180.0


@njit(forceinline=True, cache=True)
def rotate(x, y, deg):
    """Rotate (x, y) counter-clockwise by ``deg`` degrees."""
    a = deg * DEG
    c = math.cos(a)
    s = math.sin(a)
    return c * x - s * y, s * x + c * y


@njit(forceinline=True, cache=True)
def direction(x, y):
    """Direction of (x, y) in degrees, in [0, 360)."""
    d = math.atan2(y, x) / DEG
    if d < 0.0:
        d += 360.0
    if d >= 360.0:
        d -= 360.0
    return d


@njit(forceinline=True, cache=True)
def norm(x, y):
    """Length of the vector (x, y), compiled inline into the step."""
    return math.sqrt(x * x + y * y)


@njit(forceinline=True, cache=True)
def wrap360(d):
    """``d % 360`` for ``d >= 0``, bit for bit, without ``%``.

    numba lowers a float ``%`` to LLVM's ``frem``, which has no side effects, so LLVM computes it before
    the test that guards it: a guarded ``%`` in the outlier scheme called libm's x87 ``fmod`` for every
    pair of transactions (a fifth of Fig. 4C's step).  A loop is never hoisted.  It is binary long
    division by 360·2^k: each subtraction has m <= d < 2m, so it is exact (Sterbenz), as ``fmod`` is."""
    if d >= 360.0:
        if d == math.inf:
            return math.nan
        m = 360.0
        while m * 2.0 <= d:
            m *= 2.0
        while m >= 360.0:
            if d >= m:
                d -= m
            m *= 0.5
    return d


@njit(forceinline=True, cache=True)
def angular_distance(a, b):
    """Smallest absolute difference between two directions in degrees, in [0, 180]."""
    d = wrap360(abs(a - b))  # directions outside [0, 360) only: within, the reduction is one test
    if d > 180.0:
        d = 360.0 - d
    return d


@njit(forceinline=True, cache=True)
def within(x, y, cx, cy, r):
    """Strictly inside the circle of centre (cx, cy) and radius r."""
    dx = x - cx
    dy = y - cy
    return dx * dx + dy * dy < r * r


@njit(forceinline=True, cache=True)
def outside(x, y, r, width, height):
    """Would a robot disc centred at (x, y) leave the arena?"""
    return x + r >= width or x - r < 0.0 or y + r >= height or y - r < 0.0


@njit(forceinline=True, cache=True)
def to_frame(w, i, x, y):
    """A world-frame vector in robot i's frame (rotated by -heading)."""
    c = w.hdir[i, 0]
    s = w.hdir[i, 1]
    return c * x + s * y, c * y - s * x


@njit(forceinline=True, cache=True)
def to_world(w, i, x, y):
    """A vector in robot i's frame in the world frame (rotated by +heading)."""
    c = w.hdir[i, 0]
    s = w.hdir[i, 1]
    return c * x - s * y, s * x + c * y
