"""Global sensitivity indices of a sampled design (``[sweep.sample]``), computed by SALib, for a noisy simulator.

``run_outputs`` turns the robots table into one value per run and output; ``point_outputs`` averages
the runs of each design point and puts the points in the design's order (what SALib's estimators need);
``analyse`` calls SALib: Sobol' first-order and total (and second-order) indices with bootstrap 95 %
intervals, Morris μ* (with its interval), μ and σ, or RBD-FAST first-order indices for a Latin
hypercube.  A simulation is noisy: the runs of one point differ by their seeds.  So, from a design whose
points ran more than once (``runs = R``), ``noise_floor`` estimates the share of the variance that is
seed noise (with a bootstrap interval over the design's base samples): every total index contains it.
``pawn`` gives PAWN indices (SALib; distribution-based, for heavy-tailed outputs) beside Sobol'.
``local_robustness`` answers "is a point robust" from a local design around it (Morris trajectories in
a small box): the spread the parameters cause there, corrected for seed noise, against a tolerance.
Every function takes plain DataFrames and a ``Design``; ``from_store`` reads both from a results store.
The declared questions, the figures, the markdown and the files: ``analysis.sensitivity_report``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..config.sample import BUILTIN_OUTPUTS
from ..runner import design as designs
from ..runner.design import Design
from ..store import Store, StoreError
from .frames import MissingDataError
from .stats import answer

RUN = ["condition", "run"]
CONF_LEVEL = 0.95
RESAMPLES = 1000
PAWN_PERMUTATIONS = 40   # shuffles of the output for PAWN's no-effect level (SALib call: 0.2 s for 2 560 points)
PAWN_SLICES = 10
COLUMNS = ["experiment", "output", "method", "index", "parameter", "parameter2", "value", "conf", "low", "high"]
TITLES = {"S1": "first order S1", "ST": "total ST", "S2": "second order S2", "mu_star": "Morris μ*",
          "mu": "Morris μ", "sigma": "Morris σ", "PAWN": "PAWN (median KS)",
          "PAWN_null": "PAWN without effect (95th pct.)"}


@dataclass
class Sensitivity:
    """The indices of one design: ``table`` (long: one row per output, index and parameter)."""

    design: Design
    table: pd.DataFrame
    points: pd.DataFrame                       # the per-point outputs the indices were computed from
    runs: pd.DataFrame | None = None           # one row per run (``run_outputs``)
    floor: pd.DataFrame | None = None          # ``noise_floor``: seed noise's share of the variance
    files: list[Path] = field(default_factory=list)

    @property
    def runs_per_point(self) -> tuple[int, int]:
        """(fewest, most) runs at one point of the design."""
        if self.runs is None or self.runs.empty:
            return (1, 1)
        n = self.runs.groupby("point").size()
        return int(n.min()), int(n.max())

    def size(self) -> str:
        """The design's size, e.g. ``2 560 points x 2 runs = 5 120 runs``."""
        lo, hi = self.runs_per_point
        total = len(self.runs) if self.runs is not None else self.design.points
        each = f"{lo} run{'s' if lo > 1 else ''}" if lo == hi else f"{lo}-{hi} runs"
        return f"{self.design.points:,} points x {each} = {total:,} runs".replace(",", " ")


def _rows(robots: pd.DataFrame, who: str) -> pd.DataFrame:
    if who == "all":
        return robots
    return robots[robots["honest"] == (who == "honest")]


def run_outputs(robots: pd.DataFrame, design: Design) -> pd.DataFrame:
    """One row per run of the design: ``point``, ``condition``, ``run`` and one column per output."""
    rows = robots
    if "experiment" in rows.columns:
        rows = rows[rows["experiment"] == design.experiment]
    need = {"point", "condition", "run", "honest", "items_collected", "wealth_share"}
    missing = sorted(need - set(rows.columns))
    if rows.empty or missing:
        raise MissingDataError(f"{design.experiment}: no runs of the design in the tables"
                               + (f" (missing columns {', '.join(missing)})" if missing and not rows.empty else ""))
    g = rows.groupby(RUN, observed=True)
    out = g["point"].first().astype(np.int64).to_frame()
    for name in design.outputs:
        if name == "items":
            out[name] = g["items_collected"].sum().astype(float)
        elif name in ("share_gap", "byzantine_share"):
            honest = rows[rows["honest"]].groupby(RUN, observed=True)["wealth_share"]
            byz = rows[~rows["honest"]].groupby(RUN, observed=True)["wealth_share"]
            if name == "share_gap":
                out[name] = 100.0 * (honest.mean() - byz.mean())
            else:
                out[name] = 100.0 * byz.sum()
                out[name] = out[name].fillna(0.0)
        else:
            spec = design.custom[name]
            if spec["column"] not in rows.columns:
                raise MissingDataError(f"output {name}: the robots table has no column {spec['column']!r}; "
                                       f"it has {', '.join(rows.columns)}")
            values = pd.to_numeric(_rows(rows, spec["robots"])[spec["column"]], errors="coerce")
            out[name] = values.groupby([rows["condition"], rows["run"]], observed=True).agg(spec["stat"])
    return out.reset_index()


