"""Numba typed lists of views and generators, the ``step_all`` kernels' arguments (``engine.batch``,
``engine.simulation``), built and changed by functions cached on disk."""
from numba import typed

from ..jit import njit


# A typed list built or changed from Python has numba compile its methods (make, append, set item) for
# its item type in every process, uncached: about a quarter of a second each, paid by every pool worker and
# command process for its views and generators.  Built and changed here, in functions cached on disk, the
# first process compiles them and the others load them.
@njit(cache=True)
def _list_of(item):
    out = typed.List()
    out.append(item)
    return out


@njit(cache=True)
def _append(items, item):
    items.append(item)


@njit(cache=True)
def put(items, i, item):
    """``items[i] = item`` on a typed list, compiled once and cached so that building lists compiles nothing per
    run."""
    items[i] = item


def typed_list(items: list) -> typed.List:
    """A numba typed list of ``items`` (one type, at least one), made by the cached functions above."""
    out = _list_of(items[0])
    for item in items[1:]:
        _append(out, item)
    return out
