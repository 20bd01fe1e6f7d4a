"""Shared fixtures: small hand-built worlds whose arrays tests set directly."""
from __future__ import annotations

import numpy as np
import pytest

from infomarket.config import validate
from infomarket.engine import specialise
from infomarket.engine.build import behaviour_kinds, build_world
from infomarket.engine.world import kernel_view

from . import shared_kernel  # noqa: F401  (imported first, so its list of built-in behaviours is only those)


def make_config(robots: int = 2, behaviour: str = "naive", scheme: str = "delayed", **top):
    data = {"swarm": {"robots": robots, "groups": [{"behaviour": behaviour, "count": robots}]},
            "payment": {"scheme": scheme}}
    for k, v in top.items():
        if isinstance(v, dict) and isinstance(data.get(k), dict):
            data[k] = {**data[k], **v}
        else:
            data[k] = v
    return validate(data)


class Handle:
    """A world (host arrays) with its kernel view; tests poke arrays and call compiled helpers."""

    def __init__(self, cfg, seed: int = 0, record_events: bool = True):
        self.cfg = cfg
        self.rng = np.random.default_rng(seed)
        self.world, self.names = build_world(cfg, self.rng, record_events=record_events)
        self.kernel = specialise.kernel_module(behaviour_kinds(cfg), cfg.payment.scheme)
        self.view = kernel_view(self.world)

    def place(self, i: int, x: float, y: float, heading: float) -> None:
        w = self.world
        w.pos[i] = (x, y)
        a = np.radians(heading)
        w.hdir[i] = (np.cos(a), np.sin(a))

    def offer(self, i: int, site: int, x: float, y: float, age: int) -> None:
        w = self.world
        w.off_vec[i, site] = (x, y)
        w.off_age[i, site] = age
        w.off_valid[i, site] = True


@pytest.fixture
def world2():
    return Handle(make_config(2))


@pytest.fixture
def procs():
    """The one way a test starts a process (tests/procs.py): each in its own session, all killed at the end."""
    from .procs import Procs

    with Procs() as started:
        yield started
