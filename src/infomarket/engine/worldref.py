"""The world as the compiled kernel sees it: a numba StructRef of *borrowed* views of the host's arrays.

Passing a named tuple of ~75 arrays to a compiled function flattens it into hundreds of scalar
arguments per call; a StructRef is a single pointer, so rules and helpers cost a plain call.  But numba
counts references to the handle and to every array read from it, with calls it keeps out of line and
atomic instructions: that counting was the largest single cost of the step.  So nothing here is
counted.  The arrays are ``BorrowedArray`` views (same data, shape and strides, a meminfo slot typed as
a plain pointer, so numba emits no incref or decref for them), and the handle's model types its own
meminfo as a plain pointer too (``WorldModel``): the only reference is the one the Python ``WorldRef``
holds, taken and given back once per call from Python (``_unbox_world``).  Both are safe because the
host keeps the ``World`` named tuple, which owns the arrays, and the ``WorldRef`` alive for as long as
the view is used, and builds a new view whenever it replaces an array (``Simulation`` after
``build.make_room``).  A slice of a borrowed array is an ordinary numba view (with a null meminfo).

Parameter arrays (``world.PARAMS``) are typed read-only: a rule that writes one fails to compile.
With ``NUMBA_DISABLE_JIT=1`` the named tuple itself is passed: attribute access reads the same.
"""
from __future__ import annotations

import functools

import numba
import numpy as np
from numba import config, types
from numba.core.datamodel.models import StructModel
from numba.experimental import structref
from numba.core import cgutils
from numba.extending import NativeValue, box, intrinsic, register_model, unbox

from .world import PARAMS, World


class BorrowedArray(types.Array):
    """An array type numba never reference-counts: its meminfo slot is typed as a raw pointer, so
    reading it from the struct, passing it to a rule or letting it go emits no ``NRT_incref`` /
    ``NRT_decref`` call (numba keeps those calls out of line, so even on a null meminfo each costs a
    call: a sixth of a 25-robot step before).  Everything else (indexing, shape, slicing, which gives
    an ordinary view) is numba's array code: the memory layout is the same."""

    def __init__(self, dtype, ndim, layout, readonly=False, aligned=True):
        kind = "readonly borrowed array" if readonly else "borrowed array"
        super().__init__(dtype, ndim, layout, readonly=readonly, aligned=aligned,
                         name=f"{kind}({dtype}, {ndim}d, {layout})")

    @classmethod
    def of(cls, t: types.Array, readonly: bool) -> "BorrowedArray":
        return cls(t.dtype, t.ndim, t.layout, readonly=readonly or not t.mutable, aligned=t.aligned)


@register_model(BorrowedArray)
class BorrowedArrayModel(StructModel):
    """numba's array model with the meminfo member as a plain pointer (always null here)."""

    def __init__(self, dmm, fe_type):
        members = [("meminfo", types.voidptr), ("parent", types.pyobject), ("nitems", types.intp),
                   ("itemsize", types.intp), ("data", types.CPointer(fe_type.dtype)),
                   ("shape", types.UniTuple(types.intp, fe_type.ndim)),
                   ("strides", types.UniTuple(types.intp, fe_type.ndim))]
        super().__init__(dmm, fe_type, members)


class WorldType(types.StructRef):
    def preprocess_fields(self, fields):
        return tuple((name, types.unliteral(t)) for name, t in fields)


@register_model(WorldType)
class WorldModel(StructModel):
    """numba's StructRef model with the meminfo as a plain pointer: the handle itself is not
    reference-counted in compiled code either (each rule call and helper counted it up and down with
    an atomic instruction).  Its one reference belongs to the Python ``WorldRef`` that ``make_view``
    returns, which the host keeps for as long as it runs the kernel with it."""

    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, [("meminfo", types.voidptr)])


structref.define_attributes(WorldType)


class WorldRef(structref.StructRefProxy):
    """Python handle on a kernel view (boxing only; the host reads the World tuple instead)."""


@box(WorldType)
def _box_world(typ, val, c):
    """The new struct's one reference goes to the MemInfo object (which steals it), as numba's boxing."""
    meminfo = cgutils.create_struct_proxy(typ)(c.context, c.builder, value=val).meminfo
    boxed = c.box(types.MemInfoPointer(types.voidptr), meminfo)
    ctor = c.pyapi.unserialize(c.pyapi.serialize_object(WorldRef._numba_box_))
    ty = c.pyapi.unserialize(c.pyapi.serialize_object(typ))
    out = c.pyapi.call_function_objargs(ctor, [ty, boxed])
    for obj in (ctor, ty, boxed):
        c.pyapi.decref(obj)
    return out


@unbox(WorldType)
def _unbox_world(typ, obj, c):
    """Borrow the handle for the call: the reference unboxing takes is given back when the call ends
    (the ``cleanup``), since compiled code never counts it."""
    mip = types.MemInfoPointer(types.voidptr)
    mi_obj = c.pyapi.object_getattr_string(obj, "_meminfo")
    mi = c.unbox(mip, mi_obj).value
    c.pyapi.decref(mi_obj)
    st = cgutils.create_struct_proxy(typ)(c.context, c.builder)
    st.meminfo = mi
    return NativeValue(st._getvalue(), cleanup=lambda: c.context.nrt.decref(c.builder, mip, mi))


def _borrowed(arr_type, readonly: bool):
    def codegen(context, builder, sig, args):
        src = context.make_array(arr_type)(context, builder, value=args[0])
        dst = context.make_array(sig.return_type)(context, builder)
        context.populate_array(dst, data=src.data, shape=src.shape, strides=src.strides,
                               itemsize=src.itemsize, meminfo=None, parent=None)
        return dst._getvalue()

    return BorrowedArray.of(arr_type, readonly)(arr_type), codegen


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
    if isinstance(t, types.Array):
        return BorrowedArray.of(t, name in PARAMS)
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
    """Source of the module that builds views: ``make_view(world_tuple) -> struct``."""
    lines = ["# Generated by infomarket.engine.worldref: builds the kernel's view of a World (do not edit).",
             "from numba import njit",
             "from numba.experimental.structref import new as _structref_new",
             "from infomarket.engine.worldref import world_type as _world_type, borrow as _borrow, "
             "borrow_readonly as _borrow_readonly",
             "_WORLD_TYPE = _world_type()", "", "",
             "@njit(cache=True)", "def make_view(t):", "    st = _structref_new(_WORLD_TYPE)"]
    lines += [f"    st.{f} = {'_borrow_readonly' if f in PARAMS else '_borrow'}(t.{f})" for f in World._fields]
    lines += ["    return st", ""]
    return "\n".join(lines)


@functools.cache
def view_module():
    """The module with ``make_view``, generated once per world layout and cached on disk like the kernels
    (every kernel module used to compile its own copy: about 4 s for each new set of rules)."""
    from .specialise import generated_digest, load_generated

    source = constructor_source()
    return load_generated("worldview", generated_digest(source).hexdigest()[:20], source)


def kernel_view(world: World):
    """What to pass to the compiled kernels' functions for this world (valid while ``world`` lives)."""
    if config.DISABLE_JIT:
        return world
    return view_module().make_view(world)
