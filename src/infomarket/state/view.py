"""The state as compiled code sees it: a numba StructRef of *borrowed* views of the host's arrays.

Passing a named tuple of ~115 arrays to a compiled function flattens it into hundreds of scalar
arguments per call; a StructRef is a single pointer, so rules and helpers cost a plain call.  But numba
counts references to the handle and to every array read from it, with calls it keeps out of line and
atomic instructions: that counting was the largest single cost of the step.  So nothing here is
counted.  The arrays are ``BorrowedArray`` views (same data, shape and strides, a meminfo slot typed as
a plain pointer, so numba emits no incref or decref for them), and the handle's model types its own
meminfo as a plain pointer too (``WorldModel``): the only reference is the one the Python ``WorldRef``
holds, taken and given back once per call from Python (``_unbox_world``).  Both are safe because the
host keeps the named tuple, which owns the arrays, and the ``WorldRef`` alive for as long as the view
is used, and builds a new view whenever it replaces an array (``Simulation`` after growing).  A slice
of a borrowed array is an ordinary numba view (with a null meminfo).

A view is made for any layout: an ordered list of domain specs (``state.spec``).  Each field's writer
decides its type, and so who can write it:

* ``host`` (parameters): read-only ``BorrowedArray``; writing one does not compile, anywhere.
* ``ledger`` and ``log``: ``GuardedArray``, read-only too, except through ``unlock``, which only the
  ledger's operations (``ledger.kernels``) and the engine's loop and log writes call.  A buy, sell or
  payment rule that writes ``balance`` does not compile.
* ``engine`` (the swarm): writable.

With ``NUMBA_DISABLE_JIT=1`` the named tuple itself is passed: attribute access reads the same, and
``unlock`` returns its argument.
"""
from __future__ import annotations

import functools
import hashlib

import numba
import numpy as np
from numba import config, types
from numba.core.datamodel.models import StructModel
from numba.experimental import structref
from numba.core import cgutils
from numba.extending import NativeValue, box, intrinsic, register_model, unbox

from .._numba_internals import BOX, MEMINFO, add_alias, alias_func_extensions
from ..errors import InternalError
from .spec import Spec


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
    def of(cls, t: types.Array, readonly: bool) -> BorrowedArray:
        """The borrowed twin of the array type ``t`` (read-only if asked, or if ``t`` is)."""
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


class GuardedArray(BorrowedArray):
    """A read-only borrowed array that its owner can ``unlock``: the ledger's and the log's arrays.
    Parameters are plain read-only ``BorrowedArray``s, which ``unlock`` refuses."""

    def __init__(self, dtype, ndim, layout, readonly=True, aligned=True):
        types.Array.__init__(self, dtype, ndim, layout, readonly=True, aligned=aligned,
                             name=f"guarded array({dtype}, {ndim}d, {layout})")

    @classmethod
    def of(cls, t: types.Array, readonly: bool = True) -> GuardedArray:
        """The guarded twin of the array type ``t`` (same dtype, dimensions and layout)."""
        return cls(t.dtype, t.ndim, t.layout, aligned=t.aligned)


register_model(GuardedArray)(BorrowedArrayModel)


@intrinsic
def _unlock(typingctx, array):
    """A writable alias of a ledger or log array (same data), for the operations that own it
    (``ledger.kernels``, the engine's loop and log writes).  Rules never call it: that is what keeps the
    books theirs.  A parameter (read-only for everyone) has no such operation: it does not compile."""
    if isinstance(array, GuardedArray):
        out = BorrowedArray(array.dtype, array.ndim, array.layout, readonly=False, aligned=array.aligned)
    elif isinstance(array, types.Array) and array.mutable:  # a plain tuple's array (no view): as is
        out = array
    else:
        return None
    return out(array), lambda context, builder, sig, args: args[0]


def _unlock_aliases(lhs, args, alias_map, arg_aliases):
    """Tell numba's alias analysis that ``unlock(a)`` *is* ``a``.  Without it, a function that inlines an
    ``@overload(inline="always")`` (the engine's draws) runs numba's dead-code elimination, which sees a
    write into a fresh, unused call result and deletes it: ``unlock(w.site_items)[k] += 1`` next to a
    draw was silently lost (tests/terrain/test_sites_and_collisions.py keeps that case)."""
    add_alias(lhs, args[0].name, alias_map, arg_aliases)


