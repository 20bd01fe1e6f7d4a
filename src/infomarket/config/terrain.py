"""Validation and hashing helpers for the parts of an experiment that leave the paper's plane:
``[[obstacles]]``, several food / nest sites, ``robot.line_of_sight`` and ``robot.collisions``."""
from __future__ import annotations

from typing import Any


def _describe(o) -> str:
    if o.shape == "circle":
        return f"circle at ({o.x}, {o.y}) radius {o.radius}"
    return f"{o.shape} ({o.x0}, {o.y0}) - ({o.x1}, {o.y1})"


def site_overlap(cfg) -> str | None:
    """Why a site overlaps an obstacle (its disc comes closer to it than its radius), or None.
    A site must be reachable everywhere: a pick-up spot inside an obstacle could never be reached."""
    if not cfg.obstacles:
        return None
    from ..space.obstacles import encode, distance  # compiled geometry, only for configs with obstacles

    kinds, geom = encode(cfg.obstacles)
    for key in ("food", "nest"):
        for label, s in cfg._labelled_sites(key):
            for k, o in enumerate(cfg.obstacles):
                d = distance.py_func(kinds[k], *geom[k], s.x, s.y)
                if d < s.radius:
                    return (f"{label} site at ({s.x}, {s.y}) with radius {s.radius} overlaps obstacles[{k}] "
                            f"({_describe(o)}); sites may not overlap obstacles")
    return None


def drop_defaults(data: dict[str, Any]) -> None:
    """Remove the terrain keys that are at their defaults from a dumped experiment, so that a setup on
    the paper's plane hashes exactly as it did before these keys existed (stored results stay valid)."""
    if not data.get("obstacles"):
        data.pop("obstacles", None)
    robot = data.get("robot", {})
    for key in ("line_of_sight", "collisions", "sense_robots"):
        if robot.get(key) is False:
            robot.pop(key)
