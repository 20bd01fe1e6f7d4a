"""Exploratory (from the 2026-11-24 statistics review, not a declared rule): Fig. 7A's "no apparent advantage" as an equivalence test.

Per rotation angle, one Byzantine: per-run swarm throughput with staking vs without, TOST (two one-sided
Mann-Whitney tests) within +/- 10 % of the no-staking median, Holm over the angles.

    PYTHONPATH=src python docs/research/fig7a_equivalence.py STORE
"""
import sys

import numpy as np

from infomarket.analysis import metrics, stats
from infomarket.store import Store

runs = metrics.swarm_throughput(Store(sys.argv[1]).robots())
one = runs[runs.byzantines == 1]
angles = sorted(one.rotation_angle.unique())
rows = []
for a in angles:
    x = one[(one.rotation_angle == a) & (one.market == "staking")].throughput.to_numpy(float)
    y = one[(one.rotation_angle == a) & (one.market == "no_staking")].throughput.to_numpy(float)
    e = stats.effect(x, y)
    rows.append((a, len(x), np.median(x), np.median(y), 0.1 * np.median(y), stats.tost(x, y, 0.1 * np.median(y))[0], e))
for (a, n, mx, my, m, p, e), adj in zip(rows, stats.holm([r[5] for r in rows])):
    print(f"{a:g} deg: n = {n}, medians {mx:g} vs {my:g}, margin {m:.3g}, HL {e.hl:+.3g} [{e.hl_low:.3g}, "
          f"{e.hl_high:.3g}], TOST p = {p:.2g}, Holm {adj:.2g}: {'equivalent' if adj < 0.05 else 'not shown'}")
