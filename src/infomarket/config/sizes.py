"""How much memory a configuration needs, checked before any of it is spent.

The estimate follows the engine's O(n) layout (``engine.world``): per robot, a few hundred bytes of O(1) state
and O(k) buffers (neighbours, pending transactions, offers), with k bounded by how many robots fit in
communication range; a neighbour grid; the Lévy step-length table, 16 bytes × (steps + 1), once per
process (the worlds it steps share it); the wealth history, 8 bytes × robots × steps / history_every (and
its long table); the event log when recorded.  A sweep's process steps several worlds at once, and a pool
has several processes (``held_bytes``).  Results kept in memory (``run``'s tables, a store read whole)
cost per robot per run.

The limit is ``INFOMARKET_MEMORY_LIMIT`` (e.g. ``64GiB``, ``500MB``, or a number of bytes) when set, else
80 % of this machine's physical memory.  Estimates are deliberately a little generous: a refusal names
the estimate, its largest parts and how to raise the limit.
"""
from __future__ import annotations

import math
import os
import re

from ..errors import ConfigError

ENV = "INFOMARKET_MEMORY_LIMIT"
# O(1) per-robot state (~480 B: engine.world) + its first 16-entry transaction block (40 B each)
ROBOT_BYTES = 1200
# per neighbour slot per robot: index (8), a pending entry per site (2 x 32), 2 transactions (2 x 40)
SLOT_BYTES = 160
LEVY_BYTES = 16              # per entry of the step-length table (CDF + guide), steps + 1 entries
HISTORY_BYTES = 8 + 24       # per robot per sample: the float64 array, then its long table (step, robot, wealth)
EVENTS_PER_ROBOT_STEP = 0.5  # the paper's runs log 0.21-0.29 events per robot per step
EVENT_BYTES = 96 + 96        # 12 int64/float64 columns, in the engine's log and in its DataFrame
PAYMENT_BYTES = 48 + 48      # 6 columns, at most one row per purchase (bounded by the events' rate)
ROBOT_ROW_BYTES = 96         # one row of the robots table (9 columns, categorical behaviour)
RUN_ROW_BYTES = 256          # one row of the runs table (strings included) and its seed bookkeeping
#: parts held once per process, however many worlds it steps (``held_bytes``)
SHARED_PARTS = frozenset({"Lévy step-length table"})
_UNITS = {"": 1, "b": 1, "k": 10**3, "kb": 10**3, "m": 10**6, "mb": 10**6, "g": 10**9, "gb": 10**9,
          "t": 10**12, "tb": 10**12, "kib": 2**10, "mib": 2**20, "gib": 2**30, "tib": 2**40}


def human(n: float) -> str:
    """Bytes in binary units, e.g. ``7.3 TiB``."""
    if abs(n) < 1024:
        return f"{n:.0f} B"
    for unit in ("KiB", "MiB", "GiB", "TiB"):
        n /= 1024
        if abs(n) < 1024:
            return f"{n:.1f} {unit}"
    return f"{n / 1024:.1f} PiB"


def parse_bytes(text: str) -> int:
    """A size as ``INFOMARKET_MEMORY_LIMIT`` writes it, in bytes (binary and decimal units, case-insensitive).

    Raises:
        ConfigError: ``text`` is not a number with an optional known unit.

    Example:
        >>> from infomarket.config.sizes import parse_bytes
        >>> parse_bytes("64GiB") == 64 * 2**30, parse_bytes("500MB"), parse_bytes("1024")
        (True, 500000000, 1024)
    """
    m = re.fullmatch(r"\s*([0-9]+(?:\.[0-9]+)?)\s*([a-zA-Z]*)\s*", text)
    if not m or m.group(2).lower() not in _UNITS:
        raise ConfigError(f"{ENV}={text!r}: expected a size like 64GiB, 500MB or a number of bytes")
    return int(float(m.group(1)) * _UNITS[m.group(2).lower()])