alias_func_extensions[("_unlock", __name__)] = _unlock_aliases


def _identity(array):
    return array


#: ``unlock(array)``: an intrinsic, which numba inlines as the same array typed writable (with
#: ``NUMBA_DISABLE_JIT=1``, the array itself).
unlock = _identity if config.DISABLE_JIT else _unlock


class WorldType(types.StructRef):
    """numba names a StructRef type by every field it holds, and writes that name into the symbol of
    each function that takes one and into its payload type, which it builds again at every field access:
    for a layout of hundreds of fields, string work that took a large share of a chain kernel's compile.
    So the symbol carries a digest of the name (``mangling_args``, which numba leaves to subclasses), and
    the payload type is made once per view type."""

    def preprocess_fields(self, fields):
        """Drop literal types from the fields, so that views built from different values share one type."""
        return tuple((name, types.unliteral(t)) for name, t in fields)

    @property
    def mangling_args(self):
        """A short, stable symbol name (a hash of the type's name): the full one lists every field and is too long
        for a linker symbol."""
        short = self.__dict__.get("_short_name")
        if short is None:
            short = self.__dict__["_short_name"] = f"WorldType_{hashlib.sha256(self.name.encode()).hexdigest()[:24]}"
        return short, ()

    def get_data_type(self):
        """The payload type, made once per view type and remembered (numba would rebuild it at each call)."""
        payload = self.__dict__.get("_payload")
        if payload is None:
            payload = self.__dict__["_payload"] = super().get_data_type()
        return payload


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
    ctor = c.pyapi.unserialize(c.pyapi.serialize_object(getattr(WorldRef, BOX)))
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
    mi_obj = c.pyapi.object_getattr_string(obj, MEMINFO)
    mi = c.unbox(mip, mi_obj).value
    c.pyapi.decref(mi_obj)
    st = cgutils.create_struct_proxy(typ)(c.context, c.builder)
    st.meminfo = mi
    return NativeValue(st._getvalue(), cleanup=lambda: c.context.nrt.decref(c.builder, mip, mi))


#: How each writer's arrays are typed in a view.
_ARRAY_TYPE = {"host": lambda t: BorrowedArray.of(t, True), "engine": lambda t: BorrowedArray.of(t, False),
               "ledger": GuardedArray.of, "log": GuardedArray.of}
_SCALARS = {"float": types.float64, "int": types.int64, "bool": types.boolean}


def field_type(spec_field):
    """The numba type of one field in a view, from its spec: dtype, dimensions and writer."""
    if spec_field.ndim == 0:
        return _SCALARS[spec_field.dtype]
    t = types.Array(numba.from_dtype(np.dtype(spec_field.dtype)), spec_field.ndim, "C")
    return _ARRAY_TYPE[spec_field.writer](t)


@functools.cache
def view_type(specs: tuple[Spec, ...]) -> WorldType:
    """The struct type of a view of these domains (in order): the same for every run of the layout."""
    return WorldType([(f.name, field_type(f)) for spec in specs for f in spec.fields])


#: Fields a view is filled with per compiled call: the wrapper numba compiles to unbox a tuple argument,
#: and LLVM's work on it, grow faster than the tuple's length, so a layout of hundreds of fields is
#: passed in parts.
PART = 32


