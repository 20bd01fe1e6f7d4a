"""Waypoint paths: a table entry of several legs, and the helpers of the step's ``paths`` variant.

A robot's entry for a site is normally one vector (``tab_vec``).  With a path (``path_count > 0``) the
entry is the *first waypoint* and ``path_vec[:path_count]`` holds the further ones, the last being the
site; every point is a position in the robot's own frame, kept by dead reckoning exactly as the entry
is.  The engine only keeps paths consistent; what is bought and sold is up to rules
(``behaviours.paths`` has the public helpers, ``behaviours.waypoint`` the built-in rule):

* **Dead reckoning.**  Each waypoint moves by ``-dr`` and turns by ``-heading(dr)`` like the entry
  (the same arithmetic as ``step.odometry_update``).
* **Following the legs.**  A seeking robot that reaches its first waypoint (closer than its radius:
  where the model would declare the entry wrong) takes the next waypoint as its entry and goes on;
  the entry's age does not change.
* **Bumps.**  When FRONT fires while seeking (the model then drops the entry and explores), the robot
  marks the site ``blocked`` and drops its path with the entry.  Being at a site of that kind clears
  both: the sensed vector is exact and straight.
* **Timing.**  As for the entry: sellers sell the start-of-step path, purchases go to ``new_path_*``
  and are installed when the robot moves.

``engine.step`` calls these helpers when its ``paths`` option is on, which ``engine.specialise`` sets only
when a configured behaviour was registered with ``paths=True`` (on the plane too, with the terrain
variant), so neither the paper's kernel nor a terrain run without path rules pays for paths.
"""
from ..jit import njit

from .geometry import norm
from .params import FOOD, NEST


@njit(forceinline=True, cache=True)
def path_odometry(w, i, dx, dy):
    """Move robot i's waypoints by its intended move (dx, dy) in its frame, as ``odometry_update``
    moves its table entries."""
    length = norm(dx, dy)
    c = dx / length
    s = -dy / length
    for k in range(2):
        for j in range(w.path_count[i, k]):
            x = w.path_vec[i, k, j, 0] - dx
            y = w.path_vec[i, k, j, 1] - dy
            w.path_vec[i, k, j, 0] = c * x - s * y
            w.path_vec[i, k, j, 1] = s * x + c * y


@njit(forceinline=True, cache=True)
def advance(w, i):
    """A robot at its first waypoint (closer than its radius) of a valid path takes the next one."""
    for k in range(2):
        m = w.path_count[i, k]
        if m > 0 and w.tab_valid[i, k] and norm(w.tab_vec[i, k, 0], w.tab_vec[i, k, 1]) < w.radius:
            w.tab_vec[i, k, 0] = w.path_vec[i, k, 0, 0]
            w.tab_vec[i, k, 1] = w.path_vec[i, k, 0, 1]
            for j in range(m - 1):
                w.path_vec[i, k, j, 0] = w.path_vec[i, k, j + 1, 0]
                w.path_vec[i, k, j, 1] = w.path_vec[i, k, j + 1, 1]
            w.path_count[i, k] = m - 1


@njit(forceinline=True, cache=True)
def at_site(w, i, k):
    """Robot i senses a site of kind k: its entry is now one exact vector."""
    w.path_count[i, k] = 0
    w.blocked[i, k] = False


@njit(forceinline=True, cache=True)
def bumped(w, i, front, was_food, was_nest):
    """After the state machine: an entry it dropped while FRONT fired (the model's "blocked while
    seeking") marks that site blocked.  ``was_*``: the entries' validity before the state machine."""
    if front:
        if was_food and not w.tab_valid[i, FOOD]:
            w.blocked[i, FOOD] = True
        if was_nest and not w.tab_valid[i, NEST]:
            w.blocked[i, NEST] = True


@njit(forceinline=True, cache=True)
def drop_invalid(w, i):
    """A path lives only as long as its entry is valid (arrival at a final point empties it too)."""
    for k in range(2):
        if not w.tab_valid[i, k]:
            w.path_count[i, k] = 0


@njit(forceinline=True, cache=True)
def begin_paths(w, i):
    """Robot i is about to buy: its purchases go to a new path, a copy of the one it sells."""
    for k in range(2):
        m = w.path_count[i, k]
        w.new_path_count[i, k] = m
        for j in range(m):
            w.new_path_vec[i, k, j, 0] = w.path_vec[i, k, j, 0]
            w.new_path_vec[i, k, j, 1] = w.path_vec[i, k, j, 1]


@njit(forceinline=True, cache=True)
def install_path(w, i):
    """The robot moves: what it bought becomes its path (with ``install_table`` for the entry)."""
    for k in range(2):
        m = w.new_path_count[i, k]
        w.path_count[i, k] = m
        for j in range(m):
            w.path_vec[i, k, j, 0] = w.new_path_vec[i, k, j, 0]
            w.path_vec[i, k, j, 1] = w.new_path_vec[i, k, j, 1]
