"""How close to the floor the step could get if the market cost nothing: the paper's setups on this checkout's
kernel and on a copy of it whose step loop has no market (no offers, no purchases, no deposits), each
timed against the floor probe (``bench.floor``) interleaved run by run.

    .venv/bin/python tools/floor_ablation.py --rounds 11 --repeats 2

The copy is not a correct kernel (its robots never buy, so they navigate on odometry alone); it bounds what
any change to the market's code could gain.  Each figure is a setup's env-steps/s over the floor's, from the
least CPU time (``time.process_time``) over the rounds, the floor timed before each round's setups, so a
load change on the machine moves both.  The two trees are measured in turn, ``--repeats`` times each.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TEMPLATE = Path("src/infomarket/engine/loop_template.py")

#: The cut: from the sell pass to the start of the movement pass, and the deposit and table install in it.
SELL_PASS = "            for i in range(n):\n                if nbr_count[i] == 0 and not SELL_DRAWS"
MOVE_PASS = "            for i in range(n):\n                if forage(w, i, bits):"
MARKET_IN_MOVE_PASS = ("                if forage(w, i, bits):\n                    deposit(w, i, rng)\n"
                       "                if opened[i]:\n                    install_table(w, i)\n")
NO_MARKET_IN_MOVE_PASS = "                forage(w, i, bits)\n"


def without_market(source: str) -> str:
    """The step loop's source with its market passes cut out (fails loudly if the template moved on)."""
    if SELL_PASS not in source or MOVE_PASS not in source or MARKET_IN_MOVE_PASS not in source:
        raise SystemExit(f"{TEMPLATE} no longer has the passes this tool cuts; update its anchors")
    start, end = source.index(SELL_PASS), source.index(MOVE_PASS)
    return (source[:start] + source[end:]).replace(MARKET_IN_MOVE_PASS, NO_MARKET_IN_MOVE_PASS)


def measure(setups: list[str], rounds: int, steps: int) -> dict:
    """In this process: each setup's least CPU seconds a run and the floor's, interleaved."""
    from infomarket.bench.floor import floor_seconds
    from infomarket.config import load_experiment
    from infomarket.engine.simulation import Simulation
    from infomarket.seeds import run_seed

    cfgs = {name: load_experiment(name).with_overrides(steps=steps) for name in setups}
    floor_seconds(0, 1)  # compiles or loads the floor kernel
    for cfg in cfgs.values():  # compile or load every kernel before any clock runs
        Simulation(cfg, run_seed(cfg.seed, 0)).run()
    best = dict.fromkeys(setups, math.inf)
    best_floor = math.inf
    for r in range(rounds):
        best_floor = min(best_floor, floor_seconds(r + 1, steps, clock=time.process_time))
        for name, cfg in cfgs.items():
            sim = Simulation(cfg, run_seed(cfg.seed, r))
            start = time.process_time()
            sim.advance_to(cfg.steps)  # the steps alone, as the floor's
            best[name] = min(best[name], time.process_time() - start)
    return {"floor_steps_per_second": steps / best_floor,
            "setups": {n: {"steps_per_second": steps / s, "of_floor": best_floor / s} for n, s in best.items()}}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--setups", default="fig2A,fig4C")
    ap.add_argument("--rounds", type=int, default=11)
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--steps", type=int, default=15000)
    ap.add_argument("--measure", help=argparse.SUPPRESS)  # internal: measure in this process, print JSON
    a = ap.parse_args()
    setups = a.setups.split(",")
    if a.measure:
        print(json.dumps(measure(setups, a.rounds, a.steps)))
        return
    with tempfile.TemporaryDirectory() as tmp:
        cut = Path(tmp) / "no_market"
        shutil.copytree(ROOT / "src", cut / "src")
        (cut / TEMPLATE).write_text(without_market((ROOT / TEMPLATE).read_text()))
        trees = {"this checkout": ROOT / "src", "without the market": cut / "src"}
        # the copy's kernels hash other sources, so they never meet this checkout's in a shared cache;
        # its cache lives and dies with the copy
        caches = {"this checkout": {}, "without the market": {"INFOMARKET_CACHE_DIR": str(Path(tmp) / "cache")}}
        for k in range(a.repeats):
            for label, src in trees.items():
                env = {**os.environ, **caches[label], "PYTHONPATH": str(src)}
                out = subprocess.run([sys.executable, __file__, "--measure", "1", "--setups", a.setups,
                                      "--rounds", str(a.rounds), "--steps", str(a.steps)],
                                     env=env, check=True, capture_output=True, text=True)
                got = json.loads(out.stdout.strip().splitlines()[-1])
                ratios = ", ".join(f"{n} {v['of_floor']:.3f} ({v['steps_per_second'] / 1e3:.0f} k/s)"
                                   for n, v in got["setups"].items())
                print(f"{label:>20}: of the floor: {ratios}; floor {got['floor_steps_per_second'] / 1e3:.0f} k/s",
                      flush=True)


if __name__ == "__main__":
    main()
