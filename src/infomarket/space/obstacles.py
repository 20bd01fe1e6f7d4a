"""Obstacle geometry, compiled: distances from a point, and whether a segment is cut (line of sight).

Obstacles are rows of ``w.obs_kind`` / ``w.obs_geom`` (engine.params): a rectangle is (x0, y0, x1, y1)
with x0 < x1 and y0 < y1, a circle (x, y, radius, 0), a segment (x0, y0, x1, y1).  A robot is a disc of
radius ``r``: its disc *overlaps* an obstacle when the centre's distance to it is below ``r`` (so
positions may touch an obstacle, as they may touch the arena's edge), and a proximity sensor *fires*
when the probed position's distance is at most ``r`` (as ``x + r >= width`` does for the arena).
"""
import math

import numpy as np
from ..jit import njit

RECT = 0
CIRCLE = 1
SEGMENT = 2
SHAPES = ("rect", "circle", "segment")


@njit(forceinline=True, cache=True)
def segment_distance(x, y, ax, ay, bx, by):
    """Distance from (x, y) to the segment from (ax, ay) to (bx, by)."""
    ux = bx - ax
    uy = by - ay
    t = ((x - ax) * ux + (y - ay) * uy) / (ux * ux + uy * uy)
    t = min(max(t, 0.0), 1.0)
    dx = x - (ax + t * ux)
    dy = y - (ay + t * uy)
    return math.sqrt(dx * dx + dy * dy)


@njit(forceinline=True, cache=True)
def distance(kind, g0, g1, g2, g3, x, y):
    """Distance from (x, y) to one obstacle (0 inside a rectangle or a circle)."""
    if kind == RECT:
        dx = max(g0 - x, 0.0, x - g2)
        dy = max(g1 - y, 0.0, y - g3)
        return math.sqrt(dx * dx + dy * dy)
    if kind == CIRCLE:
        return max(math.sqrt((x - g0) * (x - g0) + (y - g1) * (y - g1)) - g2, 0.0)
    return segment_distance(x, y, g0, g1, g2, g3)


@njit(cache=True)
def nearest(kinds, geom, x, y):
    """Distance from (x, y) to the nearest obstacle (inf when there is none)."""
    best = np.inf
    for k in range(kinds.shape[0]):
        d = distance(kinds[k], geom[k, 0], geom[k, 1], geom[k, 2], geom[k, 3], x, y)
        if d < best:
            best = d
    return best


@njit(forceinline=True, cache=True)
def _cross(ax, ay, bx, by, cx, cy):
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


@njit(forceinline=True, cache=True)
def _on(ax, ay, bx, by, cx, cy):
    """c (collinear with a-b) lies within the bounding box of a-b."""
    return min(ax, bx) <= cx <= max(ax, bx) and min(ay, by) <= cy <= max(ay, by)


@njit(forceinline=True, cache=True)
def segments_meet(ax, ay, bx, by, cx, cy, dx, dy):
    """Do the closed segments a-b and c-d share a point?"""
    d1 = _cross(cx, cy, dx, dy, ax, ay)
    d2 = _cross(cx, cy, dx, dy, bx, by)
    d3 = _cross(ax, ay, bx, by, cx, cy)
    d4 = _cross(ax, ay, bx, by, dx, dy)
    if ((d1 > 0.0 and d2 < 0.0) or (d1 < 0.0 and d2 > 0.0)) and ((d3 > 0.0 and d4 < 0.0) or (d3 < 0.0 and d4 > 0.0)):
        return True
    return ((d1 == 0.0 and _on(cx, cy, dx, dy, ax, ay)) or (d2 == 0.0 and _on(cx, cy, dx, dy, bx, by))
            or (d3 == 0.0 and _on(ax, ay, bx, by, cx, cy)) or (d4 == 0.0 and _on(ax, ay, bx, by, dx, dy)))


@njit(forceinline=True, cache=True)
def cuts(kind, g0, g1, g2, g3, ax, ay, bx, by):
    """Does the obstacle cut the segment a-b (share a point with it)?  Touching counts as cutting."""
    if kind == CIRCLE:
        return segment_distance(g0, g1, ax, ay, bx, by) <= g2
    if kind == SEGMENT:
        return segments_meet(ax, ay, bx, by, g0, g1, g2, g3)
    # rectangle: clip a-b to the slab of each axis (Liang-Barsky); a non-empty remainder meets it
    t0 = 0.0
    t1 = 1.0
    ux = bx - ax
    uy = by - ay
    for p, q in ((-ux, ax - g0), (ux, g2 - ax), (-uy, ay - g1), (uy, g3 - ay)):
        if p == 0.0:
            if q < 0.0:
                return False
        else:
            t = q / p
            if p < 0.0:
                t0 = max(t0, t)
            else:
                t1 = min(t1, t)
    return t0 <= t1


@njit(cache=True)
def sight_blocked(kinds, geom, ax, ay, bx, by):
    """Is the straight line between two points cut by any obstacle?"""
    for k in range(kinds.shape[0]):
        if cuts(kinds[k], geom[k, 0], geom[k, 1], geom[k, 2], geom[k, 3], ax, ay, bx, by):
            return True
    return False


def encode(obstacles) -> tuple[np.ndarray, np.ndarray]:
    """Config obstacles (config.schema) as the engine's (kinds [K], geometry [K, 4]) arrays."""
    kinds = np.zeros(len(obstacles), np.int64)
    geom = np.zeros((len(obstacles), 4))
    for k, o in enumerate(obstacles):
        kinds[k] = SHAPES.index(o.shape)
        geom[k] = (o.x, o.y, o.radius, 0.0) if o.shape == "circle" else (o.x0, o.y0, o.x1, o.y1)
    return kinds, geom
