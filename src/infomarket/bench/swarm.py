"""Swarm size: robot-steps/s and peak memory from 25 robots up, at the paper's density.

Each size runs in a fresh process, so its peak resident memory (``ru_maxrss``) is its own: the arena
and both sites (centres and radii) are scaled by √(N/25), which keeps robots per unit area, and site
area per robot, as in the paper.  The behaviour is Fig. 2A's (naive robots, delayed payment).
"""
from __future__ import annotations

import json
import math
import resource
import subprocess
import sys

from ..config import load_experiment
from ..config.load import validate
from ..config.schema import Experiment
from ..errors import SimulationError


def scaled_config(robots: int, steps: int, base: str = "fig2A", chain: dict | None = None) -> Experiment:
    """``base`` with ``robots`` robots at the paper's density (every group scaled, the largest absorbs
    rounding), run for ``steps`` steps; with ``chain``, that ``[chain]`` section (``setups.chain_at``)."""
    cfg = load_experiment(base)
    k = math.sqrt(robots / cfg.swarm.robots)
    data = cfg.model_dump(exclude={"sweep"})
    data["steps"] = steps
    data["transitory"] = min(data["transitory"], steps - 1)
    data["arena"] = {"width": cfg.arena.width * k, "height": cfg.arena.height * k}
    for site in ("food", "nest"):
        s = getattr(cfg, site)
        data[site] = {"x": s.x * k, "y": s.y * k, "radius": s.radius * k}
    groups = data["swarm"]["groups"]
    counts = [round(g["count"] * robots / cfg.swarm.robots) for g in groups]
    counts[counts.index(max(counts))] += robots - sum(counts)
    for g, c in zip(groups, counts):
        g["count"] = c
    data["swarm"]["robots"] = robots
    if chain is not None:
        data["chain"] = chain
    return validate(data, f"{base} at {robots:,} robots")  # a ConfigError (too big for memory...), one message


def measure(robots: int, steps: int, seed: int = 1, chain: dict | None = None) -> dict:
    """Runs in this process, after the kernel is loaded: robot-steps/s (the median of 5 runs when a run
    is short, else one run) and the peak RSS of the process."""
    import statistics

    from ..engine.simulation import Simulation  # in the measuring interpreter only, after its memory baseline

    cfg = scaled_config(robots, steps, chain=chain)
    repeats = 5 if robots * steps < 5_000_000 else 1
    seconds, items = [], 0
    for k in range(repeats):
        sim = Simulation(cfg, seed + k)
        sim.run()
        seconds.append(sim.run_seconds)
        items = int(sim.world.items.sum())
    rss_kb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    med = statistics.median(seconds)
    return {"robot_steps_per_second": robots * steps / med, "seconds": med, "runs": repeats,
            "steps": steps, "peak_rss_mb": rss_kb / 1024.0, "items": items}


def run_swarm_sizes(sizes: list[int], steps: int, on_done=None, chain: bool = False) -> dict:
    """``measure`` for each size, each in a fresh interpreter (peak memory must not carry over); with
    ``chain``, every robot a blockchain node (``setups.chain_at``)."""
    from .setups import chain_at  # setups imports the engine: only when sizes are measured

    out = {}
    for n in sizes:
        extra = [json.dumps(chain_at(n))] if chain else []
        proc = subprocess.run([sys.executable, "-m", "infomarket.bench.swarm", str(n), str(steps), *extra],
                              capture_output=True, text=True)
        if proc.returncode != 0:
            raise SimulationError(f"bench of {n} robots failed:\n{proc.stderr.strip()[-2000:]}")
        out[n] = json.loads(proc.stdout.strip().splitlines()[-1])
        if on_done:
            on_done(n, out[n])
    return out


if __name__ == "__main__":
    print(json.dumps(measure(int(sys.argv[1]), int(sys.argv[2]),
                             chain=json.loads(sys.argv[3]) if len(sys.argv) > 3 else None)))
