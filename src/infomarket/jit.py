"""The package's ``njit``: numba's, compiled without the C-callable wrapper.

Beside every function it compiles, numba compiles a second, C-callable wrapper, so that the function can
be passed around as a first-class value (a ``FunctionType`` argument).  Nothing in the package, and no
rule, is used that way: compiled code calls each function by name, and Python calls the dispatcher.  A
step kernel holds a few hundred functions, so the wrappers were a noticeable part of every first compile
(docs/testing.md).  A function compiled with this ``njit`` is a plain numba dispatcher in every other
way; the built-in rules and the rules users register (``registry``) are compiled with it alike.
"""
import numba

#: What the package sets on every compiled function, unless the decorator says otherwise.
DEFAULTS = {"no_cfunc_wrapper": True}


def njit(*args, **options):
    """``numba.njit`` with ``DEFAULTS`` (``@njit``, ``@njit(cache=True)`` or ``njit(func, ...)``)."""
    return numba.njit(*args, **{**DEFAULTS, **options})
