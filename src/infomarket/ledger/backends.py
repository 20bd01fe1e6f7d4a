"""The ledgers a step kernel can be compiled for, and the operations the step loop calls on them.

``LEDGERS``: ``"instant"`` (``ledger.instant``: the paper's ledger, every purchase and deposit applied
at once) and ``"poa"`` (``ledger.poa``: robots as the nodes of a proof-of-authority chain, whose blocks
apply them later).  A kernel is compiled for one, its ``LEDGER`` option (written by ``engine.specialise``
beside ``TERRAIN`` and ``PATHS``); ``operations(LEDGER, settle)`` gives that ledger's compiled
operations, chosen before anything compiles, so a kernel compiles nothing of the other ledger:

``has_room(w)``          can the next step's transactions fit (else the host grows the arrays)
``begin_step(w)``        at the start of a step, after the neighbours are found
``deposit(w, i, rng)``   robot i deposited an item (``settle`` at once, or a deposit transaction)
``end_of_step(w, rng)``  after every robot has moved

The fifth, opening a transaction, is called by buy rules, which are compiled for whatever world they
are given: ``ledger.kernels.open_transaction`` reaches the same ledger through the world's type (a
world of the chain layout holds ``ledger.poa.spec.SPEC``).  ``settle(w, i, rng)`` is the kernel's
settlement (its payment rule's weights, then ``ledger.kernels.distribute``), written once in the loop.
"""
from __future__ import annotations

import functools
from typing import NamedTuple
from collections.abc import Callable

from ..jit import njit

from ..errors import InternalError
from . import instant
from .poa.arena import room_fits
from .poa.blocks import end_of_step
from .poa.gossip import gossip
from .poa.mempool import send_deposit

LEDGERS = ("instant", "poa")


class Operations(NamedTuple):
    """One ledger's operations for the step loop (the module docstring says when each is called)."""

    has_room: Callable
    begin_step: Callable
    deposit: Callable
    end_of_step: Callable


@njit(forceinline=True, cache=True)
def _nothing(w):
    pass


@njit(forceinline=True, cache=True)
def _nothing_yet(w, rng):
    pass


@njit(cache=True)
def _send_deposit(w, i, rng):
    send_deposit(w, i)


@functools.cache
def operations(ledger: str, settle) -> Operations:
    """The operations of ``ledger`` (one of ``LEDGERS``) around the kernel's ``settle``."""
    if ledger == "instant":
        return Operations(instant.has_room, _nothing, settle, _nothing_yet)
    if ledger == "poa":
        return Operations(room_fits, gossip, _send_deposit, end_of_step(settle))
    raise InternalError(f"unknown ledger {ledger!r}: one of {', '.join(LEDGERS)}")
