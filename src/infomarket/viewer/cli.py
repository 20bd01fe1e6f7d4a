"""The ``view`` and ``replay`` commands (added to ``infomarket`` by the main CLI).

Bad input raises ``UsageError`` or ``ConfigError`` before anything runs or is written; the main CLI prints it in
one line
and exits 2.  Heavy imports (aiohttp, matplotlib) wait until a command actually needs them.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from ..cliargs import UsageError, at_least, seed_value, writable_file
from ..errors import InfomarketError
from . import DEFAULT_PORT

HTML_SUFFIXES = (".html", ".htm")


def _port(text: str) -> int:
    v = at_least(0)(text)
    if v > 65535:
        raise argparse.ArgumentTypeError(f"a port is at most 65535, got {v}")
    return v


QUIET = False  # --quiet: progress lines are not printed (errors and the viewer's address still are)


def _say(text: str) -> None:
    if not QUIET:
        print(text, file=sys.stderr, flush=True)


def _announce(text: str) -> None:
    """The line a user acts on (the viewer's address): on stdout, so ``infomarket view X | head -1`` gets it.
    With --quiet only the address itself, the line's last word (``server.serve`` ends the line with it),
    so a script can read it as is (docs/viewer.md)."""
    print(text.rsplit(None, 1)[-1] if QUIET else text, flush=True)


def _load(experiment: str, steps: int | None = None):
    from ..config import load_experiment  # with the command: `infomarket --help` stays light

    cfg = load_experiment(experiment)
    if steps is not None and steps != cfg.steps:
        cfg = cfg.with_overrides(steps=steps, transitory=min(cfg.transitory, steps - 1))
    return cfg


def _warm_up(cfg, seed: int | None) -> None:
    """Build one swarm before serving: checks the seed and compiles (or loads) the step kernel, so a page
    opens in a fraction of a second instead of waiting for the compiler."""
    from ..engine import Simulation  # with the command: `infomarket --help` does not import the engine

    t0 = time.perf_counter()
    _say("preparing the step kernel (the first use of a behaviour mix compiles for a few seconds)...")
    try:
        Simulation(cfg, seed)
    except InfomarketError:
        raise
    except Exception as exc:  # noqa: BLE001 - a rule that keeps the kernel from compiling: named (checks.explain)
        from ..checks import explain

        raise explain(cfg, seed, exc) from None
    _say(f"ready in {time.perf_counter() - t0:.1f} s")


# ---------------------------------------------------------------------------------------------- view
def _quiet(args) -> None:
    global QUIET
    QUIET = bool(getattr(args, "quiet", False))


def cmd_view(args) -> int:
    """Run ``infomarket view``: serve the live viewer in the browser until stopped; returns the exit code."""
    import asyncio

    _quiet(args)
    try:
        from .server import serve  # aiohttp, with the command only
    except ImportError as exc:  # aiohttp is a dependency; say so rather than show a traceback
        raise InfomarketError(f"the viewer needs the aiohttp package ({exc}); pip install aiohttp") from None
    cfg = _load(args.experiment)
    _warm_up(cfg, args.seed)  # a signal meanwhile stops it at once (cli.main's interrupts.handling)
    try:
        asyncio.run(serve(cfg, args.seed, port=args.port, keep_running=args.keep_running, say=_say,
                          announce=_announce))
    except KeyboardInterrupt:
        pass
    _say("viewer stopped")
    return 0


# -------------------------------------------------------------------------------------------- replay
class _Ticker:
    """A progress line at most every few seconds (long recordings, long movies)."""

    def __init__(self, label: str, every: float = 3.0):
        self.label, self.every, self.last = label, every, time.monotonic()

    def __call__(self, done: int, total: int) -> None:
        now = time.monotonic()
        if now - self.last >= self.every or done == total:
            _say(f"{self.label}: {done}/{total}")
            self.last = now


def _refuse_too_big(cfg, every: int | None) -> None:
    """A replay whose event log and frames would not fit in memory is refused before it runs."""
    # with the command, as cmd_replay's own imports: `infomarket --help` stays light
    from ..config import sizes
    from .frames import frame_size
    from .recording import default_every

    every = every or default_every(cfg.steps, cfg.swarm.robots)
    frames = cfg.steps // every + 2  # the first, one every ``every`` steps, and the last
    why = sizes.recording_too_big(cfg, frames, frame_size(cfg.swarm.robots, cfg.chain.enabled))
    if why:
        raise UsageError(f"--steps {cfg.steps} --every {every}: {why}")


def cmd_replay(args) -> int:
    """Run ``infomarket replay``: record a run and write it as a self-contained HTML page, a movie, or both.

    Raises:
        UsageError: neither ``--out`` nor ``--movie`` is given, or a file has an unsupported suffix.
    """
    from .recording import record, write_html  # with the command: `infomarket --help` stays light

    _quiet(args)
    if not args.out and not args.movie:
        raise UsageError("replay: say what to write: --out FILE.html, --movie FILE.mp4 (or .gif), or both")
    if args.out and Path(args.out).suffix.lower() not in HTML_SUFFIXES:
        movie = Path(args.out).suffix.lower() in (".mp4", ".gif", ".avi", ".mov", ".webm", ".mkv")
        raise UsageError(f"--out {args.out}: the HTML replay is written to a .html (or .htm) file"
                         + ("; for a movie use --movie" if movie else ""))
    out = writable_file(args.out) if args.out else None  # before simulating: fail fast
    if args.movie:
        from .movie import check_movie_path  # matplotlib and ffmpeg, for a movie only

        check_movie_path(args.movie)
        writable_file(args.movie, "--movie")
    cfg = _load(args.experiment, args.steps)
    steps = cfg.steps
    _refuse_too_big(cfg, args.every)
    rec = record(cfg, args.seed, steps=steps, every=args.every, on_progress=_Ticker("steps"))
    _say(f"recorded {steps} steps of {cfg.name} (seed {rec.scene['seed']}): {len(rec.frames)} frames, "
         f"one every {rec.every} steps")
    if out is not None:
        write_html(rec, out)
        _say(f"wrote {out} ({out.stat().st_size / 1e6:.1f} MB); open it in a browser")
    if args.movie:
        from .movie import write_movie  # matplotlib and ffmpeg, for a movie only

        path = write_movie(rec, args.movie, on_progress=_Ticker("movie frames"))
        _say(f"wrote {path} ({path.stat().st_size / 1e6:.1f} MB)")
    return 0


def add_subcommand(subparsers) -> None:
    """Add ``view`` and ``replay`` to the main parser's subcommands."""
    v = subparsers.add_parser(
        "view", help="watch an experiment run live in the browser (local web server)",
        description="Serve a page on 127.0.0.1 that draws the swarm as the engine steps it. "
                    "Each browser tab gets its own simulation. From another machine: "
                    "ssh -L 8765:127.0.0.1:8765 HOST, then open the printed URL.")
    v.add_argument("experiment", help="a .toml file, an original .json file, or a shipped name (e.g. fig2B)")
    v.add_argument("--seed", type=seed_value, help="seed of the first swarm (default: the file's)")
    v.add_argument("--port", type=_port, default=DEFAULT_PORT,
                   help=f"port on 127.0.0.1 (default {DEFAULT_PORT}; a free one if taken; 0 = any free one)")
    v.add_argument("--keep-running", action="store_true",
                   help="keep serving after the last page closes (default: stop a few seconds after)")
    v.add_argument("--quiet", action="store_true",
                   help="print only the address to open (on stdout) and errors")
    v.set_defaults(func=cmd_view)

    r = subparsers.add_parser(
        "replay", help="write a self-contained HTML replay and/or a movie (.mp4, .gif) of one run",
        description="Run an experiment once and write what the viewer would show: an HTML file that "
                    "opens from disk (no server), and/or a movie with a progress bar.")
    r.add_argument("experiment", help="a .toml file, an original .json file, or a shipped name (e.g. fig2B)")
    r.add_argument("--out", metavar="FILE.html", help="write the HTML replay here")
    r.add_argument("--movie", metavar="FILE.mp4|FILE.gif", help="write a movie here (.mp4 needs ffmpeg)")
    r.add_argument("--seed", type=seed_value, help="seed (default: the file's)")
    r.add_argument("--steps", type=at_least(1), help="steps to record (default: the file's)")
    r.add_argument("--every", type=at_least(1), metavar="K",
                   help="keep a frame every K steps (default: about 1500 frames in all)")
    r.add_argument("--quiet", action="store_true", help="print nothing but errors")
    r.set_defaults(func=cmd_replay)