def point_outputs(runs: pd.DataFrame, design: Design) -> pd.DataFrame:
    """The mean over runs of every output at each point, indexed 0 .. points - 1 in the design's order;
    refuses a design with points not yet run (resume the sweep) or outputs that are undefined."""
    per_point = runs.groupby("point")[design.outputs].mean()
    missing = sorted(set(range(design.points)) - set(per_point.index))
    if missing:
        raise MissingDataError(f"{design.experiment}: {len(missing)} of the design's {design.points} points "
                               f"have no completed run (the first: point {missing[0]}); resume the sweep "
                               f"(`infomarket sweep` with the same --out) before analysing")
    per_point = per_point.reindex(range(design.points))
    bad = [o for o in design.outputs if per_point[o].isna().any()]
    if bad:
        first = int(per_point.index[per_point[bad[0]].isna()][0])
        raise MissingDataError(f"{design.experiment}: output {bad[0]} is undefined at point {first} (e.g. "
                               f"no robot of the kind it averages); the indices need a value at every point")
    return per_point


def _long(design: Design, output: str, index: str, values, conf=None) -> list[dict]:
    z = []
    for j, p in enumerate(design.names):
        v = float(values[j])
        c = float(conf[j]) if conf is not None else np.nan
        z.append({"experiment": design.experiment, "output": output, "method": design.method, "index": index,
                  "parameter": p, "parameter2": "", "value": v, "conf": c, "low": v - c, "high": v + c})
    return z


def analyse(design: Design, points: pd.DataFrame, *, seed: int | None = None) -> pd.DataFrame:
    """SALib's indices of every output of ``points`` (from ``point_outputs``), as one long table.

    ``conf`` is the half-width of the 95 % bootstrap interval (``low``/``high`` its ends); ``seed``
    (default: the design's) makes the bootstrap repeatable."""
    import warnings

    from SALib.analyze import morris, rbd_fast, sobol

    seed = design.seed if seed is None else seed
    problem = design.problem()
    rows: list[dict] = []
    for output in design.outputs:
        Y = points[output].to_numpy(dtype=float)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            if design.method == "sobol":
                S = sobol.analyze(problem, Y, calc_second_order=design.second_order, num_resamples=RESAMPLES,
                                  conf_level=CONF_LEVEL, seed=seed)
                rows += _long(design, output, "S1", S["S1"], S["S1_conf"])
                rows += _long(design, output, "ST", S["ST"], S["ST_conf"])
                if design.second_order:
                    d = len(design.names)
                    for a in range(d):
                        for b in range(a + 1, d):
                            v, c = float(S["S2"][a, b]), float(S["S2_conf"][a, b])
                            rows.append({"experiment": design.experiment, "output": output, "method": "sobol",
                                         "index": "S2", "parameter": design.names[a],
                                         "parameter2": design.names[b], "value": v, "conf": c,
                                         "low": v - c, "high": v + c})
            elif design.method == "morris":
                S = morris.analyze(problem, design.X, Y, num_resamples=RESAMPLES, conf_level=CONF_LEVEL,
                                   num_levels=design.levels, seed=seed)
                rows += _long(design, output, "mu_star", S["mu_star"], S["mu_star_conf"])
                rows += _long(design, output, "mu", S["mu"])
                rows += _long(design, output, "sigma", S["sigma"])
            else:
                S = rbd_fast.analyze(problem, design.X, Y, num_resamples=RESAMPLES, conf_level=CONF_LEVEL,
                                     seed=seed)
                rows += _long(design, output, "S1", S["S1"], S["S1_conf"])
    return pd.DataFrame(rows, columns=COLUMNS)


# ------------------------------------------------------------------------------------ seed noise
def blocks(design: Design) -> np.ndarray:
    """The independent unit of each point, for resampling: Saltelli's base sample (A_j, AB_1j .. AB_Dj,
    B_j and, second order, BA_1j .. BA_Dj are drawn together), Morris's trajectory, a hypercube's point."""
    d = len(design.names)
    size = {"sobol": (2 * d + 2) if design.second_order else (d + 2), "morris": d + 1}.get(design.method, 1)
    return np.arange(design.points) // size


