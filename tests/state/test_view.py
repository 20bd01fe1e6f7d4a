"""The kernel's view of the world counts no references: numba keeps NRT_incref / NRT_decref out of
line (an atomic add behind a call), so reading a field or passing the handle to a rule must emit none;
and the one reference the host holds is not leaked by calls."""
import re
from collections import namedtuple

import numba
import numpy as np
import pytest
from numba import njit

from infomarket.engine.lists import typed_list
from infomarket.engine.step import variant
from infomarket.errors import InternalError
from infomarket.state.view import BorrowedArray, GuardedArray, WorldType, layout_type, make_view

from ..conftest import Handle, make_config

STEP = variant(terrain=False, paths=False)
find_neighbours, begin_communication, install_table, forage, behaviour_step, move = (
    STEP.find_neighbours, STEP.begin_communication, STEP.install_table, STEP.forage, STEP.behaviour_step, STEP.move)


@njit
def _steps(w, rng, k):
    """The engine's per-robot pieces, inlined as the step loop inlines them (with the bit generator)."""
    bits = rng.bit_generator
    for _ in range(k):
        find_neighbours(w)
        for i in range(w.pos.shape[0]):
            begin_communication(w, i)
        for i in range(w.pos.shape[0]):
            forage(w, i, bits)
            install_table(w, i)
            dx, dy = behaviour_step(w, i, bits)
            move(w, i, dx, dy, bits)
            w.items[i] += 1


def _nrt_calls(dispatcher) -> list[str]:
    """Operands of the reference-counting calls in the compiled function itself (not in the wrapper
    that unboxes the arguments from Python, which takes and gives back the host's reference once per
    call, nor in the definitions of the NRT functions)."""
    ir = "\n".join(dispatcher.inspect_llvm().values())
    native = [f for f in ir.split("\ndefine ")[1:]
              if "@_ZN7cpython" not in f.split("(")[0] and "@NRT_" not in f.split("(")[0]]
    return [c for f in native for c in re.findall(r"call void @NRT_(?:incref|decref)\(ptr ([^)]*)\)", f)]


def test_fields_and_the_handle_emit_no_reference_counting():
    h = Handle(make_config(3))
    assert isinstance(numba.typeof(h.view), WorldType)
    _steps(h.view, h.rng, 2)
    assert _nrt_calls(_steps) == []  # the engine draws from the bit generator (engine.draws)


def test_world_arrays_are_borrowed_params_read_only_and_books_guarded():
    fields = layout_type("world").field_dict
    assert isinstance(fields["pos"], BorrowedArray) and fields["pos"].mutable
    assert isinstance(fields["sites_xy"], BorrowedArray) and not fields["sites_xy"].mutable
    assert not isinstance(fields["sites_xy"], GuardedArray)  # a parameter can never be unlocked
    for name in ("balance", "pot", "money", "tx_seller", "rep_settled", "ev_step", "pay_amount", "hist", "clock"):
        assert isinstance(fields[name], GuardedArray) and not fields[name].mutable, name


def test_calls_leave_the_hosts_one_reference():
    h = Handle(make_config(3))
    assert h.view._meminfo.refcount == 1
    _steps(h.view, h.rng, 50)
    views = typed_list([h.view])  # the kernel steps a batch (of one here)
    h.kernel.step_all(views, typed_list([h.rng]), np.array([20]), np.zeros(1, np.int64), np.zeros(1, np.int64))
    assert h.view._meminfo.refcount == 1
    del views
    assert h.view._meminfo.refcount == 1
    assert h.world.items.sum() == 150  # the writes went to the host's arrays


def test_a_slice_of_a_borrowed_array_is_an_ordinary_view():
    @njit
    def neighbours_sum(w, i):
        return w.nbr[i, :w.nbr_count[i]].sum()

    h = Handle(make_config(3))
    h.world.nbr[0, :3] = (7, 1, 2)
    h.world.nbr_count[0] = 2
    assert neighbours_sum(h.view, 0) == 8
    assert h.view._meminfo.refcount == 1


