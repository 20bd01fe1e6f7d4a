"""Tiny terrain worlds with hand-placed robots and no odometry noise, so every expected position is a
hand calculation."""
from __future__ import annotations

import numpy as np

from infomarket.config import validate
from infomarket.engine import Simulation
from infomarket.engine.world import FOOD, SEEKING_FOOD

#: Sites far from every hand-placed robot and obstacle below.
FAR_SITES = {"food": {"x": 600.0, "y": 60.0}, "nest": {"x": 1000.0, "y": 540.0}}


def terrain_config(robots: int = 1, obstacles=(), steps: int = 100, **robot):
    data = {"steps": steps, "swarm": {"robots": robots, "groups": [{"behaviour": "naive", "count": robots}]},
            "robot": {"noise_sd": 0.0, "bias_mean": 0.0, "bias_sd": 0.0, **robot},
            "obstacles": list(obstacles), **FAR_SITES}
    return validate(data)


def place(sim, i, x, y, heading):
    w = sim.world
    w.pos[i] = (x, y)
    a = np.radians(heading)
    w.hdir[i] = (np.cos(a), np.sin(a))
    w.bias[i] = 0.0


def seek_food(sim, i, vx, vy):
    """Robot i seeks food believing it at (vx, vy) in its own frame, age 0."""
    w = sim.world
    w.state[i] = SEEKING_FOOD
    w.tab_vec[i, FOOD] = (vx, vy)
    w.tab_valid[i, FOOD] = True
    w.tab_age[i, FOOD] = 0


def simulation(cfg) -> Simulation:
    return Simulation(cfg, seed=3)
