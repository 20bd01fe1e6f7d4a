"""The world as the compiled kernel sees it: a numba StructRef of *borrowed* views of the host's arrays.

Passing a named tuple of ~75 arrays to a compiled function flattens it into hundreds of scalar
arguments per call; a StructRef is a single pointer, so rules and helpers cost a plain call.  But every
read of an array field of a StructRef hands out a new reference, and numba counts references with
atomic instructions: that counting was the largest single cost of the step.  So the struct holds
views *without* a reference count (``borrow``: same data, shape and strides, no meminfo), for which
numba's incref/decref are a null test.  They are safe because the host keeps the ``World`` named tuple,
which owns the arrays, alive for as long as the view is used, and builds a new view whenever it
replaces an array (``Simulation`` after ``build.make_room``).

Parameter arrays (``world.PARAMS``) are typed read-only: a rule that writes one fails to compile.
With ``NUMBA_DISABLE_JIT=1`` the named tuple itself is passed: attribute access reads the same.
"""
from __future__ import annotations

import functools

import numba
import numpy as np
from numba import config, types
from numba.experimental import structref
from numba.extending import intrinsic

from .world import PARAMS, World


@structref.register
class WorldType(types.StructRef):
    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(t)) for name, t in fields)


class WorldRef(structref.StructRefProxy):
    """Python handle on a kernel view (boxing only; the host reads the World tuple instead)."""


structref.define_boxing(WorldType, WorldRef)


def _borrowed(arr_type, readonly: bool):
    def codegen(context, builder, sig, args):
        src = context.make_array(arr_type)(context, builder, value=args[0])
        dst = context.make_array(sig.return_type)(context, builder)
        context.populate_array(dst, data=src.data, shape=src.shape, strides=src.strides,
                               itemsize=src.itemsize, meminfo=None, parent=None)
        return dst._getvalue()

    out = arr_type.copy(readonly=True) if readonly else arr_type
    return out(arr_type), codegen


@intrinsic
def borrow(typingctx, value):
    """A view of an array that numba does not reference-count (other values pass through)."""
    if not isinstance(value, types.Array):
        return value(value), lambda context, builder, sig, args: args[0]
    return _borrowed(value, False)


@intrinsic
def borrow_readonly(typingctx, value):
    """Like ``borrow``, typed read-only: writes through it do not compile."""
    if not isinstance(value, types.Array):
        return value(value), lambda context, builder, sig, args: args[0]
    return _borrowed(value, True)


def _field_type(name: str, value):
    t = numba.typeof(value)
    if name in PARAMS and isinstance(t, types.Array):
        return t.copy(readonly=True)
    return t


@functools.cache
def world_type() -> WorldType:
    """The concrete struct type: every World has the same field types (dtypes and dimensions)."""
    from ..config.schema import Experiment
    from .build import build_world

    cfg = Experiment.model_validate({"swarm": {"robots": 2, "groups": [{"behaviour": "naive", "count": 2}]}})
    proto, _ = build_world(cfg, np.random.default_rng(0), record_events=True, history_every=1)
    return WorldType([(name, _field_type(name, value)) for name, value in zip(World._fields, proto)])


def constructor_source() -> str:
    """Source of ``make_view(world_tuple) -> struct``, for the generated kernel module."""
    lines = ["@njit(cache=True)", "def make_view(t):", "    st = _structref_new(_WORLD_TYPE)"]
    lines += [f"    st.{f} = {'_borrow_readonly' if f in PARAMS else '_borrow'}(t.{f})" for f in World._fields]
    lines += ["    return st", ""]
    return "\n".join(lines)


def kernel_view(world: World, kernel):
    """What to pass to ``kernel``'s compiled functions for this world (valid while ``world`` lives)."""
    if config.DISABLE_JIT:
        return world
    return kernel.make_view(world)
