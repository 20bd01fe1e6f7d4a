"""Synthetic results stores with known properties, written through the real ``Store`` writer.

``paper_like`` tables satisfy every headline claim by a wide margin (tight distributions, so no verdict
depends on chance); ``honest_not_richer`` gives honest and Byzantine robots the same wealth
distribution in Figs. 3-4, so those rows must fail.  Runs are few and tables small, to keep tests fast.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from infomarket.store import Store
from infomarket.store.dictionary import TABLES

ROBOTS = 25
RUNS = 6
RUNS_FIG34 = 12  # the run-level test of Figs. 3-4 needs >= 10 runs to reach p < 0.001 (1 / 2^runs)
RUNS_FIG7 = 8    # per condition: Holm over 6 angles needs p < 0.05 / 6; 8 vs 8 runs reach 1 / 12870


def _robots(name: str, groups: list[tuple[str, bool, int]], runs: int, rng, *, items, wealth,
            drift_sd: float = 0.05, condition: str = "base", keys: dict | None = None) -> pd.DataFrame:
    """One row per robot per run; ``items(honest, n)`` and ``wealth(honest, n, drift)`` draw the values
    (run by run, in that order; the table is made once: a frame per run cost most of the tests' time)."""
    behaviour = [b for b, _, c in groups for _ in range(c)]
    honest = np.array([h for _, h, c in groups for _ in range(c)])
    drifts, wealths, counts = [], [], []
    for _ in range(runs):
        drift = rng.normal(0.0, drift_sd, ROBOTS)
        drifts.append(drift)
        wealths.append(np.where(honest, wealth(True, ROBOTS, drift), wealth(False, ROBOTS, drift)))
        counts.append(np.where(honest, items(True, ROBOTS), items(False, ROBOTS)).astype(int))
    w = np.concatenate(wealths)
    df = pd.DataFrame({
        "experiment": name, "condition": condition, "run": np.repeat(np.arange(runs), ROBOTS),
        "seed": np.repeat(np.arange(1000, 1000 + runs, dtype=np.uint64), ROBOTS),
        "robot": np.tile(np.arange(ROBOTS), runs), "behaviour": behaviour * runs, "honest": np.tile(honest, runs),
        "drift": np.concatenate(drifts), "items_collected": np.concatenate(counts), "wealth": w,
        "wealth_share": np.concatenate([x / x.sum() for x in wealths]),
    })
    for k, v in (keys or {}).items():
        df[k] = v
    return df


def _runs(robots: pd.DataFrame, steps: int, transitory: int = 0, keys: tuple[str, ...] = ()) -> pd.DataFrame:
    runs = robots.groupby(["experiment", "condition", "run", *keys], as_index=False)["seed"].first()
    runs["config_hash"] = "cafe" + robots["experiment"].iloc[0]
    runs["package_version"] = "0.1.0"
    runs["duration_s"] = 0.1
    runs["steps"] = steps
    runs["transitory"] = transitory
    runs["status"] = "ok"
    return runs


def _const(v):
    return lambda honest, n, *_: np.full(n, float(v))


def _uniform_items(rng, lo_hi_honest, lo_hi_byz):
    return lambda honest, n: rng.integers(*(lo_hi_honest if honest else lo_hi_byz), n)


def _normal_wealth(rng, honest_mean, byz_mean, sd=0.3):
    return lambda honest, n, drift: rng.normal(honest_mean if honest else byz_mean, sd, n)


def _fig5_history(robots: pd.DataFrame, rng) -> pd.DataFrame:
    """Wealth every 100 steps over 10 000 steps: honest robots gain ~1 per 100 steps, scaboteurs ~0."""
    steps = np.arange(0, 10_001, 100)
    rows = robots.sort_values(["run", "robot"], kind="stable")
    rate = np.where(rows.honest, 0.01, 0.0001)
    factor = rng.uniform(0.8, 1.2, len(rows))  # one draw per robot, run by run (the order of the old loop)
    n = len(steps)
    return pd.DataFrame({"experiment": "fig5", "condition": "base", "run": np.repeat(rows.run.to_numpy(), n),
                         "seed": np.repeat(rows.seed.to_numpy().astype(np.int64), n), "step": np.tile(steps, len(rows)),
                         "robot": np.repeat(rows.robot.to_numpy(), n),
                         "wealth": (1.0 + rate[:, None] * steps * factor[:, None]).ravel(),
                         "honest": np.repeat(rows.honest.to_numpy(), n),
                         "behaviour": np.repeat(rows.behaviour.to_numpy(), n)})


def _fig6_wealth(rng, noise: float):
    """Wealth falling with |drift|, plus noise: r(|drift|, share) is negative, its size set by ``noise``."""
    return lambda honest, n, drift: (10.0 - 40.0 * np.abs(drift) + rng.normal(0, noise, n)) if honest \
        else rng.normal(1.0, 0.1, n)


def paper_like(honest_richer: bool = True, seed: int = 0) -> dict[str, tuple]:
    """Every experiment's (robots, runs, history) as the paper describes them."""
    rng = np.random.default_rng(seed)
    naive = [("naive", True, 25)]
    sceptical = [("sceptical", True, 25)]
    out = {
        "fig2A": _robots("fig2A", naive, RUNS, rng, items=_uniform_items(rng, (19, 22), (0, 1)),
                         wealth=_const(10)),
        "fig2B": _robots("fig2B", [("naive", True, 24), ("saboteur", False, 1)], RUNS, rng,
                         items=_uniform_items(rng, (8, 11), (13, 15)), wealth=_const(10)),
        "fig2C": _robots("fig2C", sceptical, RUNS, rng, items=_uniform_items(rng, (12, 21), (0, 1)),
                         wealth=_const(10)),
        "fig2D": _robots("fig2D", [("sceptical", True, 24), ("scaboteur", False, 1)], RUNS, rng,
                         items=_uniform_items(rng, (14, 19), (14, 19)), wealth=_const(10)),
    }
    # Figs. 3-4: honest wealth 10, Byzantine 7 / 8 / 9 (gap shrinks A -> C), 1 with staking.
    for number, factors in ((3, (0.7, 0.8, 0.9)), (4, (0.1, 0.1, 0.1))):
        for panel, byz, f in zip("ABC", (1, 3, 5), factors):
            byz_mean = 10 * f if honest_richer else 10
            out[f"fig{number}{panel}"] = _robots(
                f"fig{number}{panel}", [("sceptical", True, ROBOTS - byz), ("scaboteur", False, byz)], RUNS_FIG34,
                rng, items=_uniform_items(rng, (14, 19), (14, 19)), wealth=_normal_wealth(rng, 10, byz_mean))
    out["fig5"] = _robots("fig5", [("sceptical", True, 20), ("scaboteur", False, 5)], 4, rng,
                          items=_uniform_items(rng, (14, 19), (14, 19)), wealth=_const(1))
    # noise chosen so r is near the paper's -0.54 (A) and -0.64 (B) for this drift spread
    out["fig6A"] = _robots("fig6A", sceptical, RUNS, rng, items=_uniform_items(rng, (14, 19), (0, 1)),
                           wealth=_fig6_wealth(rng, 1.6))
    out["fig6B"] = _robots("fig6B", [("sceptical", True, 20), ("scaboteur", False, 5)], RUNS, rng,
                           items=_uniform_items(rng, (14, 19), (14, 19)), wealth=_fig6_wealth(rng, 1.2))
    tables = {name: (df, _runs(df, 15000), None) for name, df in out.items()}
    tables["fig5"] = (out["fig5"], _runs(out["fig5"], 10_000), _fig5_history(out["fig5"], rng))
    # Fig. 7: with 3 Byzantines staking keeps ~12 items per robot above Theta, no staking ~9;
    # with 1 Byzantine both markets give ~12.
    for byz in (1, 3):
        for market in ("staking", "no_staking"):
            for angle in range(0, 100, 10):
                low = market == "no_staking" and byz == 3 and angle > 30
                cond = f"byzantines={byz},market={market},rotation_angle={angle}"
                keys = {"byzantines": byz, "market": market, "rotation_angle": float(angle)}
                df = _robots("fig7", [("sceptical", True, ROBOTS - byz), ("scaboteur", False, byz)], RUNS_FIG7, rng,
                             items=_uniform_items(rng, (8, 10) if low else (12, 13), (8, 10) if low else (12, 13)),
                             wealth=_const(5), condition=cond, keys=keys)
                tables[f"fig7-{byz}-{market}-{angle}"] = (df, _runs(df, 30000, 20000, tuple(keys)), None)
    return tables


def write_store(root: Path, tables: dict[str, tuple], only: tuple[str, ...] | None = None) -> Store:
    """Write ``tables`` (part id -> (robots, runs, history)) as a store; ``only`` keeps part ids with
    one of these prefixes."""
    store = Store(root).create()
    for pid, (robots, runs, history) in tables.items():
        if only is None or pid.startswith(only):
            keys = [k for k in robots.columns if TABLES["robots"].column(k) is None]  # its condition keys
            store.write_part(pid, robots, runs, history, keys=keys)
    return store
