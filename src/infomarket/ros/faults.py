"""The faults ``infomarket ros swarm --fault`` injects, parsed without loading the engine or ROS 2."""
from __future__ import annotations

import re
from dataclasses import dataclass

from ..errors import ArgumentError


@dataclass(frozen=True)
class Faults:
    kill: tuple[int, int] | None = None  # (robot, step)
    drop: float = 0.0
    hostile: bool = False


def parse_fault(text: str) -> Faults:
    """One ``--fault`` value: ``kill:ROBOT@STEP``, ``drop:P`` (0 <= P < 1) or ``hostile``."""
    if text == "hostile":
        return Faults(hostile=True)
    m = re.fullmatch(r"kill:(\d+)@(\d+)", text)
    if m:
        return Faults(kill=(int(m[1]), int(m[2])))
    m = re.fullmatch(r"drop:([0-9.eE+-]+)", text)
    if m:
        try:
            p = float(m[1])
        except ValueError:
            p = -1.0
        if 0 <= p < 1:
            return Faults(drop=p)
        raise ArgumentError(f"--fault drop:P needs 0 <= P < 1, not {m[1]}")
    raise ArgumentError(f"--fault {text!r}: expected kill:ROBOT@STEP, drop:P or hostile")


def merge(faults: list[Faults]) -> Faults:
    kill = next((f.kill for f in faults if f.kill), None)
    return Faults(kill, max((f.drop for f in faults), default=0.0), any(f.hostile for f in faults))