def _replicates(runs: pd.DataFrame, design: Design, output: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per point, as [blocks, points per block]: the mean of its runs, their variance (ddof 1) and count."""
    g = runs.groupby("point")[output]
    idx = range(design.points)
    m = g.mean().reindex(idx).to_numpy(float)
    v = g.var(ddof=1).reindex(idx).to_numpy(float)
    n = g.size().reindex(idx).to_numpy(float)
    b = blocks(design)
    shape = (b.max() + 1, design.points // (b.max() + 1))
    return m.reshape(shape), v.reshape(shape), n.reshape(shape)


def _floor_stats(m: np.ndarray, v: np.ndarray, n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(floor, run share) over the last two axes: the seed noise's share of the variance of the point
    means, (mean of v / n) / var(means), and of the variance of single runs, mean(v) / (var(means) -
    mean(v / n) + mean(v)) (one-way random-effects decomposition: var(means) = between + noise / R)."""
    k = m.shape[-1] * m.shape[-2]
    vm = m.reshape(*m.shape[:-2], k).var(axis=-1, ddof=1)
    e = (v / n).reshape(*m.shape[:-2], k).mean(axis=-1)
    w = v.reshape(*m.shape[:-2], k).mean(axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return e / vm, w / (np.maximum(vm - e, 0.0) + w)


def noise_floor(runs: pd.DataFrame, design: Design, *, seed: int | None = None) -> pd.DataFrame:
    """Seed noise's share of each output's variance, from the replicates of every point, with 95 %
    percentile bootstrap intervals (``scipy.stats.bootstrap``, base samples resampled: the unit Saltelli's
    scheme draws independently).  ``floor``: share of the variance of the point means (the floor every
    total index of the point means sits on: Jansen's estimator gives (V_Ti + noise / R) / V);
    ``run_share``: share of the variance of single runs.  Empty when a point ran once (no replicates)."""
    from scipy import stats as sps

    cols = ["output", "runs_per_point", "floor", "floor_low", "floor_high", "run_share", "run_share_low",
            "run_share_high"]
    per = runs.groupby("point").size()
    if per.min() < 2:
        return pd.DataFrame(columns=cols)
    seed = design.seed if seed is None else seed
    rows = []
    for output in design.outputs:
        m, v, n = _replicates(runs, design, output)
        floor, share = (float(x) for x in _floor_stats(m, v, n))
        ci = []
        for k in (0, 1):
            def stat(i, axis=-1, k=k):
                i = np.asarray(i, dtype=np.int64)
                return _floor_stats(m[i], v[i], n[i])[k]  # noqa: B023 - called within this iteration
            res = sps.bootstrap((np.arange(m.shape[0]),), stat, vectorized=True, n_resamples=RESAMPLES,
                                batch=100, confidence_level=CONF_LEVEL, method="percentile",
                                rng=np.random.default_rng(seed))
            ci.append((float(res.confidence_interval.low), float(res.confidence_interval.high)))
        rows.append({"output": output, "runs_per_point": int(per.min()), "floor": floor, "floor_low": ci[0][0],
                     "floor_high": ci[0][1], "run_share": share, "run_share_low": ci[1][0],
                     "run_share_high": ci[1][1]})
    return pd.DataFrame(rows, columns=cols)


def _floor_rows(design: Design, floor: pd.DataFrame) -> list[dict]:
    return [{"experiment": design.experiment, "output": r.output, "method": "replicates", "index": kind,
             "parameter": "", "parameter2": "", "value": v, "conf": (hi - lo) / 2, "low": lo, "high": hi}
            for r in floor.itertuples()
            for kind, v, lo, hi in (("floor", r.floor, r.floor_low, r.floor_high),
                                    ("run_share", r.run_share, r.run_share_low, r.run_share_high))]


# ------------------------------------------------------------------------------------------ PAWN
def pawn(design: Design, points: pd.DataFrame, *, seed: int | None = None,
         permutations: int | None = None) -> pd.DataFrame:
    """PAWN indices (SALib's ``pawn.analyze``: the median over 10 slices of each parameter of the
    Kolmogorov-Smirnov distance between the conditional and the unconditional output distribution) of
    every output, and ``PAWN_null``: the 95th percentile of the same index over ``permutations`` seeded
    shuffles of the output (a permutation test: the level a parameter without effect reaches at this
    sample size; a KS distance is never 0 on a finite sample).  Distribution-based, so a heavy tail does
    not dominate it as it dominates variance.  (No bootstrap interval: resampling with replacement
    duplicates points, which biases a KS distance upwards.)"""
    import warnings

    from SALib.analyze import pawn as salib_pawn

    seed = design.seed if seed is None else seed
    permutations = PAWN_PERMUTATIONS if permutations is None else permutations
    problem, X = design.problem(), design.X
    rows = []
    for output in design.outputs:
        Y = points[output].to_numpy(dtype=float)

        def index(y):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                return np.asarray(salib_pawn.analyze(problem, X, y, S=PAWN_SLICES, seed=seed)["median"], float)

        value = index(Y)
        rng = np.random.default_rng(seed)
        null = np.percentile([index(rng.permutation(Y)) for _ in range(permutations)], 95, axis=0)
        for j, p in enumerate(design.names):
            for kind, v in (("PAWN", value[j]), ("PAWN_null", null[j])):
                rows.append({"experiment": design.experiment, "output": output, "method": "pawn", "index": kind,
                             "parameter": p, "parameter2": "", "value": float(v), "conf": np.nan, "low": np.nan,
                             "high": np.nan})
    return pd.DataFrame(rows, columns=COLUMNS)


def sensitivity(robots: pd.DataFrame, design: Design, *, seed: int | None = None,
                distribution: bool = True) -> Sensitivity:
    """The indices from a robots table (a store's, or a notebook's DataFrame) and its design: SALib's,
    the seed-noise floor (when points ran more than once) and, for a Sobol' or hypercube design with
    ``distribution``, PAWN indices."""
    runs = run_outputs(robots, design)
    points = point_outputs(runs, design)
    floor = noise_floor(runs, design, seed=seed)
    parts = [analyse(design, points, seed=seed)]
    if len(floor):
        parts.append(pd.DataFrame(_floor_rows(design, floor), columns=COLUMNS))
    if distribution and design.method in ("sobol", "lhs"):
        parts.append(pawn(design, points, seed=seed))
    table = pd.concat(parts, ignore_index=True) if len(parts) > 1 else parts[0]
    return Sensitivity(design, table, points, runs, floor)


def from_store(store, experiment: str | None = None) -> Sensitivity:
    """The indices of the design kept in ``store`` (the only one, or ``experiment``'s)."""

    store = Store(store) if not isinstance(store, Store) else store
    if not store.exists():
        raise StoreError(f"{store.root}: not an infomarket results store (no store.json)")
    names = designs.designs(store.root)
    if not names:
        raise MissingDataError(f"{store.root}: holds no sampled design (sweep an experiment with a "
                               f"[sweep.sample] section into it)")
    if experiment is None:
        if len(names) > 1:
            raise StoreError(f"{store.root}: holds designs of {', '.join(names)}; name one with --experiment")
        experiment = names[0]
    elif experiment not in names:
        raise StoreError(f"{store.root}: holds no design of {experiment!r}; it holds {', '.join(names)}")
    return sensitivity(store.robots(), designs.load(store.root, experiment))


# ------------------------------------------------------------------------------------ robustness
DRIVES = 0.1  # a parameter drives an output when its total index above the noise floor is at least this


def floor_of(s: Sensitivity, output: str) -> tuple[float, float, float]:
    """(floor, low, high) of ``output``; NaN when the design's points ran once."""
    if s.floor is None or s.floor.empty or output not in set(s.floor.output):
        return (np.nan, np.nan, np.nan)
    r = s.floor.set_index("output").loc[output]
    return float(r.floor), float(r.floor_low), float(r.floor_high)


def drivers(s: Sensitivity, threshold: float = DRIVES) -> dict[str, list[str]]:
    """The parameters whose total index (Sobol') minus the seed-noise floor (0 when unknown), μ* share
    (Morris) or S1 (RBD-FAST) is ≥ ``threshold``."""
    t = s.table
    kind = {"sobol": "ST", "morris": "mu_star", "lhs": "S1"}[s.design.method]
    out = {}
    for output in s.design.outputs:
        rows = t[(t.output == output) & (t["index"] == kind)]
        values = rows.value / rows.value.sum() if kind == "mu_star" and rows.value.sum() > 0 else rows.value
        if kind == "ST":
            values = values - np.nan_to_num(floor_of(s, output)[0])
        out[output] = rows.parameter[values >= threshold].tolist()
    return out


def morris_noise(s: Sensitivity, output: str) -> float:
    """The Morris μ* that seed noise alone gives a replicated Morris design: an elementary effect of pure
    noise is the difference of two point means over Δ (levels / (2 (levels - 1)), SALib's step in units of
    the range), normal with variance 2 s2 / R, whose mean absolute value is sqrt(2 / π) sqrt(2 s2 / R) / Δ
    (s2 / R: the mean of each point's within-point variance over its run count).  NaN without replicates."""
    d = s.design
    if d.method != "morris" or s.runs is None or s.runs_per_point[0] < 2:
        return np.nan
    _, v, n = _replicates(s.runs, d, output)
    delta = d.levels / (2.0 * (d.levels - 1))
    return float(np.sqrt(2.0 / np.pi) * np.sqrt(2.0 * np.nanmean(v / n)) / delta)


def _spread(m: np.ndarray, v: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Standard deviation the parameters cause between points (last two axes), seed noise removed:
    sqrt(max(0, var(means) - mean(v / n)))."""
    k = m.shape[-1] * m.shape[-2]
    vm = m.reshape(*m.shape[:-2], k).var(axis=-1, ddof=1)
    e = (v / n).reshape(*m.shape[:-2], k).mean(axis=-1)
    return np.sqrt(np.maximum(vm - e, 0.0))


def local_robustness(local: Sensitivity, reference: pd.DataFrame | None = None, *, tolerance: float = 0.05,
                     seed: int | None = None) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Is the centre of a local design (e.g. Morris trajectories in a small box around the paper's
    point, every point run R >= 2 times) in a robust region?  Returns (verdicts, parameters).

    verdicts, one row per output: ``spread``, the standard deviation of the output that the parameters
    cause across the box (the between-point variance of the point means minus the seed noise's share,
    ``_spread``), with a 95 % percentile bootstrap interval over trajectories (``scipy.stats.bootstrap``);
    ``tolerance`` x the 5-95 % range of the output over ``reference`` (the global design's point means;
    the box's own runs when None); ``robust``: yes when the interval's upper end is below the tolerance,
    no when its lower end is above it, else inconclusive (``stats.answer``).
    parameters, one row per output and parameter: SALib's Morris μ* with its interval, and ``mu_star_noise``,
    the μ* that seed noise alone gives (E|N(0, 2 s2 / R)| / Δ, s2 the within-point variance, Δ Morris's
    step); ``moves``: μ*'s lower bound above it."""
    from scipy import stats as sps


    d = local.design
    if local.runs is None or local.runs_per_point[0] < 2:
        raise MissingDataError(f"{d.experiment}: the local design's points ran once; its robustness needs "
                               f"replicates (runs >= 2) to tell the parameters' spread from seed noise")
    seed = d.seed if seed is None else seed
    verdicts, params = [], []
    for output in d.outputs:
        m, v, n = _replicates(local.runs, d, output)
        spread = float(_spread(m, v, n))

        def stat(i, axis=-1):
            i = np.asarray(i, dtype=np.int64)
            return _spread(m[i], v[i], n[i])  # noqa: B023 - called within this iteration

        res = sps.bootstrap((np.arange(m.shape[0]),), stat, vectorized=True, n_resamples=RESAMPLES, batch=100,
                            confidence_level=CONF_LEVEL, method="percentile", rng=np.random.default_rng(seed))
        lo, hi = float(res.confidence_interval.low), float(res.confidence_interval.high)
        ref = (reference[output] if reference is not None else local.runs[output]).to_numpy(float)
        p5, p95 = np.nanpercentile(ref, [5, 95])
        tol = tolerance * float(p95 - p5)
        y = local.runs[output].to_numpy(float)
        verdicts.append({"output": output, "spread": spread, "spread_low": lo, "spread_high": hi,
                         "range_5_95": float(p95 - p5), "tolerance": tol,
                         "robust": answer(hi < tol, lo > tol), "runs": len(y),
                         "median": float(np.median(y)), "positive": float(np.mean(y > 0))})
        noise_mu = morris_noise(local, output)
        if d.method == "morris":
            rows = local.table[(local.table.output == output) & (local.table["index"] == "mu_star")]
            for r in rows.itertuples():
                params.append({"output": output, "parameter": r.parameter, "mu_star": r.value, "mu_star_low": r.low,
                               "mu_star_high": r.high, "mu_star_noise": noise_mu, "moves": bool(r.low > noise_mu)})
    return pd.DataFrame(verdicts), pd.DataFrame(params)


__all__ = ["BUILTIN_OUTPUTS", "Sensitivity", "analyse", "from_store", "local_robustness", "noise_floor",
           "pawn", "point_outputs", "run_outputs", "sensitivity"]
