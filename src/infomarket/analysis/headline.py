"""The "paper vs this store" table: one row per headline number of docs/model.md §8.

Each row is a metric (a function here, computing one number from the tables) judged by a rule declared
in ``tolerances.toml`` (bounds and the reasoning behind them, written before any result was seen).
Keeping the numbers in the file and the arithmetic here means a rule can be reviewed without reading
code, and a test can check that every rule has a metric and every metric a rule.
"""
from __future__ import annotations

import inspect
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from . import metrics, stats
from .metrics import THETA_DEG
from .study import Declaration, packaged
from .completeness import affected, gaps
from .frames import Frames, MissingDataError, require
from ..errors import ConfigError

#: the rows (and the open questions, analysis.future) with their record of amendments
DECLARATION = packaged("tolerances.toml")
TOLERANCES = DECLARATION.path
PASS, FAIL, NO_DATA, INCONCLUSIVE = "pass", "fail", "no data", "inconclusive"
COLUMNS = ["id", "figure", "claim", "paper", "store", "value", "tolerance", "verdict", "note"]
INCOMPLETE = "incomplete design"  # a row whose experiment lacks conditions of its shipped plan


@dataclass(frozen=True)
class Rule:
    """Bounds on one number: ``min``/``max`` inclusive, ``above``/``below`` strict."""

    id: str
    figure: str
    claim: str
    paper: str
    min: float | None = None
    max: float | None = None
    above: float | None = None
    below: float | None = None
    params: dict = field(default_factory=dict, compare=False)  # other declared keys (e.g. alpha)

    def passes(self, value: float) -> bool:
        """Whether ``value`` meets every declared bound (a missing or NaN value never passes)."""
        if value is None or math.isnan(value):
            return False
        return ((self.min is None or value >= self.min) and (self.max is None or value <= self.max)
                and (self.above is None or value > self.above) and (self.below is None or value < self.below))

    def describe(self) -> str:
        """The bounds as shown in a report: ``[min, max]``, or each bound as ``>= x``, ``< y`` joined by 'and'."""
        if self.min is not None and self.max is not None:
            return f"[{self.min:g}, {self.max:g}]"
        parts = [f"{op} {v:g}" for op, v in ((">=", self.min), ("<=", self.max), (">", self.above),
                                             ("<", self.below)) if v is not None]
        return " and ".join(parts)


def load_rules(path: str | Path = TOLERANCES) -> dict[str, Rule]:
    """The rules of ``path`` by id, in file order."""
    data = (DECLARATION if Path(path) == TOLERANCES else Declaration.read(path)).data
    rules = {}
    for rid, spec in data["rows"].items():
        bounds = {k: float(spec[k]) for k in ("min", "max", "above", "below") if k in spec}
        if not bounds:
            raise ConfigError(f"{path}: rows.{rid} declares no bound")
        params = {k: v for k, v in spec.items() if k not in ("figure", "claim", "paper", *bounds)}
        rules[rid] = Rule(rid, spec["figure"], spec["claim"], spec["paper"], **bounds, params=params)
    return rules


@dataclass(frozen=True)
class Measurement:
    """A headline row's measured value, how the table shows it, and whether the store's runs can decide it."""
    value: float   # what the rule judges
    shown: str     # how the table shows it (with the numbers it was computed from)
    floor: float | None = None  # the smallest value the store's run counts allow (a p-value's minimum)
    undecided: bool = False     # the store's runs cannot decide the row (a failing row is "inconclusive")
    too_small: bool = False     # no run count of the store could reach the row's alpha


METRICS: dict[str, Callable[[Frames], Measurement]] = {}


def metric(rid: str):
    """Decorator: register the function as the measurement of the headline row ``rid`` (in ``METRICS``)."""
    def register(fn: Callable[[Frames], Measurement]):
        METRICS[rid] = fn
        return fn
    return register


def _g(x: float) -> str:
    return f"{x:.3g}"


def _median(f: Frames, name: str, column: str = "items_collected", honest: bool = True) -> float:
    return metrics.median(require(f.robots, name, (column, "honest")), column, honest)


