"""What a sweep into a growing store costs beyond its runs: a search's generations, one sweep each, into one
caching store (as the attack and defence searches sweep), with runs so short that the store's work is
what is measured.  Prints each generation's CPU milliseconds at a few points and the total.

    .venv/bin/python tools/store_growth.py --generations 400 --conditions 8 --runs 2 --steps 10
"""
from __future__ import annotations

import argparse
import tempfile
import time

import infomarket as im
from infomarket.runner.plan import Condition, condition_number
from infomarket.runner.sweep import run_sweep
from infomarket.store import Store


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--generations", type=int, default=400)
    ap.add_argument("--conditions", type=int, default=8, help="candidates a generation")
    ap.add_argument("--runs", type=int, default=2, help="runs a candidate")
    ap.add_argument("--steps", type=int, default=10)
    ap.add_argument("--experiment", default="fig4C")
    a = ap.parse_args()
    cfg = im.load_experiment(a.experiment).with_overrides(steps=a.steps, transitory=0)
    with tempfile.TemporaryDirectory() as folder:
        store = Store(f"{folder}/store", cache=True)
        start = time.process_time()
        for g in range(a.generations):
            conds = []
            for c in range(a.conditions):
                cid = f"gen={g},cand={c}"
                conds.append(Condition(cfg.name, cid, {"gen": g, "cand": c}, cfg, a.runs, cfg.seed,
                                       condition_number(cid)))
            t0 = time.process_time()
            run_sweep(conds, store)
            if g % max(1, a.generations // 8) == 0 or g == a.generations - 1:
                print(f"generation {g:5d}: {1000 * (time.process_time() - t0):7.1f} ms CPU, "
                      f"{len(store.committed())} parts", flush=True)
        print(f"total: {time.process_time() - start:.1f} s CPU")


if __name__ == "__main__":
    main()