def _compiles(fn, *args) -> bool:
    try:
        fn(*args)
    except numba.core.errors.TypingError as e:
        assert "readonly" in str(e) or "read-only" in str(e) or "unlock" in str(e) or "No implementation" in str(e)
        return False
    return True


def test_only_unlock_writes_the_books_and_nothing_writes_a_parameter():
    from infomarket.state.view import unlock

    h = Handle(make_config(2))

    @njit
    def write_balance(w):
        w.balance[0] = 5.0

    @njit
    def write_log(w):
        w.ev_count[0] = 3

    @njit
    def write_parameter(w):
        w.sites_r[0] = 1.0

    @njit
    def unlock_parameter(w):
        unlock(w.sites_r)[0] = 1.0

    @njit
    def ledger_operation(w):
        unlock(w.balance)[0] = 5.0

    assert not _compiles(write_balance, h.view)
    assert not _compiles(write_log, h.view)
    assert not _compiles(write_parameter, h.view)
    assert not _compiles(unlock_parameter, h.view)
    assert _compiles(ledger_operation, h.view) and h.world.balance[0] == 5.0


def test_a_rule_that_writes_a_balance_does_not_compile():
    """A buy rule as users write it (registering one wraps it in numba.njit, as here), given the
    view the step loop gives it; no kernel is built, so the test costs no step compile."""
    import numpy as np
    import pytest

    def thief_buy(w, me, nbrs):
        w.balance[me] += 1.0

    def honest_buy(w, me, nbrs):
        w.new_valid[me, 0] = False  # its own robot's new table: allowed

    h = Handle(make_config(2))
    nbrs = np.array([1], np.int64)
    with pytest.raises(numba.core.errors.TypingError, match="readonly"):
        njit(thief_buy)(h.view, 0, nbrs)
    njit(honest_buy)(h.view, 0, nbrs)
    assert not h.world.new_valid[0, 0]


def test_a_view_is_the_hosts_own_memory_and_scalars_and_a_field_of_another_kind_is_refused():
    @njit
    def read(w):
        w.items[1] = 9  # written through the view: the host's array
        return w.pos[2, 1], w.nbr.shape[1], w.width, w.transitory

    h = Handle(make_config(3))
    h.world.pos[2, 1] = 4.25
    y, cols, width, transitory = read(h.view)
    assert (y, cols, width, transitory) == (4.25, h.world.nbr.shape[1], h.world.width, h.world.transitory)
    assert h.world.items[1] == 9
    wrong = h.world._replace(pos=h.world.pos.astype(np.float32))
    with pytest.raises(InternalError, match=r"'pos' is array\(float32"):
        make_view("world", wrong)
    names = list(type(h.world)._fields)
    names[:2] = names[1::-1]
    swapped = namedtuple("Swapped", names)(**h.world._asdict())
    with pytest.raises(InternalError, match="does not hold the fields of layout 'world' in its order"):
        make_view("world", swapped)


def test_a_function_of_a_view_has_a_short_symbol_and_the_payload_type_is_built_once(monkeypatch):
    # numba names a StructRef type by all its fields; a symbol or payload type built from that name for
    # every function and field access was a large share of a chain kernel's compile
    world, chain = layout_type("world"), layout_type("chainworld")
    assert len(world.name) > 5000 and len(chain.name) > len(world.name)  # numba's own name: every field

    @njit(cache=False)
    def clock_of(w):
        return w.clock[0]

    h = Handle(make_config(3))
    clock_of(h.view)
    (compiled,) = clock_of.overloads.values()
    assert len(compiled.fndesc.mangled_name) < 300, compiled.fndesc.mangled_name[:300]
    assert world.mangling_args != chain.mangling_args  # two layouts, two symbols

    built = []
    init = numba.types.StructRefPayload.__init__
    monkeypatch.setattr(numba.types.StructRefPayload, "__init__",
                        lambda self, *a, **k: built.append(1) or init(self, *a, **k))
    first = world.get_data_type()
    for _ in range(3):
        assert world.get_data_type() is first
    assert len(built) <= 1