# --------------------------------------------------------------------------------------- Fig. 2
@metric("fig2A_median")
def _fig2a(f: Frames) -> Measurement:
    m = _median(f, "fig2A")
    return Measurement(m, _g(m))


@metric("fig2B_halves")
def _fig2b_halves(f: Frames) -> Measurement:
    a, b = _median(f, "fig2A"), _median(f, "fig2B")
    r = b / a if a else math.nan
    return Measurement(r, f"{_g(b)} / {_g(a)} = {r:.2f}")


@metric("fig2B_saboteur_gains")
def _fig2b_saboteur(f: Frames) -> Measurement:
    s, h = _median(f, "fig2B", honest=False), _median(f, "fig2B")
    return Measurement(s - h, f"{_g(s)} - {_g(h)} = {_g(s - h)}")


@metric("fig2C_below_2A")
def _fig2c_below(f: Frames) -> Measurement:
    c, a = _median(f, "fig2C"), _median(f, "fig2A")
    return Measurement(c - a, f"{_g(c)} - {_g(a)} = {_g(c - a)}")


@metric("fig2C_wider")
def _fig2c_wider(f: Frames) -> Measurement:
    iqr = {n: metrics.iqr(require(f.robots, n, ("items_collected",)).query("honest")["items_collected"])
           for n in ("fig2A", "fig2C")}
    r = iqr["fig2C"] / iqr["fig2A"] if iqr["fig2A"] else math.inf
    return Measurement(r, f"{_g(iqr['fig2C'])} / {_g(iqr['fig2A'])} = {r:.2f}")


@metric("fig2D_vs_2B")
def _fig2d_vs_2b(f: Frames) -> Measurement:
    d, b = _median(f, "fig2D"), _median(f, "fig2B")
    r = d / b if b else math.inf
    return Measurement(r, f"{_g(d)} / {_g(b)} = {r:.2f}")


@metric("fig2D_vs_2C")
def _fig2d_vs_2c(f: Frames) -> Measurement:
    d, c = _median(f, "fig2D"), _median(f, "fig2C")
    return Measurement(d - c, f"{_g(d)} - {_g(c)} = {_g(d - c)}")


# ------------------------------------------------------------------------------------ Figs. 3-4
@metric("fig3A_scaboteur_share")
def _fig3a_scaboteur(f: Frames) -> Measurement:
    m = 100.0 * _median(f, "fig3A", "wealth_share", honest=False)
    return Measurement(m, f"{m:.2f}")


@metric("fig3A_honest_share")
def _fig3a_honest(f: Frames) -> Measurement:
    m = 100.0 * _median(f, "fig3A", "wealth_share", honest=True)
    return Measurement(m, f"{m:.2f}")


def _gap(f: Frames, name: str) -> float:
    return metrics.share_gap_pp(require(f.robots, name, ("wealth_share", "honest")))


@metric("fig3_gap_shrinks")
def _fig3_shrinks(f: Frames) -> Measurement:
    a, b, c = (_gap(f, f"fig3{p}") for p in "ABC")
    return Measurement(min(a - b, b - c), f"gaps A {a:.2f}, B {b:.2f}, C {c:.2f} pp")


def _mann_whitney(name: str) -> Callable[[Frames], Measurement]:
    """Run-level: each run's honest minus Byzantine mean wealth share (percentage points),
    one-sided Wilcoxon signed-rank test; the paper's robot-level Mann-Whitney, which pools robots over
    runs (pseudo-replicates), is shown beside it.  ``floor``: 1 / 2^runs, the smallest p the runs allow."""
    def measure(f: Frames) -> Measurement:
        rows = require(f.robots, name, ("wealth_share", "honest"))
        honest = rows["honest"].to_numpy(bool)
        if honest.all() or not honest.any():
            raise MissingDataError(f"{name}: needs both honest and Byzantine robots")
        means = rows.groupby(["run", "honest"])["wealth_share"].mean().unstack().dropna()
        run_level = stats.paired(100.0 * (means[True] - means[False]).to_numpy())
        mw = stats.mann_whitney(rows.loc[honest, "wealth_share"], rows.loc[~honest, "wealth_share"])
        return Measurement(run_level.p, f"run-level: {run_level.describe(' pp')}; robot-level (robots pooled "
                           f"over runs, as the paper): Mann-Whitney p = {mw.pvalue:.2g} (n = {mw.n_honest} vs "
                           f"{mw.n_byzantine})", floor=run_level.min_p)
    return measure


