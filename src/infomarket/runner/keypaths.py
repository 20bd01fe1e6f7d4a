"""Key paths: how sweeps and sampled designs name a key of an experiment (``payment.stake``,
``swarm.groups[1].params.rotation_angle``), shared by the grid expansion (``runner.plan``) and the sampled
designs (``runner.design``)."""
from __future__ import annotations

import re
from typing import Any

from ..errors import ConfigError

#: one dotted part of a key path: a name, optionally indexed (``groups[1]``)
KEY_PART = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)(?:\[(\d+)\])?$")


def set_path(data: dict, path: str, value: Any, where: str) -> None:
    """Assign ``value`` at a dotted path like ``swarm.groups[1].params.rotation_angle``."""
    parts = path.split(".")
    node: Any = data
    for k, part in enumerate(parts):
        m = KEY_PART.match(part)
        if not m:
            raise ConfigError(f"{where}: {path!r} is not a key path (like payment.stake or swarm.groups[1].count)")
        name, index = m.group(1), m.group(2)
        last = k == len(parts) - 1
        if not isinstance(node, dict) or (name not in node and not (last and parts[k - 1] == "params")):
            allowed = ", ".join(sorted(node)) if isinstance(node, dict) else "none"
            raise ConfigError(f"{where}: unknown condition key {path!r}: no {name!r} here; allowed: {allowed}")
        if index is not None:
            seq = node[name]
            if not isinstance(seq, list) or int(index) >= len(seq):
                raise ConfigError(f"{where}: {path!r}: index {index} out of range")
            if last:
                seq[int(index)] = value
            else:
                node = seq[int(index)]
            continue
        if last:
            node[name] = value
        else:
            node = node[name]


def label(path: str) -> str:
    """The column a key path names: its last key without an index (``swarm.groups[1].count`` -> ``count``)."""
    part = KEY_PART.match(path.split(".")[-1])
    assert part is not None, path  # every key path was checked against KEY_PART where it was read
    return part.group(1)
