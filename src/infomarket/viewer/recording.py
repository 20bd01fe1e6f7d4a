"""Record a run once and write it as a self-contained HTML replay (``infomarket replay --out``).

A recording is the scene, a frame every ``every`` steps and the event log: exactly what the live page
receives, so the replay is the live page itself with the data embedded (gzip + base64 inside a JSON
``<script>``) and its script and style inlined.  It opens from disk, needs no server and no network,
and has the same drawing and controls except restart; a slider moves through the run.
"""
from __future__ import annotations

import base64
import gzip
import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from html import escape
from pathlib import Path

import numpy as np

from .._version import __version__
from ..config.schema import Experiment
from ..engine import Simulation
from ..checks import explain
from ..errors import InfomarketError, InternalError
from . import STATIC
from ..ledger.blocklog import BranchNumbers
from .frames import Frame, decode, encode, event_columns, frame_size, honest_mask, scene

#: Frames a replay holds by default: enough to watch smoothly, small enough to open fast (~2 MB for 25
#: robots); large swarms get fewer, so that the frames stay within ``FRAME_BYTES`` before compression.
DEFAULT_FRAMES = 1500
FRAME_BYTES = 24_000_000


@dataclass
class Recording:
    """One run as the viewer sees it."""

    scene: dict
    frames: list[bytes]
    events: dict[str, np.ndarray]
    every: int

    def frame(self, k: int) -> Frame:
        """Frame ``k`` of the recording, decoded."""
        return decode(self.frames[k], self.scene["n"], self.scene.get("chain") is not None)


def default_every(steps: int, robots: int = 25) -> int:
    """Steps between kept frames: about ``DEFAULT_FRAMES`` in all, fewer for large swarms."""
    frames = max(50, min(DEFAULT_FRAMES, FRAME_BYTES // frame_size(robots)))
    return max(1, math.ceil(steps / frames))


def record(config: Experiment, seed: int | None = None, *, steps: int | None = None, every: int | None = None,
           on_progress: Callable[[int, int], None] | None = None) -> Recording:
    """Run ``config`` for ``steps`` (default: its own) keeping a frame every ``every`` steps."""
    steps = config.steps if steps is None else steps
    every = default_every(steps, config.swarm.robots) if every is None else every
    try:
        sim = Simulation(config, seed, record_events=True)
    except InfomarketError:
        raise
    except Exception as exc:  # noqa: BLE001 - a rule that keeps the kernel from compiling: named (checks.explain)
        raise explain(config, seed, exc) from None
    honest = honest_mask(sim)
    branches = BranchNumbers()  # a branch keeps its number from frame to frame while it lasts
    frames = [encode(sim, honest, branches)]
    while sim.clock < steps:
        try:
            sim.step(min(every, steps - sim.clock))
        except Exception as exc:  # noqa: BLE001 - a rule raised: named with its file, line and the step
            raise explain(config, sim.seed, exc, sim, record_events=True) from None
        frames.append(encode(sim, honest, branches))
        if on_progress:
            on_progress(sim.clock, steps)
    return Recording(scene(sim), frames, event_columns(sim), every)


def _pack(data: bytes) -> str:
    return base64.b64encode(gzip.compress(data, compresslevel=6, mtime=0)).decode("ascii")


#: The viewer's scripts, in the order the page loads them (classic scripts: a page opened from disk may not
#: load ES modules).
SCRIPTS = ("viewer-draw.js", "viewer.js")


def _inline(page: str, old: str, new: str) -> str:
    if page.count(old) != 1:
        raise InternalError(f"viewer page template changed: expected one {old!r}")  # a packaging defect
    return page.replace(old, new)


def html(rec: Recording) -> str:
    """The replay page as one string."""
    events = rec.events
    payload = {
        "generator": f"infomarket {__version__}",
        "scene": rec.scene,
        "every": rec.every,
        "frame_count": len(rec.frames),
        "frames": _pack(b"".join(rec.frames)),
        "event_count": int(len(events["step"])),
        "events": _pack(b"".join(events[c].astype("<i4").tobytes()
                                 for c in ("step", "kind", "buyer", "seller", "site"))),
    }
    data = json.dumps(payload, separators=(",", ":")).replace("<", "\\u003c")  # nothing can close the tag
    page = (STATIC / "index.html").read_text(encoding="utf-8")
    css = (STATIC / "viewer.css").read_text(encoding="utf-8")
    page = _inline(page, '<link rel="stylesheet" href="static/viewer.css">', f"<style>\n{css}</style>")
    for name in SCRIPTS:  # in the page's order: the drawing part first, the part that starts the viewer last
        js = (STATIC / name).read_text(encoding="utf-8").replace("</script", "<\\/script")
        tag = f"<script>\n{js}</script>"
        if name == SCRIPTS[-1]:
            tag = f'<script id="infomarket-replay" type="application/json">{data}</script>\n{tag}'
        page = _inline(page, f'<script src="static/{name}"></script>', tag)
    return _inline(page, "<title>infomarket viewer</title>",
                   f"<title>infomarket replay: {escape(rec.scene['name'])}, seed {rec.scene['seed']}</title>")


def write_html(rec: Recording, path: str | Path) -> Path:
    """Write the replay page to ``path`` (atomically: a half-written file never appears)."""
    path = Path(path)
    tmp = path.with_name(path.name + ".part")
    try:
        tmp.write_text(html(rec), encoding="utf-8")
        tmp.replace(path)
    except BaseException:  # a full disk, Ctrl-C: no .part file is left behind
        tmp.unlink(missing_ok=True)
        raise
    return path