def _gap_larger(panel: str) -> Callable[[Frames], Measurement]:
    def measure(f: Frames) -> Measurement:
        g3, g4 = _gap(f, f"fig3{panel}"), _gap(f, f"fig4{panel}")
        return Measurement(g4 - g3, f"{g4:.2f} vs {g3:.2f} pp")
    return measure


for _p in "ABC":
    metric(f"fig3{_p}_mannwhitney")(_mann_whitney(f"fig3{_p}"))
    metric(f"fig4{_p}_mannwhitney")(_mann_whitney(f"fig4{_p}"))
    metric(f"fig4{_p}_gap_larger")(_gap_larger(_p))


# --------------------------------------------------------------------------------------- Fig. 5
@metric("fig5_scaboteurs_poor")
def _fig5_poor(f: Frames) -> Measurement:
    curves = metrics.wealth_curves(f.history, f.robots)["share"]
    if False not in curves:
        raise MissingDataError("fig5: no scaboteurs in the history")
    mean = curves[False].mean(axis=0)
    late = mean[mean.index >= mean.index.max() / 2]
    peak = 100.0 * float(late.max())
    return Measurement(peak, f"{peak:.2f} (at step {int(late.idxmax())})")


@metric("fig5_honest_grows")
def _fig5_grows(f: Frames) -> Measurement:
    mean = metrics.wealth_curves(f.history, f.robots)["wealth"][True].mean(axis=0)
    steps = mean.index.to_numpy()
    marks = [steps[np.abs(steps - q * steps.max()).argmin()] for q in (0.25, 0.5, 0.75, 1.0)]
    values = [float(mean[s]) for s in marks]
    return Measurement(float(np.diff(values).min()),
                       ", ".join(f"{v:.3g} at {int(s)}" for s, v in zip(marks, values)))


# --------------------------------------------------------------------------------------- Fig. 6
def _pearson(name: str) -> Callable[[Frames], Measurement]:
    def measure(f: Frames) -> Measurement:
        rows, when = metrics.drift_and_share(f.robots, f.history, name)
        if len(rows) < 3:
            raise MissingDataError(f"{name}: fewer than 3 honest robots")
        c = stats.pearson(rows["abs_drift"], rows["wealth_share"])
        return Measurement(c.r, f"r = {c.r:.2f}, 95 % CI [{c.low:.2f}, {c.high:.2f}], n = {c.n}, {when}")
    return measure


metric("fig6A_pearson")(_pearson("fig6A"))
metric("fig6B_pearson")(_pearson("fig6B"))


# --------------------------------------------------------------------------------------- Fig. 7
def _throughput_medians(f: Frames, byzantines: int) -> pd.DataFrame:
    runs = metrics.swarm_throughput(f.robots)
    panel = runs[runs["byzantines"] == byzantines]
    med = panel.groupby(["rotation_angle", "market"])["throughput"].median().unstack("market")
    if not {"staking", "no_staking"} <= set(med.columns):
        raise MissingDataError(f"fig7: {byzantines} Byzantine(s) needs both staking and no_staking runs")
    return med.dropna()