@intrinsic(prefer_literal=True)
def fill_view(typingctx, view, part, start):
    """Fields ``start, start + 1, ...`` of ``view`` (a fresh struct) set from ``part``, a tuple of the
    state's values in the layout's order: an array as a borrowed view of the same data (read-only,
    guarded or writable, as its type in the view says), a scalar cast to the view's type.  One intrinsic
    rather than a ``setattr`` and a borrowing call per field, which numba typed and lowered one by one."""
    if not (isinstance(view, WorldType) and isinstance(part, types.BaseTuple)
            and isinstance(start, types.IntegerLiteral)):
        return None
    fields = list(view.field_dict.items())[start.literal_value:start.literal_value + len(part)]
    if len(fields) != len(part):
        raise InternalError(f"fill_view: {len(part)} values from field {start.literal_value} of a view of "
                            f"{len(view.field_dict)}")
    for (name, field_type), given in zip(fields, part.types):
        if isinstance(field_type, BorrowedArray) != isinstance(given, types.Array) or (
                isinstance(given, types.Array) and (given.dtype, given.ndim) != (field_type.dtype, field_type.ndim)):
            raise InternalError(f"fill_view: the state's {name!r} is {given}, the view's is {field_type}")

    def codegen(context, builder, sig, args):
        st, tup, _ = args
        meminfo = cgutils.create_struct_proxy(view)(context, builder, value=st).meminfo
        data_type = view.get_data_type()
        payload_ptr = builder.bitcast(context.nrt.meminfo_data(builder, meminfo),
                                      context.get_value_type(data_type).as_pointer())
        payload = cgutils.create_struct_proxy(data_type)(context, builder, ref=payload_ptr)
        for k, ((name, field_type), value_type) in enumerate(zip(fields, part.types)):
            value = builder.extract_value(tup, k)
            if isinstance(field_type, BorrowedArray):
                src = context.make_array(value_type)(context, builder, value=value)
                dst = context.make_array(field_type)(context, builder)
                context.populate_array(dst, data=src.data, shape=src.shape, strides=src.strides,
                                       itemsize=src.itemsize, meminfo=None, parent=None)
                value = dst._getvalue()
            else:
                value = context.cast(builder, value, value_type, field_type)
            setattr(payload, name, value)
        return context.get_dummy_value()

    return types.none(view, part, start), codegen


def constructor_source(specs: tuple[Spec, ...], layout: str) -> str:
    """Source of the module that builds views of a layout: ``new_view`` makes one from the state's first
    ``PART`` values, and ``FILLS`` (first field, function) fill it with the rest, a part each."""
    count = sum(len(spec.fields) for spec in specs)
    lines = [f"# Generated by infomarket.state.view: builds the compiled view of the {layout!r} layout (do not edit).",
             "from infomarket.jit import njit",
             "from numba.experimental.structref import new as _structref_new",
             "from infomarket.state.view import layout_type as _layout_type, fill_view as _fill_view",
             f"_TYPE = _layout_type({layout!r})", "", "",
             "@njit(cache=True)", "def new_view(part):", "    st = _structref_new(_TYPE)",
             "    _fill_view(st, part, 0)", "    return st"]
    for start in range(PART, count, PART):
        lines += ["", "", "@njit(cache=True)", f"def fill_{start}(st, part):", f"    _fill_view(st, part, {start})"]
    lines += ["", "", f"FILLS = ({''.join(f'({start}, fill_{start}), ' for start in range(PART, count, PART))})", ""]
    return "\n".join(lines)


#: Layouts by name: the domains a view of that name holds (registered by their owners).
_LAYOUTS: dict[str, tuple[Spec, ...]] = {}


def register_layout(name: str, specs: tuple[Spec, ...]) -> None:
    """Declare a layout (``"world"``: parameters, swarm, ledger, log; ``"book"``: ledger, log)."""
    _LAYOUTS[name] = tuple(specs)


def layout_type(name: str) -> WorldType:
    """The numba type of the world view for the layout called ``name``."""
    return view_type(_LAYOUTS[name])


@functools.cache
def view_module(name: str):
    """The module with ``make_view`` for a layout, generated once per layout and cached on disk like the
    kernels (compiling it costs a few seconds, so every kernel shares it)."""
    from ..generated import generated_digest, load_generated  # generated imports the engine, which imports this

    source = constructor_source(_LAYOUTS[name], name)
    return load_generated(f"view{name}", generated_digest(source).hexdigest()[:20], source)


@functools.cache
def _in_layout_order(name: str, state_type: type) -> bool:
    names = [f.name for spec in _LAYOUTS[name] for f in spec.fields]
    if list(state_type._fields) != names:
        raise InternalError(f"a {state_type.__name__} does not hold the fields of layout {name!r} in its order")
    return True


def make_view(name: str, state):
    """What to pass to compiled code for ``state`` (a named tuple of layout ``name``), valid while it lives."""
    if config.DISABLE_JIT:
        return state
    module = view_module(name)
    _in_layout_order(name, type(state))
    values = tuple(state)
    view = module.new_view(values[:PART])
    for start, fill in module.FILLS:
        fill(view, values[start:start + PART])
    return view
