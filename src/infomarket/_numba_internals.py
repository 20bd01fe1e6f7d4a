"""Every private numba API infomarket uses, checked once, here.

The compiled view (``state.view``), the engine's draws (``engine.draws``), the rule registry
(``registry``) and the disk cache of the package's compiled functions (``compiled_cache``) lean on numba
internals that numba may rename or drop in any release.  They are taken from
this module only, which checks the installed numba against the range the tests cover and that each
internal is there, so an unsupported numba fails at import with one message naming the numba version and
what is missing, instead of a compile error deep in a kernel.  pyproject.toml pins numba to ``SUPPORTED``.
"""
from __future__ import annotations

import itertools

import numba
from numba.core import caching, ir_utils
from numba.core import registry as _registry
from numba.experimental import structref
from numba.np.random import distributions, generator_core

from .errors import InfomarketError

#: the numba releases the tests cover: ``LOW <= version < HIGH`` (major, minor); keep pyproject.toml's pin equal
SUPPORTED = ((0, 68), (0, 69))


class UnsupportedNumba(InfomarketError, ImportError):
    """The installed numba is outside the supported range or lacks an internal infomarket uses."""


def _range_text() -> str:
    (a, b), (c, d) = SUPPORTED
    return f"numba>={a}.{b},<{c}.{d}"


def check_version(version: str) -> None:
    """Raise ``UnsupportedNumba`` when ``version`` (``numba.__version__``) is outside ``SUPPORTED``."""
    try:
        major_minor = tuple(int(p) for p in version.split(".")[:2])
    except ValueError:
        raise UnsupportedNumba(f"numba {version}: cannot read the version; "
                               f"infomarket supports {_range_text()}") from None
    low, high = SUPPORTED
    if not low <= major_minor < high:
        raise UnsupportedNumba(f"numba {version} is not supported: infomarket supports {_range_text()} "
                               f"(pip install '{_range_text()}')")


def require(owner, name: str, where: str, version: str | None = None):
    """``owner.name``, or ``UnsupportedNumba`` naming the numba version and the missing internal."""
    version = version or numba.__version__
    if name in getattr(owner, "__slots__", ()):  # a slot (an instance attribute) is there when declared
        return name
    try:
        return getattr(owner, name)
    except AttributeError:
        raise UnsupportedNumba(f"numba {version} has no {where}.{name}, which infomarket uses; "
                               f"infomarket supports {_range_text()}") from None


check_version(numba.__version__)

#: alias analysis: ``unlock(a)`` is ``a`` (state.view)
add_alias = require(ir_utils, "_add_alias", "numba.core.ir_utils")
alias_func_extensions = require(ir_utils, "alias_func_extensions", "numba.core.ir_utils")
#: the names of the classmethod numba boxes a StructRef with (``getattr(proxy_class, BOX)``) and of the
#: proxy's meminfo slot (state.view)
require(structref.StructRefProxy, "_numba_box_", "numba.experimental.structref.StructRefProxy")
BOX = "_numba_box_"
MEMINFO = require(structref.StructRefProxy, "_meminfo", "numba.experimental.structref.StructRefProxy")
#: ``Generator.random()`` on a bare bit generator (engine.draws)
next_double = require(generator_core, "next_double", "numba.np.random.generator_core")
#: ``Generator.normal(loc, scale)`` on a bare bit generator (engine.draws)
random_normal = require(distributions, "random_normal", "numba.np.random.distributions")
#: the type of an ``@njit`` function (registry): a rule already compiled is taken as it is
CPUDispatcher = require(_registry, "CPUDispatcher", "numba.core.registry")

#: numba's disk cache (compiled_cache): the base of a locator (which must keep its function's file as
#: ``_py_file``: numba's warning that a function cannot be cached reads it), the list of locators a cached
#: function is offered to, and the index-and-data files of one function's cache (saved in order below)
CacheLocator = require(caching, "_CacheLocator", "numba.core.caching")
IndexDataCacheFile = require(caching, "IndexDataCacheFile", "numba.core.caching")
_locators = require(require(caching, "CacheImpl", "numba.core.caching"), "_locator_classes",
                    "numba.core.caching.CacheImpl")
_INDEX_METHODS = ("_load_index", "_save_index", "_save_data", "_data_name")
for _method in _INDEX_METHODS:
    require(IndexDataCacheFile, _method, "numba.core.caching.IndexDataCacheFile")


class _OrderedIndex(IndexDataCacheFile):
    """numba's index and data files of one function, whose ``save`` (where ``_save_lock(cache_path)`` gives a
    lock) runs under that lock and writes the code before the index entry that names it; elsewhere
    exactly numba's.  numba's own reads the index, writes it back with the new entry, then writes the code:
    two processes saving two signatures at once could both take one file name, and leave an index that
    names a file holding the other's code."""

    def __init__(self, cache_path, filename_base, source_stamp):
        super().__init__(cache_path, filename_base, source_stamp)
        self._folder = cache_path

    def save(self, key, data):
        lock = _save_lock(self._folder) if _save_lock is not None else None
        if lock is None:
            return super().save(key, data)
        with lock:
            overloads = self._load_index()
            name = overloads.get(key)
            if name is None:
                taken = set(overloads.values())
                name = next(n for n in map(self._data_name, itertools.count(1)) if n not in taken)
            self._save_data(name, data)
            overloads[key] = name
            self._save_index(overloads)


#: ``install_cache``'s ``lock``
_save_lock = None


def install_cache(locator, lock) -> None:
    """Offer every function cached from now on to ``locator`` first (a ``CacheLocator``), and save each
    cache whose folder ``lock(folder)`` gives a lock for (a context manager; None: numba's save) in order,
    under that lock (``_OrderedIndex``: numba's ``Cache`` makes its index by the module-level name)."""
    global _save_lock
    if locator not in _locators:
        _locators.insert(0, locator)
    _save_lock = lock
    caching.IndexDataCacheFile = _OrderedIndex


#: each internal as (owner, name, where), for the tests
USES = ((ir_utils, "_add_alias", "numba.core.ir_utils"), (ir_utils, "alias_func_extensions", "numba.core.ir_utils"),
        (structref.StructRefProxy, "_numba_box_", "numba.experimental.structref.StructRefProxy"),
        (structref.StructRefProxy, "_meminfo", "numba.experimental.structref.StructRefProxy"),
        (generator_core, "next_double", "numba.np.random.generator_core"),
        (distributions, "random_normal", "numba.np.random.distributions"),
        (_registry, "CPUDispatcher", "numba.core.registry"), (caching, "_CacheLocator", "numba.core.caching"),
        (caching, "IndexDataCacheFile", "numba.core.caching"), (caching, "CacheImpl", "numba.core.caching"),
        (caching.CacheImpl, "_locator_classes", "numba.core.caching.CacheImpl"),
        *((IndexDataCacheFile, m, "numba.core.caching.IndexDataCacheFile") for m in _INDEX_METHODS))
