"""One viewer's simulation and playback state, and the commands a page may send.

Every browser connection gets its own ``Session`` (its own ``Simulation``), so two tabs on one server
never step, restart or inspect each other's swarm.  A session is plain synchronous Python: the server
runs its slow calls (building, stepping) in a worker thread, one at a time per session.

Commands are JSON objects with a ``cmd`` key (the page's whole vocabulary):

=========  ===========================  =====================================================
cmd        other keys                   effect
=========  ===========================  =====================================================
play       (none)                       stream frames, ``speed`` steps apart
pause      (none)                       stop streaming
step       ``n`` (default 1)            advance ``n`` steps now and send that frame
speed      ``value`` (1..MAX_SPEED)     steps per frame while playing
restart    ``seed`` (optional)          a fresh swarm (a random seed unless given)
select     ``robot`` (id or null)       send that robot's details with every frame
ack        (none)                       the page has taken a frame (flow control)
=========  ===========================  =====================================================
"""
from __future__ import annotations

import json
import secrets
from dataclasses import dataclass, field

from ..config.schema import Experiment
from ..engine import Simulation
from ..checks import explain
from ..errors import InfomarketError
from ..seeds import MAX_SEED
from ..ledger.blocklog import BranchNumbers
from .frames import encode, honest_mask, robot_detail, scene

DEFAULT_SPEED = 10
MAX_SPEED = 1000
MAX_STEP = 10_000  # one command stays short, so Ctrl-C never waits long for a worker thread


class CommandError(InfomarketError, ValueError):
    """A message from the page that cannot be carried out; its text goes back to the page."""


@dataclass(frozen=True)
class Command:
    """One command from the page (play, pause, speed, select, ...), with its number when it takes one."""
    name: str
    value: int | None = None


def _int(msg: dict, key: str, lo: int, hi: int, default=None, *, optional=False) -> int | None:
    v = msg.get(key, default)
    if v is None and optional:
        return None
    if isinstance(v, bool) or not isinstance(v, int) or not lo <= v <= hi:
        raise CommandError(f"{msg.get('cmd')}: {key} must be an integer in [{lo}, {hi}], got {v!r}")
    return v


def parse_command(text: str | bytes, robots: int) -> Command:
    """Validate one message from the page; raise ``CommandError`` saying what is wrong."""
    try:
        msg = json.loads(text)
    except ValueError:
        raise CommandError(f"not JSON: {str(text)[:80]!r}") from None
    if not isinstance(msg, dict) or not isinstance(msg.get("cmd"), str):
        raise CommandError('expected an object like {"cmd": "play"}')
    cmd = msg["cmd"]
    if cmd in ("play", "pause", "ack"):
        return Command(cmd)
    if cmd == "step":
        return Command(cmd, _int(msg, "n", 1, MAX_STEP, 1))
    if cmd == "speed":
        return Command(cmd, _int(msg, "value", 1, MAX_SPEED))
    if cmd == "restart":
        if isinstance(msg.get("seed"), str) and msg["seed"].isascii() and msg["seed"].isdigit():
            msg = {**msg, "seed": int(msg["seed"])}  # the page sends seeds as text: JavaScript numbers stop at 2**53
        return Command(cmd, _int(msg, "seed", 0, MAX_SEED, optional=True))
    if cmd == "select":
        return Command(cmd, _int(msg, "robot", 0, robots - 1, optional=True))
    raise CommandError(f"unknown command {cmd!r}; known: play, pause, step, speed, restart, select, ack")


@dataclass
class Session:
    """A swarm being watched: the simulation, whether it plays, its speed and the selected robot."""

    config: Experiment
    seed: int | None = None
    playing: bool = False
    speed: int = DEFAULT_SPEED
    selected: int | None = None
    sim: Simulation = field(init=False)

    def __post_init__(self) -> None:
        self.restart(self.seed)

    @property
    def robots(self) -> int:
        """The swarm's size."""
        return len(self.sim.behaviour_names)

    def restart(self, seed: int | None = None) -> None:
        """A fresh swarm from step 0; a random seed unless one is given."""
        self.seed = secrets.randbelow(MAX_SEED + 1) if seed is None else int(seed)
        try:
            self.sim = Simulation(self.config, self.seed, record_events=True)
        except InfomarketError:
            raise
        except Exception as exc:  # noqa: BLE001 - a rule that keeps the kernel from compiling: named (checks.explain)
            raise explain(self.config, self.seed, exc) from None
        self._honest = honest_mask(self.sim)
        self._branches = BranchNumbers()  # a branch keeps its number (its ring's colour) while it lasts

    def scene(self) -> dict:
        """The ``scene`` message: what does not change while the run plays (arena, sites, robots' kinds)."""
        return {"type": "scene", **scene(self.sim)}

    def status(self) -> dict:
        """The ``status`` message: playing or not, speed, step, seed and the selected robot."""
        return {"type": "status", "playing": self.playing, "speed": self.speed, "step": self.sim.clock,
                "seed": self.seed, "selected": self.selected}

    def frame(self) -> bytes:
        """The current frame, binary-encoded for the page (``viewer.frames``)."""
        return encode(self.sim, self._honest, self._branches)

    def detail(self) -> dict | None:
        """The selected robot's details for the side panel; None when none is selected."""
        return None if self.selected is None else robot_detail(self.sim, self.selected, branches=self._branches)

    def advance(self, k: int) -> tuple[bytes, dict | None]:
        """Step ``k`` times; the new frame and the selected robot's details (run in a worker thread)."""
        try:
            self.sim.step(k)
        except Exception as exc:  # noqa: BLE001 - a rule raised: the page is told which, at which step (checks.explain)
            raise explain(self.config, self.seed, exc, self.sim, record_events=True) from None
        return self.frame(), self.detail()
