"""The world as the compiled kernel sees it: a numba StructRef over the same arrays.

Passing a named tuple of ~70 arrays to a compiled function flattens it into hundreds of scalar
arguments per call; a StructRef is a single pointer, so rules and helpers cost a plain call.  The
host keeps the ``World`` named tuple (same arrays, shared memory) and hands the kernel this view.
With ``NUMBA_DISABLE_JIT=1`` the named tuple itself is passed: attribute access reads the same.
"""
from __future__ import annotations

from numba import config, types
from numba.experimental import structref

from .world import World


@structref.register
class WorldType(types.StructRef):
    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(t)) for name, t in fields)


class WorldRef(structref.StructRefProxy):
    """Proxy for :class:`WorldType`; constructed only through :func:`kernel_view`."""


structref.define_proxy(WorldRef, WorldType, list(World._fields))


def kernel_view(world: World):
    """What to pass to compiled code for this world."""
    if config.DISABLE_JIT:
        return world
    return WorldRef(*world)