def physical_memory() -> int:
    """This machine's physical memory in bytes (8 GiB assumed where the system does not tell)."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
        return 8 * 2**30


def limit() -> tuple[int, str]:
    """The memory limit in bytes, and where it comes from (for messages)."""
    text = os.environ.get(ENV)
    if text:
        return parse_bytes(text), f"{ENV}={text}"
    return int(0.8 * physical_memory()), "80 % of this machine's memory"


def neighbour_slots(cfg) -> int:
    """Most robots whose discs fit within communication range of one robot (a packing bound), at most n - 1."""
    n, r, reach = cfg.swarm.robots, cfg.robot.radius, cfg.robot.communication_range
    ratio = min((reach + r) / r, float(n))  # capped first: a huge range must not overflow the square
    return int(min(n - 1, math.ceil(ratio ** 2)))


def run_bytes(cfg, *, record_events: bool = False, history_every: int | None = None) -> dict[str, int]:
    """Estimated bytes of one run of ``cfg``, by part."""
    n, steps = cfg.swarm.robots, cfg.steps
    every = cfg.history_every if history_every is None else history_every
    from ..space.grid import grid_shape  # the config layer stays free of the compiled space code until sized

    _, nx, ny = grid_shape(cfg.arena.width, cfg.arena.height, cfg.robot.communication_range, n)
    cells = nx * ny
    parts = {
        "robot state": n * (ROBOT_BYTES + ROBOT_ROW_BYTES),
        "neighbour and transaction buffers": n * neighbour_slots(cfg) * SLOT_BYTES + 8 * (cells + n),
        "Lévy step-length table": LEVY_BYTES * (steps + 1),
        "wealth history": n * (steps // every) * HISTORY_BYTES if every else 0,
        "event log": int(n * steps * EVENTS_PER_ROBOT_STEP * EVENT_BYTES) if record_events else 0,
        "payments log": int(n * steps * EVENTS_PER_ROBOT_STEP * PAYMENT_BYTES) if record_events else 0,
    }
    return parts


def results_bytes(cfg, runs: int, *, history_every: int | None = None) -> int:
    """Estimated bytes of the results of ``runs`` runs held at once (``run``'s tables, a store read whole)."""
    n = cfg.swarm.robots
    every = cfg.history_every if history_every is None else history_every
    per_run = n * ROBOT_ROW_BYTES + RUN_ROW_BYTES + (n * (cfg.steps // every) * HISTORY_BYTES if every else 0)
    return runs * per_run


def _refusal(what: str, need: int, parts: dict[str, int] | None, fix: str) -> str:
    cap, source = limit()
    detail = ""
    if parts:
        top = sorted(((v, k) for k, v in parts.items() if v), reverse=True)[:3]
        detail = " (" + ", ".join(f"{k} {human(v)}" for v, k in top) + ")"
    return (f"{what} would need about {human(need)} of memory{detail}, more than the limit of {human(cap)} "
            f"({source}); {fix}, or raise the limit deliberately: {ENV}={human(need * 1.25).replace(' ', '')}")


def run_too_big(cfg, *, record_events: bool = False, history_every: int | None = None) -> str | None:
    """Why one run of ``cfg`` would not fit in memory, or None."""
    parts = run_bytes(cfg, record_events=record_events, history_every=history_every)
    need = sum(parts.values())
    if need <= limit()[0]:
        return None
    return _refusal("one run", need, parts, "use fewer robots or steps (or a larger history_every)")


def runs_too_big(cfg, runs: int, *, history_every: int | None = None) -> str | None:
    """Why the results of ``runs`` runs of ``cfg`` would not fit in memory, or None."""
    need = results_bytes(cfg, runs, history_every=history_every)
    if need <= limit()[0]:
        return None
    return _refusal(f"the results of {runs:,} runs", need, None, "ask for fewer runs")


def held_bytes(cfg, worlds: int, processes: int = 1, *, record_events: bool = False) -> dict[str, int]:
    """Estimated bytes, by part, of ``processes`` processes each stepping ``worlds`` runs of ``cfg`` at once:
    the worlds of one process share the random walk's sampling tables (``engine.build.SHARED_TABLES``)."""
    return {k: v * processes * (1 if k in SHARED_PARTS else worlds)
            for k, v in run_bytes(cfg, record_events=record_events).items()}


def held_too_big(cfg, worlds: int, processes: int = 1, *, record_events: bool = False) -> str | None:
    """Why ``processes`` processes (pool workers, or the command's own), each stepping ``worlds`` runs of
    ``cfg`` at once, would not fit in memory, or None."""
    parts = held_bytes(cfg, worlds, processes, record_events=record_events)
    need = sum(parts.values())
    if need <= limit()[0]:
        return None
    who = f"{processes} worker processes, each" if processes > 1 else "one process"
    return _refusal(f"{who} stepping {worlds} run(s) of {cfg.steps:,} steps at once", need, parts,
                    "use fewer --steps or --workers (or a larger history_every)")


def recording_too_big(cfg, frames: int, frame_bytes: int) -> str | None:
    """Why a replay of ``cfg`` (one run with its event log, and ``frames`` frames of ``frame_bytes`` each,
    held twice while the page is written) would not fit in memory, or None."""
    parts = run_bytes(cfg, record_events=True)
    parts["frames"] = 2 * frames * frame_bytes
    need = sum(parts.values())
    if need <= limit()[0]:
        return None
    return _refusal(f"a replay of {cfg.steps:,} steps in {frames:,} frames", need, parts,
                    "use fewer --steps or a larger --every")


def batch_too_big(cfg, runs: int, what: str, *, extra: dict[str, int] | None = None) -> str | None:
    """Why ``runs`` runs of ``cfg`` held at once (the RL vector env's worlds: ``what`` names the option
    that asked for them), plus ``extra`` bytes by part, would not fit in memory, or None."""
    parts = held_bytes(cfg, runs)
    parts.update(extra or {})
    need = sum(parts.values())
    if need <= limit()[0]:
        return None
    return _refusal(f"{what}: {runs:,} runs at once", need, parts, "ask for fewer runs at once")
