"""Neighbour search: pairs strictly closer than the communication range, lists in increasing id order.

Small swarms (the paper's 25) test all pairs: a grid costs more than it saves below a few dozen robots.
Larger swarms bin robots into a uniform grid of cells at least one communication range wide, rebuilt
every step (a counting sort, O(n)), and test only the pairs in adjacent cells, so a step costs O(n) at a
fixed density instead of O(n²).  Both paths test a pair (i, j), i < j, with the same arithmetic, so
they find exactly the same neighbours.

A robot may have more neighbours than ``nbr`` has columns: the count is still exact, nothing beyond
the capacity is written, and ``has_room`` sends the host to grow the table before the step goes on.
"""
from ..jit import njit

from ..space.grid import grid_shape  # noqa: F401  (the grid's geometry; re-exported for the engine)

#: Up to this many robots, all pairs are tested.
ALL_PAIRS_UP_TO = 48


@njit(forceinline=True, cache=True)
def _link(nbr, nbr_count, cap, i, j):
    """Record that i and j are neighbours (each at the end of the other's list)."""
    c = nbr_count[i]
    if c < cap:
        nbr[i, c] = j
    nbr_count[i] = c + 1
    c = nbr_count[j]
    if c < cap:
        nbr[j, c] = i
    nbr_count[j] = c + 1


@njit(cache=True)
def neighbours_by_all_pairs(pos, rc2, nbr, nbr_count, cap):
    """Fill the neighbour lists by testing every pair: O(n²), the fastest for small swarms.

    Args:
        pos (numpy.ndarray): robot positions, ``[n, 2] float64``.
        rc2 (float): the squared communication range; a pair strictly closer is linked.
        nbr (numpy.ndarray): ``[n, cap] int`` lists to append to; ids past ``cap`` are counted, not stored.
        nbr_count (numpy.ndarray): ``[n] int`` neighbours so far (the caller zeroes it), updated in place.
        cap (int): the lists' capacity.
    """
    n = pos.shape[0]
    for i in range(n):
        xi = pos[i, 0]
        yi = pos[i, 1]
        for j in range(i + 1, n):
            dx = pos[j, 0] - xi
            dy = pos[j, 1] - yi
            if dx * dx + dy * dy < rc2:
                _link(nbr, nbr_count, cap, i, j)


@njit(forceinline=True, cache=True)
def _cell(x, size, cells):
    c = int(x / size)
    return min(max(c, 0), cells - 1)


@njit(cache=True)
def neighbours_by_grid(pos, rc2, nbr, nbr_count, cap, size, nx, ny, start, items):
    """Fill the neighbour lists via a cell grid (cells at least the range wide): O(n) for large swarms.

    Lists the same neighbours in the same increasing order as ``neighbours_by_all_pairs``, so a run does not
    depend on which of the two the engine picks.

    Args:
        pos (numpy.ndarray): as ``neighbours_by_all_pairs``.
        rc2 (float): as ``neighbours_by_all_pairs``.
        nbr (numpy.ndarray): as ``neighbours_by_all_pairs``.
        nbr_count (numpy.ndarray): as ``neighbours_by_all_pairs``.
        cap (int): as ``neighbours_by_all_pairs``.
        size (float): a cell's side.
        nx (int): the number of cells along x.
        ny (int): the number of cells along y.
        start (numpy.ndarray): ``[nx * ny + 1] int`` scratch: where each cell's robots begin in ``items``.
        items (numpy.ndarray): ``[n] int`` scratch: robot ids sorted by cell.
    """
    n = pos.shape[0]
    ncell = nx * ny
    for c in range(ncell + 1):
        start[c] = 0
    for i in range(n):  # counting sort by cell; ids stay increasing inside a cell
        start[_cell(pos[i, 1], size, ny) * nx + _cell(pos[i, 0], size, nx) + 1] += 1
    for c in range(ncell):
        start[c + 1] += start[c]
    for i in range(n):
        c = _cell(pos[i, 1], size, ny) * nx + _cell(pos[i, 0], size, nx)
        items[start[c]] = i
        start[c] += 1
    for c in range(ncell - 1, 0, -1):  # the fill moved each start to the next cell's: shift back
        start[c] = start[c - 1]
    start[0] = 0
    for i in range(n):
        xi = pos[i, 0]
        yi = pos[i, 1]
        cx = _cell(xi, size, nx)
        cy = _cell(yi, size, ny)
        first = nbr_count[i]  # neighbours with lower ids are already listed, in increasing order
        for gy in range(max(cy - 1, 0), min(cy + 2, ny)):
            for gx in range(max(cx - 1, 0), min(cx + 2, nx)):
                c = gy * nx + gx
                for k in range(start[c], start[c + 1]):
                    j = items[k]
                    if j <= i:
                        continue
                    dx = pos[j, 0] - xi
                    dy = pos[j, 1] - yi
                    if dx * dx + dy * dy < rc2:
                        _link(nbr, nbr_count, cap, i, j)
        # the higher ids came cell by cell: sort them (insertion sort, lists are short)
        last = min(nbr_count[i], cap)
        for a in range(first + 1, last):
            v = nbr[i, a]
            b = a - 1
            while b >= first and nbr[i, b] > v:
                nbr[i, b + 1] = nbr[i, b]
                b -= 1
            nbr[i, b + 1] = v


@njit(cache=True)
def find_all_neighbours(w):
    """Fill ``nbr`` / ``nbr_count`` for the current positions (idempotent: depends on positions only)."""
    nbr = w.nbr
    nbr_count = w.nbr_count
    n = nbr_count.shape[0]
    for i in range(n):
        nbr_count[i] = 0
    rc = w.comm_range
    if rc <= 0.0:
        return
    if n <= ALL_PAIRS_UP_TO:
        neighbours_by_all_pairs(w.pos, rc * rc, nbr, nbr_count, nbr.shape[1])
    else:
        neighbours_by_grid(w.pos, rc * rc, nbr, nbr_count, nbr.shape[1], w.grid_cell, w.grid_nx, w.grid_ny,
                           w.cell_start, w.cell_items)
