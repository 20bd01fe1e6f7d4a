"""The neighbour grid's geometry: how the engine bins robots (``engine.neighbours``) and what
``config.sizes`` counts when it estimates a run's memory."""
from __future__ import annotations

import math


def grid_shape(width: float, height: float, comm_range: float, robots: int) -> tuple[float, int, int]:
    """Cell side and counts: at least one communication range wide (so neighbours are in adjacent
    cells), and no more than about 4 cells per robot (so memory stays O(n) in a sparse arena)."""
    side = max(comm_range, math.sqrt(width * height / max(4 * robots, 64)), 1e-9)
    return side, max(1, math.ceil(width / side)), max(1, math.ceil(height / side))
