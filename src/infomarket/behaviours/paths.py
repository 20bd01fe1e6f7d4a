"""Public helpers for rules that trade waypoint paths instead of one vector.

A robot's entry for a site may be a short polyline (``engine.paths``): the entry itself is the first
waypoint and up to ``PATH_POINTS - 1`` further waypoints follow, the last being the site, all positions
in the robot's own frame.  The step's paths variant (``engine.step``, ``engine.paths``) follows the legs in order and
dead-reckons every waypoint; a behaviour whose rules use these helpers must be registered with
``paths=True`` so that its runs compile that step (``register_behaviour(..., paths=True)``).

What is sold is the seller's path as it was at the start of the step: its offer (what its sell rule
returns: the first leg, from the seller to its first waypoint) followed by its further waypoints (the
seller's own; a sell rule shapes only the first leg).  What is bought (``buy_path``) is that path seen
from the buyer: the seller's position, then the seller's waypoints, rotated and shifted into the
buyer's frame, shortened to ``PATH_POINTS`` points by dropping the waypoints that bend the path least.
The transaction is recorded, and weighed by the payment schemes, with the direction of the first leg,
exactly as ``api.buy`` records the direction of a bought vector.
"""
import numpy as np
from ..jit import njit

from ..engine.geometry import norm
from ..engine.geometry import to_frame, to_world
from ..engine.world import PATH_POINTS
from .api import buy


@njit(forceinline=True, cache=True)
def was_blocked(w, me, site):
    """Did the robot bump into something while seeking ``site`` since it was last at such a site?"""
    return w.blocked[me, site]


@njit(forceinline=True, cache=True)
def path_length(w, me, site):
    """Number of waypoints after the entry in the robot's current path for ``site`` (this step's
    purchases included); 0 means the entry is one straight vector."""
    return w.new_path_count[me, site]


@njit(forceinline=True, cache=True)
def offered_path_length(w, seller, site):
    """Number of waypoints after the first leg in what ``seller`` offers for ``site`` this step."""
    return w.path_count[seller, site]


@njit(forceinline=True, cache=True)
def path_point(w, me, site, j):
    """Point j (0 = the entry, the first waypoint) of the robot's current path for ``site``: (x, y)."""
    if j == 0:
        return w.new_vec[me, site, 0], w.new_vec[me, site, 1]
    return w.new_path_vec[me, site, j - 1, 0], w.new_path_vec[me, site, j - 1, 1]


@njit(forceinline=True, cache=True)
def detour(ax, ay, bx, by, cx, cy):
    """How much longer a -> b -> c is than a -> c (0 when b lies on the segment)."""
    return norm(bx - ax, by - ay) + norm(cx - bx, cy - by) - norm(cx - ax, cy - ay)


@njit(forceinline=True, cache=True)
def shorten(pts, m, keep):
    """Drop interior points of the polyline (0, 0) -> pts[0] -> ... -> pts[m - 1] until at most
    ``keep`` remain: each time the one whose removal shortens the path least (the straightest corner).
    The last point (the site) always stays.  Works in place; returns the new count."""
    while m > keep and m > 1:
        best = 0
        best_d = np.inf
        for j in range(m - 1):
            ax, ay = (0.0, 0.0) if j == 0 else (pts[j - 1, 0], pts[j - 1, 1])
            d = detour(ax, ay, pts[j, 0], pts[j, 1], pts[j + 1, 0], pts[j + 1, 1])
            if d < best_d:
                best = j
                best_d = d
        for j in range(best, m - 1):
            pts[j, 0] = pts[j + 1, 0]
            pts[j, 1] = pts[j + 1, 1]
        m -= 1
    return m


@njit(forceinline=True, cache=True)
def install_points(w, me, site, pts, m, age):
    """Make the polyline pts[:m] (robot frame, m <= PATH_POINTS) the robot's entry for ``site``."""
    w.new_vec[me, site, 0] = pts[0, 0]
    w.new_vec[me, site, 1] = pts[0, 1]
    for j in range(1, m):
        w.new_path_vec[me, site, j - 1, 0] = pts[j, 0]
        w.new_path_vec[me, site, j - 1, 1] = pts[j, 1]
    w.new_path_count[me, site] = m - 1
    w.new_age[me, site] = age
    w.new_valid[me, site] = True


@njit(forceinline=True, cache=True)
def buy_path(w, me, seller, site):
    """Buy the seller's path for ``site`` and make it the robot's entry: (ok, age).

    The purchase itself is ``api.buy`` (stake, refusal, cooldown, the transaction with the direction of
    the seller's first leg in the buyer's frame).  The installed path is, in the buyer's frame, the
    seller's position, the seller's first waypoint, then its further waypoints, shortened to
    ``PATH_POINTS`` points (``shorten``).  A refused purchase changes nothing."""
    ok, fx, fy, age = buy(w, me, seller, site)
    if not ok:
        return False, 0
    pts = np.empty((PATH_POINTS + 1 + w.path_vec.shape[2], 2))
    ox, oy = to_frame(w, me, w.pos[seller, 0] - w.pos[me, 0], w.pos[seller, 1] - w.pos[me, 1])
    pts[0, 0] = ox
    pts[0, 1] = oy
    pts[1, 0] = fx  # buy returns the first waypoint already shifted by the seller's position
    pts[1, 1] = fy
    m = 2
    for j in range(w.path_count[seller, site]):
        gx, gy = to_world(w, seller, w.path_vec[seller, site, j, 0], w.path_vec[seller, site, j, 1])
        rx, ry = to_frame(w, me, gx, gy)
        pts[m, 0] = ox + rx
        pts[m, 1] = oy + ry
        m += 1
    m = shorten(pts, m, PATH_POINTS)
    install_points(w, me, site, pts, m, age)
    return True, age


@njit(forceinline=True, cache=True)
def clear_path(w, me, site):
    """Make the robot's current entry for ``site`` one straight vector again (its waypoints dropped)."""
    w.new_path_count[me, site] = 0
