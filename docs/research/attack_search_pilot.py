"""Pilot for sizing the attack-search study's confirmation runs (docs/attack-search.md, "How the run
counts were sized"): a few attacks of the hand-written set and the truthful reference, 32 runs each, on
ONE seed stream of their own ("pilot", disjoint from the study's search, selection and confirmation
streams), in five cells; it writes the per-run items to a CSV and prints, per cell, each attack's sd and
the sd and correlation of its per-seed differences with the reference and with the strongest attack.

    python docs/research/attack_search_pilot.py /tmp/pilot      # about 800 runs of 30 000 steps
    python docs/research/attack_search_pilot.py --sizing docs/research/attack_search_pilot.csv   # the sizing alone

(``attack_search_pilot.csv`` beside this file is the pilot's per-run output, as made for the declared run
count.)

Then, from the per-run CSV, the confirmation run count each declared decision needs: the smallest count
(16 to 256, by 16) at which the signed-rank test, at alpha 0.05 / 24 (Holm's first step over the 24
cells), reaches power 0.8 when the pilot's per-seed differences, centred, are shifted to the effect
named (``analysis.paired_runs.runs_for_power``, 2 000 simulated studies each).  The numbers are no answer
of the study and its seeds never serve one.
"""
from __future__ import annotations

import hashlib
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from infomarket import load_experiment
from infomarket.analysis import paired_runs as pr
from infomarket.runner.plan import Condition, condition_number
from infomarket.runner.sweep import run_sweep
from infomarket.search import study
from infomarket.search.objective import per_run
from infomarket.seeds import run_seed
from infomarket.store import Store

CELLS = [("staking", 1), ("staking", 3), ("staking", 8), ("outlier", 3), ("weighted", 3)]
ATTACKS = ["truthful", "scaboteur_20", "theta_surfer", "colluder", "scaboteur_90"]
RUNS = 32
STREAM = int(hashlib.sha256(b"pilot").hexdigest()[:15], 16)


@dataclass(frozen=True)
class PilotCondition(Condition):
    def seed(self, run: int) -> int:  # every attack of a cell on the same seeds: paired by run
        return run_seed(self.master_seed, run, STREAM)


def main(out: Path) -> None:
    st = study.load(load_experiment("attack_search"))
    decl = study.load_declarations()["baselines"]
    conds = []
    for cell in study.cells(st, [d for d, _ in CELLS], sorted({b for _, b in CELLS})):
        if (cell.defence, cell.byzantines) not in CELLS:
            continue
        for a in ATTACKS:
            cid = f"attack={a}"
            cfg = cell.with_attack(decl[a]["params"])
            conds.append(PilotCondition(cell.experiment, cid, {"attack": a}, cfg, RUNS, cfg.seed,
                                        condition_number(cid)))
    store = Store(out / "store", cache=True)
    if not store.exists():
        store.create()
    run_sweep(conds, store, workers=1)
    per = per_run(store.robots())
    per["attack"] = per.condition.str.removeprefix("attack=")
    per[["experiment", "attack", "run", "items"]].to_csv(out / "pilot.csv", index=False)
    for exp, g in per.groupby("experiment"):
        w = g.pivot(index="run", columns="attack", values="items")
        worst = w.drop(columns="truthful").median().idxmin()
        print(f"{exp}: worst {worst}")
        for a in w.columns:
            d_ref, d_w = w[a] - w["truthful"], w[a] - w[worst]
            print(f"  {a:14s} median {w[a].median():6.2f} sd {w[a].std():5.2f} | vs truthful: sd(d) "
                  f"{d_ref.std():5.2f} r {np.corrcoef(w[a], w['truthful'])[0, 1]:+.2f} | vs worst: sd(d) "
                  f"{d_w.std():5.2f} r {np.corrcoef(w[a], w[worst])[0, 1]:+.2f}")
    sizing(out / "pilot.csv")


ALPHA = 0.05 / 24
GRID = range(16, 257, 16)
DECLARED = 128  # questions.toml [search] confirmation_runs: the power each decision has with it


def sizing(csv: Path) -> None:
    """Per pilot cell, the runs each decision needs (see the module's docstring)."""
    per = pd.read_csv(csv)
    print(f"\nconfirmation runs for power 0.8 at alpha {ALPHA:.5f}, one-sided signed-rank:")
    for exp, g in per.groupby("experiment"):
        w = g.pivot(index="run", columns="attack", values="items")
        order = w.drop(columns="truthful").median().sort_values().index
        worst, second = order[0], order[1]
        loss = 1.0 - w[worst] / w["truthful"]
        m = pr.noise(loss.to_numpy())
        # the worst case's loss 5 points beyond the 10 % margin, shown beyond; 5 points within, shown within
        beyond = pr.runs_for_power(m, 0.15, shift=-0.10, alpha=ALPHA, grid=GRID, sims=2000)
        within = pr.runs_for_power(m, 0.05, shift=-0.10, alternative="less", alpha=ALPHA, grid=GRID, sims=2000)
        # one strong attack beating another by 10 % (5 %) of its median items
        d = (w[worst] - w[second]).to_numpy()
        ten = pr.runs_for_power(pr.noise(d), -0.10 * w[second].median(), alternative="less", alpha=ALPHA,
                                grid=GRID, sims=2000)
        five = pr.runs_for_power(pr.noise(d), -0.05 * w[second].median(), alternative="less", alpha=ALPHA,
                                 grid=GRID, sims=2000)
        at = [pr.runs_for_power(m_, e, shift=sh, alternative=alt, alpha=ALPHA, grid=[DECLARED], sims=2000)[1]
              for m_, e, sh, alt in ((m, 0.15, -0.10, "greater"), (m, 0.05, -0.10, "less"),
                                     (pr.noise(d), -0.10 * w[second].median(), 0.0, "less"))]
        print(f"  {exp}: loss {pr.hodges_lehmann(loss.to_numpy()):.1%} sd {loss.std():.3f}: beyond 10 % at 15 %: "
              f"{beyond[0]} ({beyond[1]:.2f}), within at 5 %: {within[0]} ({within[1]:.2f}) | {worst} - {second} "
              f"sd {d.std(ddof=1):.2f}: 10 % of {w[second].median():.2f} items: {ten[0]} ({ten[1]:.2f}), "
              f"5 %: {five[0]} ({five[1]:.2f}); power with {DECLARED} runs: {at[0]:.2f}, {at[1]:.2f}, {at[2]:.2f}")


if __name__ == "__main__":
    if len(sys.argv) > 2 and sys.argv[1] == "--sizing":
        sizing(Path(sys.argv[2]))
    else:
        main(Path(sys.argv[1]))
