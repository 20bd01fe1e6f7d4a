"""The training example's comparison: the learned policy against the experiment's own attack (the
constant liar) on the same held-out seeds, answered as docs/rl.md declares."""
from __future__ import annotations

import numpy as np

from ..analysis.stats import ALPHA, INCONCLUSIVE, NO, YES, paired
from ..seeds import run_seed
from .train import Training, episodes

#: The held-out seeds' stream (condition index of ``seeds.run_seed``), apart from the training's draws.
HELD_OUT = 1


def held_out_seeds(seed: int, n: int) -> np.ndarray:
    """``n`` seeds for the final comparison: runs of a condition of their own (``HELD_OUT``) under ``seed``, apart
    from the episodes' seeds."""
    return np.array([run_seed(seed, i, HELD_OUT) for i in range(n)], np.int64)


def compare(env, trained: Training, runs: int, seed: int) -> dict:
    """Honest items per honest robot under the constant liar and under the learned policy, on ``runs``
    held-out seeds; ``beats_constant_liar``: yes when the within-seed difference (liar minus learned) is
    above 0 by a one-sided Wilcoxon signed-rank test at ALPHA, no when it is below 0 by the same test,
    else inconclusive."""
    seeds = held_out_seeds(seed, runs)
    _, liar = episodes(env, None, seeds, fixed=env.runs.default_action.astype(float))
    _, learned = episodes(env, np.repeat(trained.theta[None], runs, axis=0), seeds)
    d = liar - learned
    better, worse = paired(d, alternative="greater"), paired(-d, alternative="greater")
    answer = YES if better.significant else NO if worse.significant else INCONCLUSIVE
    return {"held_out_seeds": seeds.tolist(), "liar_items": liar.tolist(), "learned_items": learned.tolist(),
            "liar_mean": float(liar.mean()), "learned_mean": float(learned.mean()),
            "difference": better.describe(" items"), "hl_pseudo_median": better.hl,
            "hl_interval": [better.hl_low, better.hl_high], "p": better.p, "alpha": ALPHA,
            "beats_constant_liar": answer, "fitness": trained.fitness, "theta": trained.theta.tolist(),
            "actions": list(env.runs.actions), "policy_at_zero_observation": dict(zip(
                env.runs.actions, (env.runs.low + (env.runs.high - env.runs.low)
                                   / (1.0 + np.exp(-trained.theta[-1]))).tolist()))}


def describe(r: dict) -> str:
    """The training's result ``r`` in a few lines for the terminal: settings, held-out means and the verdict."""
    s = r["settings"]
    return "\n".join([
        f"{s['experiment']}: {s['iterations']} ES iterations x {2 * s['pairs']} runs of {s['steps']} steps "
        f"(K = {s['interval']}), {r['wall_seconds']:.0f} s",
        f"honest items per honest robot on {len(r['liar_items'])} held-out seeds: constant liar "
        f"{r['liar_mean']:.3f}, learned {r['learned_mean']:.3f}",
        f"liar minus learned: {r['difference']}",
        f"the learned attack beats the constant liar: {r['beats_constant_liar']}",
    ])
