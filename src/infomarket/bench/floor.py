"""This machine's floor: the least work per step that any faithful implementation of the model must do.

Per step: the neighbour search (all pairs for a small swarm, the grid beyond, as the engine does), and
per robot one Gaussian draw for the odometry noise, the rotation it causes, the move, and dead
reckoning of its two table entries.  No market, no foraging, no state machine.  ``infomarket bench``
runs it in the same process as the setups and prints how far each setup is above it.
"""
from __future__ import annotations

import math
import statistics
import time

import numpy as np
from ..jit import njit

from ..engine.neighbours import ALL_PAIRS_UP_TO, grid_shape, neighbours_by_all_pairs, neighbours_by_grid

DEG = math.pi / 180.0


@njit(cache=True)
def floor_kernel(pos, hdir, tab, bias, nbr, nbr_count, cell_start, cell_items, rc, cell, nx, ny,
                 speed, noise_sd, radius, width, height, rng, steps):
    """Advance ``steps`` steps; returns a checksum so the compiler cannot drop the work."""
    n = pos.shape[0]
    cap = nbr.shape[1]
    links = 0
    for _ in range(steps):
        for i in range(n):
            nbr_count[i] = 0
        if n <= ALL_PAIRS_UP_TO:
            neighbours_by_all_pairs(pos, rc * rc, nbr, nbr_count, cap)
        else:
            neighbours_by_grid(pos, rc * rc, nbr, nbr_count, cap, cell, nx, ny, cell_start, cell_items)
        for i in range(n):
            links += nbr_count[i]
            a = rng.normal(bias[i], noise_sd) * DEG
            c = math.cos(a)
            s = math.sin(a)
            hx = c * hdir[i, 0] - s * hdir[i, 1]
            hy = s * hdir[i, 0] + c * hdir[i, 1]
            hdir[i, 0] = hx
            hdir[i, 1] = hy
            x = pos[i, 0] + speed * hx
            y = pos[i, 1] + speed * hy
            if x < radius or x > width - radius:
                hdir[i, 0] = -hx
            if y < radius or y > height - radius:
                hdir[i, 1] = -hy
            pos[i, 0] = min(max(x, radius), width - radius)
            pos[i, 1] = min(max(y, radius), height - radius)
            for k in range(2):
                tx = tab[i, k, 0] - speed
                ty = tab[i, k, 1]
                tab[i, k, 0] = c * tx + s * ty
                tab[i, k, 1] = c * ty - s * tx
    return links


def floor_arguments(seed: int, robots: int = 25, width: float = 1200.0, height: float = 600.0,
                    comm_range: float = 50.0) -> tuple:
    """``floor_kernel``'s arguments but ``steps``: a swarm of ``robots`` scattered over a ``width`` x
    ``height`` arena from ``seed``, at the paper's speed, noise and radius."""
    rng = np.random.default_rng(seed)
    pos = np.column_stack([rng.uniform(8, width - 8, robots), rng.uniform(8, height - 8, robots)])
    ang = rng.uniform(0, 2 * math.pi, robots)
    hdir = np.column_stack([np.cos(ang), np.sin(ang)])
    tab = rng.normal(0, 100, (robots, 2, 2))
    bias = rng.normal(0.05, 0.05, robots)
    cell, nx, ny = grid_shape(width, height, comm_range, robots)
    nbr = np.zeros((robots, 64), np.int64)
    return (pos, hdir, tab, bias, nbr, np.zeros(robots, np.int64), np.zeros(nx * ny + 1, np.int64),
            np.zeros(robots, np.int64), comm_range, cell, nx, ny, 2.5, 0.05, 8.0, width, height, rng)


def floor_seconds(seed: int, steps: int, robots: int = 25, width: float = 1200.0, height: float = 600.0,
                  comm_range: float = 50.0, clock=time.perf_counter) -> float:
    """Seconds of one floor run of ``steps`` steps on ``floor_arguments(seed, ...)``: wall clock by
    default, as the setups' ``run_seconds``; ``clock=time.process_time`` for CPU time."""
    args = floor_arguments(seed, robots, width, height, comm_range)
    t0 = clock()
    floor_kernel(*args, steps)
    return clock() - t0


def floor_summary(times: list[float], robots: int, steps: int) -> dict:
    """The floor's rates from its runs' seconds (the median run)."""
    med = statistics.median(times)
    return {"steps_per_second": steps / med, "robot_steps_per_second": robots * steps / med,
            "seconds_per_run": med, "robots": robots, "steps": steps, "repeats": len(times)}


def floor_steps_per_second(robots: int = 25, steps: int = 15000, repeats: int = 7, width: float = 1200.0,
                           height: float = 600.0, comm_range: float = 50.0, seed: int = 0) -> dict:
    """Median env-steps/s of the floor kernel for ``robots`` robots in a ``width`` x ``height`` arena."""
    floor_seconds(seed, 1, robots, width, height, comm_range)  # compiles or loads the kernel; not timed
    times = [floor_seconds(seed + rep, steps, robots, width, height, comm_range) for rep in range(1, repeats + 1)]
    return floor_summary(times, robots, steps)