@metric("fig7B_staking_helps")
def _fig7b(f: Frames, rule: Rule) -> Measurement:
    """Fraction of angles above Theta where staking's per-run swarm throughput is significantly higher
    than no staking's (one-sided Mann-Whitney, Holm over those angles, alpha declared in the rule).  A
    row that fails while some non-significant angle had power < 0.8 to detect a gain of the declared
    margin (a fraction of the no-staking median) is undecided: "inconclusive"."""
    runs = metrics.swarm_throughput(f.robots)
    panel = runs[(runs["byzantines"] == 3) & (runs["rotation_angle"] > THETA_DEG)]
    _throughput_medians(f, 3)  # raises MissingDataError when a market is missing
    angles = sorted(panel["rotation_angle"].unique())
    if not angles:
        raise MissingDataError(f"fig7: no rotation angle above {THETA_DEG:g} deg with 3 Byzantines")
    alpha, fraction = rule.params.get("alpha", stats.ALPHA), rule.params.get("margin_fraction", 0.10)
    comps = []
    for a in angles:
        at = panel[panel["rotation_angle"] == a]
        x = at.loc[at["market"] == "staking", "throughput"].to_numpy(float)
        y = at.loc[at["market"] == "no_staking", "throughput"].to_numpy(float)
        if len(x) == 0 or len(y) == 0:
            continue
        comps.append(stats.compare(x, y, declared=fraction * float(np.median(y)), alpha=alpha,
                                   family=len(angles), label=f"{a:g} deg"))
    comps = stats.adjust(comps)
    wins = [c.significant for c in comps]
    weak = [c.label for c, w in zip(comps, wins) if not w and not c.power >= stats.POWER]
    shown = (f"{sum(wins)} of {len(comps)} angles significant (Holm, alpha {alpha:g}); "
             + (f"underpowered at {', '.join(weak)}; " if weak else "")
             + "; ".join(f"{c.label}: HL {c.effect.hl:+.3g} [{c.effect.hl_low:.3g}, {c.effect.hl_high:.3g}], "
                         f"p = {c.p:.2g}, Holm {c.p_adjusted:.2g}, power {c.power:.2f}" for c in comps))
    return Measurement(float(np.mean(wins)), shown, undecided=bool(weak), too_small=stats.too_few_runs(comps))


@metric("fig7A_no_difference")
def _fig7a(f: Frames) -> Measurement:
    med = _throughput_medians(f, 1)
    rel = 100.0 * (med["staking"] - med["no_staking"]).abs() / med["no_staking"]
    worst = rel.idxmax()
    return Measurement(float(rel.max()), f"{rel.max():.1f} % (at {worst:g} deg)")


# ---------------------------------------------------------------------------------------- table
def _undecided(m: Measurement, rule: Rule) -> bool:
    """The store's runs cannot decide the row: the metric says so, or the smallest value its run counts
    allow cannot satisfy the rule's strict upper bound (a p-value that can never be below it)."""
    return m.undecided or (m.floor is not None and rule.below is not None and m.floor >= rule.below)


def headline_table(source, rules: dict[str, Rule] | None = None) -> pd.DataFrame:
    """One row per rule: the paper's value, this store's value, the tolerance and the verdict
    (``pass``, ``fail``, ``inconclusive`` when the row fails but the store's run counts could not have
    decided it, or ``no data`` when the store lacks what the row needs).

    ``source`` is anything ``Frames.of`` reads: a Store, a store path, Frames or a dict of tables."""
    frames = Frames.of(source)
    rules = load_rules() if rules is None else rules
    incomplete = gaps(frames.runs)
    rows = []
    for rid, rule in rules.items():
        if rid not in METRICS:
            raise ConfigError(f"tolerance rows.{rid} has no metric in headline.py")
        try:
            fn = METRICS[rid]
            m = fn(frames, rule) if len(inspect.signature(fn).parameters) == 2 else fn(frames)
            store, value, verdict = m.shown, m.value, PASS if rule.passes(m.value) else FAIL
            note = ""
            if verdict == FAIL and _undecided(m, rule):
                verdict = INCONCLUSIVE
                if m.too_small or (m.floor is not None and rule.below is not None and m.floor >= rule.below):
                    note = stats.N_TOO_SMALL
            gone = affected(rule.figure, incomplete)
            if gone:  # part of the design is missing: the number describes what is there, not the claim
                verdict, note = INCONCLUSIVE, INCOMPLETE
                store = " ".join(incomplete[g].describe() for g in gone) + " -- " + store
        except MissingDataError as exc:
            store, value, verdict, note = str(exc), math.nan, NO_DATA, ""
        rows.append([rid, rule.figure, rule.claim, rule.paper, store, value, rule.describe(), verdict, note])
    return pd.DataFrame(rows, columns=COLUMNS)
