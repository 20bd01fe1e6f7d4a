"""How long `infomarket run` takes to stop after Ctrl-C, at random moments, on a busy machine.

Each trial starts `infomarket run` (default: fig2B, 200 runs, one worker per core; through the console
script's entry, `python -m infomarket_entry`, so a stop during its imports counts too) in a session of its
own with a fresh, empty kernel cache (INFOMARKET_CACHE_DIR; --warm: one cache shared by the trials),
sends SIGINT to its process group (as a terminal's Ctrl-C does) at a random moment between --earliest
and --latest seconds after the start, and measures the time until the command has exited; then it
lists any process left in the command's session (pool workers, compile children) and kills them.
Meanwhile --busy processes spin, so the cores are taken as on a loaded machine; they are always killed.

It reports each stop and a summary; it asserts nothing about time.  Run from the repository root:

    python tools/sigint_proof.py                 # 20 trials, cold cache, two busy loops
    python tools/sigint_proof.py --warm --signal TERM
"""
from __future__ import annotations

import argparse
import contextlib
import os
import random
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SRC = str(Path(__file__).resolve().parents[1] / "src")


def session_members(sid: int) -> list[int]:
    """Live (not zombie) processes whose session is ``sid``."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            fields = stat[stat.rindex(")") + 2:].split()
            if int(fields[3]) == sid and fields[0] != "Z":
                found.append(int(entry.name))
    return found


def kill_session(sid: int) -> None:
    for pid in {sid, *session_members(sid)}:
        for kill in (os.killpg, os.kill):
            with contextlib.suppress(ProcessLookupError, PermissionError):
                kill(pid, signal.SIGKILL)


def _as_from_a_terminal() -> None:  # in the child: Ctrl-C not ignored, even if this script's was (nohup, &)
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def start(argv, env, **kw) -> subprocess.Popen:
    return subprocess.Popen(argv, env=env, start_new_session=True, preexec_fn=_as_from_a_terminal, **kw)


def _stop(signum, frame):  # SIGTERM to this script: leave through its finally (the busy loops are killed)
    raise SystemExit(1)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--trials", type=int, default=20)
    p.add_argument("--earliest", type=float, default=0.2)
    p.add_argument("--latest", type=float, default=20.0)
    p.add_argument("--busy", type=int, default=2, help="busy loops to run meanwhile (default 2)")
    p.add_argument("--seed", type=int, default=None, help="seed of the random moments (default: random)")
    p.add_argument("--signal", choices=["INT", "TERM"], default="INT")
    p.add_argument("--warm", action="store_true", help="one kernel cache for all trials (else each a fresh one)")
    p.add_argument("words", nargs="*", default=["run", "fig2B", "--runs", "200"],
                   help="the infomarket command (default: run fig2B --runs 200); --out is added")
    args = p.parse_args()
    signal.signal(signal.SIGTERM, _stop)
    seed = args.seed if args.seed is not None else random.randrange(2**32)
    rng = random.Random(seed)
    sig = getattr(signal, f"SIG{args.signal}")
    work = Path(tempfile.mkdtemp(prefix="sigint-proof-"))
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in (SRC, os.environ.get("PYTHONPATH", "")) if p)}
    busy = [start([sys.executable, "-c", "while True: pass"], env) for _ in range(args.busy)]
    rows = []
    proc = None
    try:
        print(f"{args.trials} trials of `infomarket {' '.join(args.words)}`, SIG{args.signal} at "
              f"{args.earliest}-{args.latest} s (seed {seed}), {args.busy} busy loop(s), "
              f"{'shared warm' if args.warm else 'fresh cold'} kernel cache; load {os.getloadavg()[0]:.1f}",
              flush=True)
        if args.warm:  # fill the shared cache first: the trials then load the kernel and run
            subprocess.run([sys.executable, "-m", "infomarket_entry", *args.words, "--runs", "1", "--steps", "10",
                            "--quiet", "--out", str(work / "warm")], env={**env, "INFOMARKET_CACHE_DIR": str(work / "cache")},
                           check=True)
        for k in range(args.trials):
            cache = work / ("cache" if args.warm else f"cache{k}")
            out = work / f"out{k}"
            err = open(work / f"err{k}.txt", "w+")
            delay = rng.uniform(args.earliest, args.latest)
            cmd = [sys.executable, "-m", "infomarket_entry", *args.words, "--out", str(out)]
            t_start = time.monotonic()
            proc = start(cmd, {**env, "INFOMARKET_CACHE_DIR": str(cache)}, stdout=subprocess.DEVNULL, stderr=err)
            while time.monotonic() - t_start < delay and proc.poll() is None:
                time.sleep(0.01)
            if proc.poll() is not None:
                rows.append((k, delay, None, proc.returncode, "", []))
                print(f"{k:3d}  at {delay:5.2f} s: finished before the signal (exit {proc.returncode})", flush=True)
                continue
            with contextlib.suppress(ProcessLookupError):
                os.killpg(proc.pid, sig)
            t0 = time.monotonic()
            proc.wait()
            stop = time.monotonic() - t0
            left = session_members(proc.pid)
            kill_session(proc.pid)
            err.seek(0)
            text = err.read()
            lines = [ln for ln in text.splitlines() if ln.strip()]
            last = lines[-1] if lines else ""
            rows.append((k, delay, stop, proc.returncode, text, left))
            print(f"{k:3d}  at {delay:5.2f} s: stopped in {stop:6.3f} s, exit {proc.returncode}, "
                  f"{len(left)} process(es) left; {last[:110]}", flush=True)
    finally:
        if proc is not None:
            kill_session(proc.pid)
        for b in busy:
            kill_session(b.pid)
            b.wait()
    stops = [r[2] for r in rows if r[2] is not None]
    if stops:
        print(f"\nstops: {len(stops)}; within 2 s: {sum(s <= 2 for s in stops)}; median {statistics.median(stops):.3f} s, "
              f"max {max(stops):.3f} s; exit codes {sorted({r[3] for r in rows})}; "
              f"processes left behind: {sum(len(r[5]) for r in rows)}; tracebacks: "
              f"{sum('Traceback' in r[4] for r in rows)}")
    print(f"files: {work}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
