"""``[chain]`` values that cannot act in the run: refused when they contradict the rest of the section,
warned about (one line, ``ConfigWarning``) when only the run's length keeps them from acting.

A contradiction (a key of the chain model under ``consensus = "instant"``, a ``latency`` without a
backbone) is a mistake whatever the run's length, so it is a ``ConfigError``.  A value beyond the run's
end (no block in the run, a partition that starts after it, a backbone that never delivers, a finality
depth no run this long reaches) is a warning, not a refusal: a shortened look at a chain study
(``--steps 300``) keeps running its longer settings, and says which of them do nothing.
"""
from __future__ import annotations

import warnings

from ..errors import ConfigError, ConfigWarning

#: The keys the chain model reads; the instant ledger reads none of them.
POA_KEYS = ("period", "signers", "out_of_turn_delay", "backbone", "latency", "loss", "gas_price", "finality",
            "partition")


def check(chain, steps: int) -> list[str]:
    """Raise ConfigError for a contradiction in ``chain`` (a ``config.schema.Chain``); return (and warn
    about) what cannot act in a run of ``steps`` steps."""
    defaults = type(chain)()
    if not chain.enabled:
        moved = [k for k in POA_KEYS if getattr(chain, k) != getattr(defaults, k)]
        if moved:
            raise ConfigError(f"chain.{moved[0]} = {_shown(getattr(chain, moved[0]))}: consensus = \"instant\" (the "
                              f"paper's shared ledger) has no blocks, network or gas, so "
                              f"{', '.join('chain.' + k for k in moved)} would do nothing; set chain.consensus = "
                              f"\"poa\", or remove {'it' if len(moved) == 1 else 'them'}")
        return []
    if chain.latency and not chain.backbone:
        raise ConfigError(f"chain.latency = {chain.latency}: the latency is the backbone's, and chain.backbone is "
                          f"false; set chain.backbone = true, or remove chain.latency")
    notes = []
    if chain.period >= steps:
        notes.append(f"chain.period = {chain.period} is not below steps = {steps}: no block is made in the run")
    if chain.partition is not None and chain.partition[0] >= steps:
        notes.append(f"chain.partition = [{chain.partition[0]}, {chain.partition[1]}] starts at or after the run's "
                     f"end (steps = {steps}): the network is never partitioned")
    if chain.backbone and chain.latency >= steps:
        notes.append(f"chain.latency = {chain.latency} is not below steps = {steps}: the backbone delivers nothing "
                     f"within the run")
    if chain.finality > steps:
        notes.append(f"chain.finality = {chain.finality} is more blocks than a run of {steps} steps can make: no "
                     f"block becomes final by depth (only once every robot's head is on it)")
    for note in notes:
        warnings.warn(note, ConfigWarning, stacklevel=2)
    return notes


def describe(chain) -> str:
    """The ``[chain]`` section in one line (``infomarket check``)."""
    if not chain.enabled:
        return "chain: instant (the paper's shared ledger; no [chain] keys act)"
    signers = f"signers {', '.join(map(str, chain.signers))}" if chain.signers else "every robot signs"
    net = (f"a backbone {chain.latency} step(s) late" if chain.backbone else "no backbone") + \
        f", message loss {chain.loss:g}"
    part = f", partitioned during steps [{chain.partition[0]}, {chain.partition[1]})" if chain.partition else ""
    return (f"chain: poa, a block every {chain.period} step(s) (out-of-turn delay {chain.out_of_turn_delay}), "
            f"{signers}; {net}; gas price {chain.gas_price:g}; finality {chain.finality} blocks{part}")


def _shown(value) -> str:
    return str(list(value)) if isinstance(value, (list, tuple)) else repr(value) if isinstance(value, str) \
        else str(value).lower() if isinstance(value, bool) else str(value)
