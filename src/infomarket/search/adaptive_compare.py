"""The adaptive attacker against the hand-written attacks on one cell, as docs/rl.md declares the
comparison: the best hand-written attack is chosen on selection seeds, then it, the learned policy and the
truthful reference play the same fresh confirmation seeds, and the per-seed differences are tested.
Neither seed set is one that training or the driver plays (streams of their own)."""
from __future__ import annotations

import numpy as np
import pandas as pd

from ..analysis.stats import paired
from ..runner.execute import run_together
from ..seeds import run_seed
from .adaptive import Policy, _stream, confirm
from .objective import per_run
from .study import Cell

#: Runs stepped together per call for the hand-written attacks (``runner.execute.run_together``).
TOGETHER = 16


def seeds_of(cell: Cell, phase: str, runs: int) -> list[int]:
    """Run seeds of the comparison's ``phase`` ("selection" or "confirmation")."""
    stream = _stream("adaptive", f"docs-{phase}")
    return [run_seed(cell.config.seed, k, stream) for k in range(runs)]


def parametric_items(cell: Cell, params: dict, seeds, steps=None, transitory=None) -> np.ndarray:
    """Honest items per honest robot of ordinary runs of the cell with the attacker's ``params``."""
    cfg = cell.with_attack(params, steps=steps, transitory=transitory)
    outs = []
    for i in range(0, len(seeds), TOGETHER):
        outs += run_together(cfg, [(i + k, s) for k, s in enumerate(seeds[i:i + TOGETHER])])
    robots = pd.concat([o.robots.assign(experiment=cfg.name, condition="c") for o in outs], ignore_index=True)
    return per_run(robots).sort_values("run")["items"].to_numpy()


def compare(cell: Cell, policy: Policy, hand_written: dict[str, dict], truthful: dict, *, selection: int = 16,
            confirmation: int = 32, steps=None, transitory=None) -> dict:
    """The declared comparison's numbers; ``answer``: "yes" when the hand-written attack minus the learned
    policy is above 0 by a one-sided Wilcoxon signed-rank test at 0.05, "no" when below 0 by the same test,
    else "inconclusive"."""
    length = {"steps": steps, "transitory": transitory}
    sel = seeds_of(cell, "selection", selection)
    means = {n: float(parametric_items(cell, p, sel, **length).mean()) for n, p in hand_written.items()}
    best = min(means, key=means.get)  # ties: the first declared
    conf = seeds_of(cell, "confirmation", confirmation)
    learned = confirm(cell, policy, conf, **length)["items"].to_numpy()
    hand = parametric_items(cell, hand_written[best], conf, **length)
    truth = parametric_items(cell, truthful, conf, **length)
    d = hand - learned
    above, below = paired(d, alternative="greater"), paired(-d, alternative="greater")
    answer = "yes" if above.significant else "no" if below.significant else "inconclusive"
    return {"best_hand_written": best, "selection_means": means, "learned": learned.tolist(),
            "hand_written": hand.tolist(), "truthful": truth.tolist(), "learned_mean": float(learned.mean()),
            "hand_written_mean": float(hand.mean()), "truthful_mean": float(truth.mean()),
            "hl": above.hl, "hl_interval": [above.hl_low, above.hl_high], "p_above": above.p, "p_below": below.p,
            "positive_share": float((d > 0).mean()), "answer": answer}
