"""Every private numba API infomarket uses, checked once, here.

The compiled view (``state.view``), the engine's draws (``engine.draws``) and the rule registry
(``registry``) lean on numba internals that numba may rename or drop in any release.  They are taken from
this module only, which checks the installed numba against the range the tests cover and that each
internal is there, so an unsupported numba fails at import with one message naming the numba version and
what is missing, instead of a compile error deep in a kernel.  pyproject.toml pins numba to ``SUPPORTED``.
"""
from __future__ import annotations

import numba
from numba.core import ir_utils
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
        raise UnsupportedNumba(f"numba {version}: cannot read the version; infomarket supports {_range_text()}") from None
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

#: each internal as (owner, name, where), for the tests
USES = ((ir_utils, "_add_alias", "numba.core.ir_utils"), (ir_utils, "alias_func_extensions", "numba.core.ir_utils"),
        (structref.StructRefProxy, "_numba_box_", "numba.experimental.structref.StructRefProxy"),
        (structref.StructRefProxy, "_meminfo", "numba.experimental.structref.StructRefProxy"),
        (generator_core, "next_double", "numba.np.random.generator_core"),
        (distributions, "random_normal", "numba.np.random.distributions"),
        (_registry, "CPUDispatcher", "numba.core.registry"))
