"""The world as the compiled kernel sees it: a numba StructRef over the same arrays.

Passing a named tuple of ~70 arrays to a compiled function flattens it into hundreds of scalar
arguments per call; a StructRef is a single pointer, so rules and helpers cost a plain call.  The
host keeps the ``World`` named tuple (same arrays, shared memory) and hands the kernel this view,
built by a cached constructor that ``engine.specialise`` writes into every generated kernel module.
With ``NUMBA_DISABLE_JIT=1`` the named tuple itself is passed: attribute access reads the same.
"""
from __future__ import annotations

import functools

import numba
import numpy as np
from numba import config, types
from numba.experimental import structref

from .world import World


@structref.register
class WorldType(types.StructRef):
    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(t)) for name, t in fields)


class WorldRef(structref.StructRefProxy):
    """Python handle on a kernel view (boxing only; the host reads the World tuple instead)."""


structref.define_boxing(WorldType, WorldRef)


@functools.cache
def world_type() -> WorldType:
    """The concrete struct type: every World has the same field types (dtypes and dimensions)."""
    from ..config.schema import Experiment
    from .build import build_world

    cfg = Experiment.model_validate({"swarm": {"robots": 2, "groups": [{"behaviour": "naive", "count": 2}]}})
    proto, _ = build_world(cfg, np.random.default_rng(0), record_events=True, history_every=1)
    return WorldType([(name, numba.typeof(value)) for name, value in zip(World._fields, proto)])


def constructor_source() -> str:
    """Source of ``make_view(world_tuple) -> struct``, for the generated kernel module."""
    lines = ["@njit(cache=True)", "def make_view(t):", "    st = _structref_new(_WORLD_TYPE)"]
    lines += [f"    st.{f} = t.{f}" for f in World._fields]
    lines += ["    return st", ""]
    return "\n".join(lines)


def kernel_view(world: World, kernel):
    """What to pass to ``kernel``'s compiled functions for this world."""
    if config.DISABLE_JIT:
        return world
    return kernel.make_view(world)
