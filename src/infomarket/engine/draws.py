"""Random draws from a numpy ``Generator`` or from its bit generator, with the same numbers either way.

The step loop passes the engine's own pieces (foraging, the random walk, motion noise) the Generator's
bit generator rather than the Generator: numba counts references to a Generator each time one is passed
to a function (an atomic add behind an out-of-line call), while a bit generator is a plain struct.
numba's ``Generator.random()`` is ``next_double`` on the bit generator and ``Generator.normal(loc,
scale)`` is ``random_normal`` on it, so these give the same draws as the methods, in the same order.
Rules still receive the Generator (``rng``), which is the public API.
"""
from __future__ import annotations

import numpy as np
from numba import types
from numba.extending import overload

from .._numba_internals import next_double, random_normal


def uniform(source):
    """A draw from [0, 1): ``source.random()``."""
    if isinstance(source, np.random.Generator):
        return source.random()
    return np.random.Generator(source).random()  # plain Python (NUMBA_DISABLE_JIT): the same stream


def normal(source, loc, scale):
    """A draw from N(loc, scale²): ``source.normal(loc, scale)``."""
    if isinstance(source, np.random.Generator):
        return source.normal(loc, scale)
    return np.random.Generator(source).normal(loc, scale)


@overload(uniform, inline="always")
def _uniform(source):
    if isinstance(source, types.NumPyRandomGeneratorType):
        return lambda source: source.random()
    if isinstance(source, types.NumPyRandomBitGeneratorType):
        return lambda source: next_double(source)


@overload(normal, inline="always")
def _normal(source, loc, scale):
    if isinstance(source, types.NumPyRandomGeneratorType):
        return lambda source, loc, scale: source.normal(loc, scale)
    if isinstance(source, types.NumPyRandomBitGeneratorType):
        return lambda source, loc, scale: random_normal(source, loc, scale)
